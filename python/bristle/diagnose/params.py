# SPDX-License-Identifier: Apache-2.0
"""Parameters of a saved model (model.json "params"): a name (with its unit
in it, the name of the br_plant_cfg_t field it sets), the unit, what it
means, and its bounds [lo, hi] (lo = GT0: "> 0"). NOMINAL are the thesis
model's, load side; each cause module (causes/) lists its own in PARAMS.
The same names, units, causes and bounds are the C table
sim/lib/plant/br_model_params.h (test_model.py holds the two together);
docs/diagnose.md, "Parameters", has the table.

The same Param describes a machine file's controller keys (closedloop.py),
so every number read from a model or machine file goes through check()."""
import math
import sys
from typing import NamedTuple

GT0 = sys.float_info.min  # the C table's BR_GT0 (DBL_MIN): "> 0"
INF = math.inf


def bounds_text(lo, hi):
    """The C table's wording (br_param_bounds_text)."""
    if lo == GT0 and hi != INF:
        return f"must be > 0 and <= {hi:g}"
    if hi == INF:
        return "must be > 0" if lo == GT0 else ("must be finite" if lo == -INF else f"must be >= {lo:g}")
    return f"must be <= {hi:g}" if lo == -INF else f"must be in {lo:g} .. {hi:g}"


class Param(NamedTuple):
    name: str
    unit: str
    meaning: str
    lo: float = -INF
    hi: float = INF

    def check(self, v):
        """None when v is a number (int or float, not a bool) within the
        bounds, else the problem: "parameter Fc_N = 0 must be > 0 and <= 1e+05"."""
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return f"parameter {self.name} is not a number ({_short(v)})"
        if not (self.lo <= v <= self.hi):  # NaN fails too
            # an int beyond the float range is shown as written (format 'g' would overflow)
            shown = f"{v:g}" if isinstance(v, float) or abs(v) < 1e300 else _short(v)
            return f"parameter {self.name} = {shown} {bounds_text(self.lo, self.hi)}"
        return None


def _short(v, n=40):
    s = repr(v)
    return s if len(s) <= n else s[: n - 1] + "…"


NOMINAL = (
    Param("Meff_kg", "kg", "moving mass at the load, J/L² + M (a log cannot tell the screw's inertia from the "
          "table's mass; machines/reference.json's M_kg is the table alone)", GT0, 1e4),
    Param("sigma2_Nspm", "N s/m", "viscous friction σ2 (moving in +x when the friction is asymmetric)", 0.0, 1e6),
    Param("Fc_N", "N", "Coulomb friction level (moving in +x when the friction is asymmetric)", GT0, 1e5),
    Param("Fs_N", "N", "stiction level (the Stribeck curve at rest)", GT0, 1e5),
    Param("vs_mps", "m/s", "Stribeck velocity", GT0, 10.0),
    Param("sigma0_Npm", "N/m", "bristle stiffness σ0", GT0, 1e12),
    Param("sigma1_Nspm", "N s/m", "bristle damping σ1", 0.0, 1e8),
)

# relations between parameters that the force model divides by or takes a
# root of (br_plant_init checks the same): (names, test, problem)
RELATIONS = (
    (("Fc_N", "dFc_neg_N"), lambda p: p["Fc_N"] + p["dFc_neg_N"] > 0, "Fc_N + dFc_neg_N must be > 0"),
    (("sigma2_Nspm", "dsigma2_neg_Nspm"), lambda p: p["sigma2_Nspm"] + p["dsigma2_neg_Nspm"] >= 0,
     "sigma2_Nspm + dsigma2_neg_Nspm must be >= 0"),
)
