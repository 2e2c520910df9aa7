# SPDX-License-Identifier: Apache-2.0
"""offset: a constant force on the axis (gravity on a tilted axis, cable
drag, an amplifier offset).

Force model: + offset_N (a column of ones, linear: nothing to search).
Plant (br_sim_plant.c) and closed loop: a load force offset_N, + opposing
motion in +x. Estimator (the firmware's extended
model, br_model_cfg_t.causes): in its force balance and its compensation."""
import numpy as np

from ..params import Param

NAME = "offset"
MEANING = "a constant force: gravity on a tilted axis, cable drag, an amplifier offset"
ACTION = ("Check whether the axis is tilted (gravity), a cable chain or hose pulls on the table, or the "
          "amplifier has an offset (command 0 with the motor free); a constant load is compensated by feed-"
          "forward of offset_N.")
OPTION = "--offset"
PARAMS = (Param("offset_N", "N", "constant load force, + opposes motion in +x", -1e5, 1e5),)
NL = ()
HOOK = "force"
MACHINE = {"offset_N": (-1.0e5, 1.0e5, "constant load force, + opposes motion in +x")}
DETECTION = ("offset", "N", 0.001, lambda s, ref: ["--offset", f"{s:.6g}"])
CONTROL_CASE = (["--offset", "2.5"], "2.5 N constant force (tilted axis)")


def robustness_draw(c, sgn):
    """The robustness study's plant parameters of this cause from uniforms c[0..2] and a sign."""
    return {"offset_N": sgn * (0.5 + 2.5 * c[0])}


def load_columns(prep, nl):
    return {"offset": prep.memo(("ones",), lambda: np.ones(prep.n))}


def search(prep, base, fit_with):
    return {}


def params(coef, nl, p):
    return {"offset_N": coef["offset"]}


def from_params(p):
    return {"offset": p["offset_N"]}, {}


def report_params(p):
    return {"force_N": p["offset_N"]}


def evidence(r, p):
    rest = np.abs(r.v) < 0.02 * r.v95
    mp, mn = r.e[r.moving & (r.v > 0)].mean(), r.e[r.moving & (r.v < 0)].mean()
    at_rest = f", {r.e[rest].mean():+.2f} N at rest" if rest.any() else ""
    return (f"The nominal model's residual has the same sign in both directions: {mp:+.2f} N moving in +x, "
            f"{mn:+.2f} N moving in -x{at_rest} (residual vs velocity); fitted constant force "
            f"{p['force_N']:+.3g} N.")


def closed_loop(p, plant):
    off = p["offset_N"]
    plant.loads.append(lambda x: off)
