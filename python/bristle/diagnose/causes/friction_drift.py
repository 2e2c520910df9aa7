# SPDX-License-Identifier: Apache-2.0
"""friction_drift: the friction level (Coulomb, stiction and viscous
together) changing with time while the machine runs (warm-up of screw, nut
and guides, lubricant temperature, wear).

Force model, plant (br_sim_plant.c), closed loop and estimator (the
firmware's extended model, its clock br_model_tick): the friction (viscous +
LuGre) times s(t) = max(0, 1 + r t), r = drift_per_s, t the time since the
start (the log's first sample; the plant's and the estimator's start). The
spec's relative_rate_per_s is r: 0.02 means the level grows by 2 % of its
starting value each second. r is searched on a GRID-point grid over
|r| < 0.95 / T (T the log's duration: s stays positive on the log), then by a
bounded search around the best point."""
import numpy as np

from ..params import Param
from ..search1d import grid_then_bounded

NAME = "friction_drift"
MEANING = ("friction level (Coulomb, stiction, viscous together) changing with time: warm-up of screw, "
           "nut and guides, lubricant temperature, wear")
ACTION = ("Log the screw-nut and guide temperatures with the force; run the axis through a warm-up cycle before "
          "production or before identification; check the lubrication. Online estimation (the PF / UKF) follows a "
          "slow drift; a machine file with drift_per_s lets the estimators expect it.")
OPTION = "--drift"
PARAMS = (Param("drift_per_s", "1/s", "relative rate r of the friction level in time: friction × max(0, 1 + r t)",
                -1.0, 1.0),)
NL = ("drift_per_s",)
HOOK = "force"
MACHINE = {"drift_per_s": (-1.0, 1.0, "friction level scaled by max(0, 1 + drift_per_s t), t since the start")}
DETECTION = ("relative rate of the friction level", "1/s", 1e-5, lambda s, ref: ["--drift", f"{s:.6g}"])
CONTROL_CASE = (["--drift", "0.01"], "friction level +1 % of its start a second (warm-up)")
GRID = 21


def scale(r, t):
    return np.maximum(0.0, 1.0 + r * t)


def times(prep):
    """The intervals' middle times from the log's first sample, s."""
    return prep.memo(("interval_times",), lambda: 0.5 * (prep.t[1:] + prep.t[:-1]) - prep.t[0])


def friction_scale(prep, nl):
    return scale(nl["drift_per_s"], times(prep))


def search(prep, base, fit_with):
    rmax = min(0.95 / max(float(prep.t[-1] - prep.t[0]), 1e-6), PARAMS[0].hi)

    def sse(r):
        return fit_with({"drift_per_s": r}).train_sse

    return {"drift_per_s": grid_then_bounded(sse, np.linspace(-rmax, rmax, GRID), 1e-4 * rmax)}


def params(coef, nl, p):
    return {"drift_per_s": nl["drift_per_s"]}


def from_params(p):
    return {}, {"drift_per_s": p["drift_per_s"]}


def report_params(p):
    return {"relative_rate_per_s": p["drift_per_s"]}


def evidence(r, p):
    t = times(r.prep)[r.prep.whole]
    sgn = np.sign(r.v[r.moving])
    lo, hi = np.percentile(t, [20, 80])
    ts = t[r.moving]
    e = r.e[r.moving] * sgn
    el = e[ts < lo].mean() if (ts < lo).any() else 0.0
    eh = e[ts > hi].mean() if (ts > hi).any() else 0.0
    rate = p["relative_rate_per_s"]
    return (f"The residual in the direction of motion changes with time, {el:+.2f} N before t = {lo:.3g} s "
            f"and {eh:+.2f} N after t = {hi:.3g} s (residual vs time): the friction level scales by "
            f"1 {rate:+.3g} t ({100 * rate:+.2f} % of its starting value a second).")


def closed_loop(p, plant):
    r = p["drift_per_s"]
    plant.friction_scales.append(lambda x, t: max(0.0, 1.0 + r * t))
