"""Machine parameters (a machine description, machines/*.json) and derived values.

Shared by the design scripts. The reference machine (machines/reference.json)
is the default; its numbers' source is ../shared/spec/reference-machine.md."""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
REPO_ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
REFERENCE_MACHINE = os.path.join(REPO_ROOT, "machines", "reference.json")
# generated headers: one root on the include path, one folder per kind below bristle_gen/
GEN_DIR = os.path.join(REPO_ROOT, "firmware", "gen")


def load(path=REFERENCE_MACHINE):
    with open(path) as f:
        p = {k: v for k, v in json.load(f).items() if not k.startswith("_")}
    p["file"] = os.path.relpath(os.path.abspath(path), REPO_ROOT) if os.path.abspath(path).startswith(REPO_ROOT + os.sep) \
        else os.path.basename(path)
    p["L_mprad"] = p["lead_m_per_rev"] / (2.0 * math.pi)
    p["Jeff_kgm2"] = p["J_kgm2"] + p["L_mprad"] ** 2 * p["M_kg"]
    p["rad_per_count"] = 2.0 * math.pi / p["counts_per_rev"]
    return p


def c_float(x):
    """A C float literal that round-trips exactly to the float32 nearest x."""
    import numpy as np
    f = np.float32(x)
    s = "%.9e" % float(f)
    assert np.float32(float(s)) == f
    return s + "f"
