"""Golden references of the bristle numerics, float64, written from the
algorithm descriptions (docs/golden.md), independently of the C sources.

Scalar arithmetic uses Python floats (IEEE binary64) and the libm functions
of the `math` module, state vectors are float64 numpy arrays with element-wise
operations only (no BLAS, no FMA contraction), so a trace is reproducible bit
for bit on any machine with the same libm, whatever SIMD extensions numpy
dispatches to.
"""
import json
import math
import os

__all__ = ["REPO_ROOT", "MACHINE_JSON", "load_machine"]

REPO_ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MACHINE_JSON = os.path.join(REPO_ROOT, "machines", "reference.json")


def load_machine(path=MACHINE_JSON):
    """Reference machine parameters (machines/reference.json)
    plus the derived quantities every reference needs:
      L = lead / (2 pi)                  (m/rad)
      Jeff = J + L^2 M                   (kg m^2)
      rad_per_count = 2 pi / counts_per_rev
    """
    with open(path, "r", encoding="utf-8") as f:
        raw = json.load(f)
    m = {k: float(v) for k, v in raw.items() if not k.startswith("_")}
    m["L_mprad"] = m["lead_m_per_rev"] / (2.0 * math.pi)
    m["Jeff_kgm2"] = m["J_kgm2"] + m["L_mprad"] ** 2 * m["M_kg"]
    m["rad_per_count"] = 2.0 * math.pi / m["counts_per_rev"]
    return m
