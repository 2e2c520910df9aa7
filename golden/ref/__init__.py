# SPDX-License-Identifier: Apache-2.0
"""Golden references of the bristle numerics, float64, written from the
algorithm descriptions (docs/golden.md), independently of the C sources.

Scalar arithmetic uses Python floats (IEEE binary64) and the libm functions
of the `math` module, state vectors are float64 numpy arrays with element-wise
operations only (no BLAS, no FMA contraction), so a trace is reproducible bit
for bit on any machine with the same libm, whatever SIMD extensions numpy
dispatches to.
"""
import os
import sys

__all__ = ["REPO_ROOT", "MACHINE_JSON", "load_machine", "machine_module"]

REPO_ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
MACHINE_JSON = os.path.join(REPO_ROOT, "machines", "reference.json")


def load_machine(path=MACHINE_JSON):
    """Reference machine parameters (machines/reference.json, read and checked
    by firmware/design/machine.py) by their symbols, plus the derived
    quantities every reference needs:
      L = lead / (2 pi)                  (m/rad)
      Jeff = J + L^2 M                   (kg m^2)
      rad_per_count = 2 pi / counts_per_rev
    """
    return machine_module().params(machine_module().load_or_exit(path))


def machine_module():
    """firmware/design/machine.py, the machine-description loader."""
    design = os.path.join(REPO_ROOT, "firmware", "design")
    if design not in sys.path:
        sys.path.insert(0, design)
    import machine
    return machine
