# SPDX-License-Identifier: Apache-2.0
"""actuator_delay: a dead time between the commanded and the applied force
(amplifier, fieldbus, a filter in the drive).

Force model: the force compared with is the logged one delayed by d: with
zero-order hold, the mean over interval k of the command delayed by
d = (m + f) dt is (1 - f) F[k-m] + f F[k-m-1], filtered like the force. d is
searched on a half-period grid over 0 .. DELAY_MAX_S, then by a bounded
search around the best point. Plant (br_sim_plant.c), closed loop and
estimator (the firmware's extended model: model.causes.delay_s, a command
history in br_est): the torque reaching the axis is the command of d earlier."""
import numpy as np

from ..params import Param
from ..search1d import grid_then_bounded

NAME = "actuator_delay"
MEANING = "a dead time between the commanded and the applied force"
ACTION = ("Look for the dead time in the drive chain: fieldbus cycles, the drive's current-loop filters, the "
          "sampling of the command; shorten it or give the estimator the delay (the extended model does).")
OPTION = "--delay"
PARAMS = (Param("delay_s", "s", "actuator dead time d", 0.0, 0.1),)  # upper: BR_PLANT_DELAY_MAX_S
NL = ("delay_s",)
HOOK = "measurement"
MACHINE = {"delay_s": (0.0, 0.1, "actuator dead time")}
DETECTION = ("dead time", "s", 5e-6, lambda s, ref: ["--delay", f"{s:.6g}"])
CONTROL_CASE = (["--delay", "0.003"], "3 ms actuator dead time")
DELAY_MAX_S = 0.02


def robustness_draw(c, sgn):
    """The robustness study's plant parameters of this cause from uniforms c[0..2] and a sign."""
    return {"delay_s": 0.0005 + 0.0025 * c[0]}


def delayed_force(prep, delay_s):
    """The filtered force that reaches the axis over each interval when the
    logged (commanded) force is applied delay_s later (before the log
    starts: its first force)."""
    if delay_s <= 0.0:
        return prep.y
    m = int(np.floor(delay_s / prep.dt))
    f = delay_s / prep.dt - m
    F = prep.force
    prev = np.concatenate([np.full(m, F[0]), F])[: len(F)]
    prev2 = np.concatenate([np.full(m + 1, F[0]), F])[: len(F)]
    return prep.lp((1.0 - f) * prev + f * prev2)[:-1]


def target(prep, nl):
    d = nl.get("delay_s", 0.0)
    return prep.memo(("target", d), lambda: delayed_force(prep, d))


def search(prep, base, fit_with):
    dt = prep.dt

    def sse(d):
        return fit_with({"delay_s": max(d, 0.0)}).train_sse

    grid = np.arange(0.0, DELAY_MAX_S + 1e-12, 0.5 * dt)
    return {"delay_s": max(grid_then_bounded(sse, grid, 1e-3 * dt), 0.0)}


def params(coef, nl, p):
    return {"delay_s": nl["delay_s"]}


def from_params(p):
    return {}, {"delay_s": p["delay_s"]}


def report_params(p):
    return {"delay_s": p["delay_s"]}


def evidence(r, p):
    prep = r.prep
    da = np.abs(np.gradient(prep.a, prep.dt))[prep.whole]
    jerky = da > np.percentile(da, 90)
    r1 = float(np.sqrt(np.mean(r.e[jerky] ** 2)))
    r0 = float(np.sqrt(np.mean(r.e[~jerky] ** 2)))
    return (f"The residual concentrates where the acceleration changes (RMS {r1:.2f} N there against {r0:.2f} N "
            f"elsewhere, residual vs time) and shifting the logged force by {1e3 * p['delay_s']:.3g} ms removes it: "
            f"the force reaches the axis that much later than it is commanded.")


def closed_loop(p, plant):
    plant.delay_s += p["delay_s"]
