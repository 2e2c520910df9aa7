"""Reference-machine parameters (reference_machine.json) and derived values.

Shared by the design scripts; the numbers' source is
../shared/spec/reference-machine.md."""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def load(path=os.path.join(HERE, "reference_machine.json")):
    with open(path) as f:
        p = {k: v for k, v in json.load(f).items() if not k.startswith("_")}
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
