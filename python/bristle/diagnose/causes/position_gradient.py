# SPDX-License-Identifier: Apache-2.0
"""position_gradient: friction that grows or shrinks along the travel
(misalignment of screw and guides, a preload that varies).

Force model, plant (br_sim_plant.c), closed loop and estimator
(the firmware's extended model): the friction (viscous + LuGre) times k(x) = max(0, 1 + s x),
s = grad_per_m. s is searched on a GRID-point grid over |s| < 0.95 / max|x|
(k stays positive on the log), then by a bounded search around the best
point."""
import numpy as np

from ..params import Param
from ..search1d import grid_then_bounded

NAME = "position_gradient"
MEANING = "friction that grows or shrinks along the travel: misalignment, preload variation"
ACTION = ("Check the alignment of screw and guides along the travel and the preload of the guides; the end "
          "where the friction grows is where they bind.")
OPTION = "--gradient"
PARAMS = (Param("grad_per_m", "1/m", "relative slope s of the friction along the travel: friction × max(0, 1 + s x)",
                 -1e3, 1e3),)
NL = ("grad_per_m",)
HOOK = "force"
MACHINE = {"grad_per_m": (-1.0e3, 1.0e3, "friction scaled by max(0, 1 + grad_per_m x) along the travel")}
DETECTION = ("relative slope", "1/m", 0.008, lambda s, ref: ["--gradient", f"{s:.6g}"])
CONTROL_CASE = (["--gradient", "4"], "friction +4 %/cm along the travel")
GRID = 21


def robustness_draw(c, sgn):
    """The robustness study's plant parameters of this cause from uniforms c[0..2] and a sign."""
    return {"grad_per_m": sgn * (1.0 + 4.0 * c[0])}


def scale(s, x):
    return np.maximum(0.0, 1.0 + s * x)


def friction_scale(prep, nl):
    return scale(nl["grad_per_m"], prep.xm)


def search(prep, base, fit_with):
    xmax = float(np.max(np.abs(prep.xm[prep.whole])))
    smax = 0.95 / max(xmax, 1e-6)

    def sse(s):
        return fit_with({"grad_per_m": s}).train_sse

    return {"grad_per_m": grid_then_bounded(sse, np.linspace(-smax, smax, GRID), 1e-4 * smax)}


def params(coef, nl, p):
    return {"grad_per_m": nl["grad_per_m"]}


def from_params(p):
    return {}, {"grad_per_m": p["grad_per_m"]}


def report_params(p):
    return {"relative_slope_per_m": p["grad_per_m"]}


def evidence(r, p):
    sgn = np.sign(r.v[r.moving])
    lo, hi = np.percentile(r.x, [10, 90])
    xs = r.x[r.moving]
    rl = (r.e[r.moving] * sgn)[xs < lo].mean() if (xs < lo).any() else 0.0
    rh = (r.e[r.moving] * sgn)[xs > hi].mean() if (xs > hi).any() else 0.0
    s = p["relative_slope_per_m"]
    return (f"The residual in the direction of motion changes along the travel, {rl:+.2f} N near x = {lo:.3g} m "
            f"and {rh:+.2f} N near x = {hi:.3g} m (residual vs position): friction scales by 1 {s:+.3g} x "
            f"({100 * s * (hi - lo):+.1f} % between those positions).")


def closed_loop(p, plant):
    s = p["grad_per_m"]
    plant.friction_scales.append(lambda x, t: max(0.0, 1.0 + s * x))
