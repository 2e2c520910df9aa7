# SPDX-License-Identifier: Apache-2.0
"""asymmetric_friction: Coulomb and/or viscous friction that differ by the
direction of motion (wear or fatigue of the screw on one side, a preload
that depends on the direction).

Force model: the viscous coefficient per direction of v (sigma2 in +x,
sigma2 + dsigma2_neg_Nspm in -x), and the whole Stribeck curve in -x scaled
by c = (Fc + dFc_neg_N) / Fc inside the bristle dynamics (lugre.stribeck's
neg_ratio), exactly as the plant simulator does (br_sim_plant.c). c is the
one nonlinear parameter: first from a linear fit with the LuGre level split
by the sign of z (symmetric bristle dynamics), then a bounded scalar search
with c inside the bristle dynamics.

Estimator (the firmware's extended model, br_model_cfg_t.causes): the
viscous term and the Stribeck level inside the bristle dynamics by the
direction of motion, as here."""
import math

import numpy as np
from scipy import optimize

from ..params import Param

NAME = "asymmetric_friction"
MEANING = "Coulomb and/or viscous friction that differ by the direction of motion"
ACTION = ("Inspect the screw and nut for wear or fatigue on one side, the preload and the lubrication; compare "
          "with a log after service. The firmware's extended model compensates each direction with its own "
          "level.")
OPTION = "--asym"
PARAMS = (Param("dFc_neg_N", "N", "Coulomb level in −x minus that in +x (the stiction level scaled alike)",
                -1e5, 1e5),
          Param("dsigma2_neg_Nspm", "N s/m", "viscous friction in −x minus that in +x", -1e6, 1e6))
NL = ("fc_ratio", "fc_split")      # c = Fc in -x / Fc in +x; the split first estimate
HOOK = "force"
MACHINE = {"dFc_neg_N": (-1.0e5, 1.0e5, "Coulomb level in -x is Fc_N + dFc_neg_N (Fs scaled alike)"),
           "dsigma2_neg_Nspm": (-1.0e6, 1.0e6, "viscous friction in -x is sigma2_Nspm + this")}
DETECTION = ("relative asymmetry of Fc and Fv in -x", "", 0.0002,
             lambda s, ref: ["--asym", f"{ref['Fc_N'] * s:.6g},{ref['sigma2_Nspm'] * s:.6g}"])
CONTROL_CASE = (["--asym", "2.1,15"], "Coulomb 7 -> 9.1 N and viscous 50 -> 65 N s/m in -x")
FC_RATIO_BOUNDS = (0.2, 5.0)


def robustness_draw(c, sgn):
    """The robustness study's plant parameters of this cause from uniforms c[0..2] and a sign."""
    return {"dFc_neg_N": sgn * (0.5 + 2.0 * c[0]),
            "dsigma2_neg_Nspm": sgn * (5.0 + 15.0 * c[1])}


def stribeck_neg_ratio(nl):
    return 1.0 if nl.get("fc_split") else nl["fc_ratio"]


def friction_columns(prep, nl, v, phi):
    """Viscous by the direction of motion; the LuGre level whole, or (the
    first estimate of c) split by the sign of z."""
    cols = {"sigma2": np.maximum(v, 0.0), "sigma2_neg": np.minimum(v, 0.0)}
    if nl.get("fc_split"):
        cols["Fc"] = prep.lp(np.maximum(phi, 0.0))
        cols["Fc_neg_split"] = prep.lp(np.minimum(phi, 0.0))
    else:
        cols["Fc"] = prep.lp(phi)
    return cols


def search(prep, base, fit_with):
    split = fit_with({"fc_split": True, "fc_ratio": 1.0})
    c0 = split.coef["Fc_neg_split"] / split.coef["Fc"] if split.coef["Fc"] > 0 else 1.0
    c0 = min(max(c0, FC_RATIO_BOUNDS[0]), FC_RATIO_BOUNDS[1])

    def sse(lc):
        return fit_with({"fc_ratio": math.exp(lc)}).train_sse

    lo = max(math.log(c0) - 0.2, math.log(FC_RATIO_BOUNDS[0]))
    hi = min(math.log(c0) + 0.2, math.log(FC_RATIO_BOUNDS[1]))
    r = optimize.minimize_scalar(sse, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
    return {"fc_ratio": float(math.exp(r.x))}


def params(coef, nl, p):
    return {"dFc_neg_N": nl["fc_ratio"] * p["Fc_N"] - p["Fc_N"],
            "dsigma2_neg_Nspm": coef["sigma2_neg"] - coef["sigma2"]}


def from_params(p):
    return ({"sigma2_neg": p["sigma2_Nspm"] + p["dsigma2_neg_Nspm"]},
            {"fc_ratio": (p["Fc_N"] + p["dFc_neg_N"]) / p["Fc_N"]})


def report_params(p):
    """The spec's names (../shared/spec/measured-log.md): each direction's level."""
    return {"Fc_pos_N": p["Fc_N"], "Fc_neg_N": p["Fc_N"] + p["dFc_neg_N"],
            "Fv_pos_Nspm": p["sigma2_Nspm"], "Fv_neg_Nspm": p["sigma2_Nspm"] + p["dsigma2_neg_Nspm"]}


def evidence(r, p):
    fast = np.abs(r.v) > 0.6 * r.v95
    slow = r.moving & ~fast
    parts = []
    for name, m in (("slow", slow), ("fast", fast)):
        if (m & (r.v > 0)).any() and (m & (r.v < 0)).any():
            parts.append(f"{name}: {r.e[m & (r.v > 0)].mean():+.2f} N in +x, {r.e[m & (r.v < 0)].mean():+.2f} N in -x")
    return ("The nominal model's residual differs by direction and speed (" + "; ".join(parts) +
            f"; residual vs velocity): friction in -x is {p['Fc_neg_N']:.3g} N + {p['Fv_neg_Nspm']:.4g} N s/m, "
            f"in +x {p['Fc_pos_N']:.3g} N + {p['Fv_pos_Nspm']:.4g} N s/m.")


def closed_loop(p, plant):
    plant.stribeck_neg_ratio *= (p["Fc_N"] + p["dFc_neg_N"]) / p["Fc_N"]
    plant.sigma2_neg_Nspm = p["sigma2_Nspm"] + p["dsigma2_neg_Nspm"]
