# SPDX-License-Identifier: Apache-2.0
"""Values a fit may not claim as measured (docs/diagnose.md, "Identifiability",
"Non-physical values").

A LuGre fit of a log can land where no axis is: the bristle damping far
above the presliding mode's critical damping, or a shape parameter on the
edge of its search range (the log pulls it beyond). Such a value is not a
measurement; the diagnosis holds it at the machine file's value
(identify.py) and the report says why.

Bristle damping ratio of the presliding mode (the bristle spring sigma0 on
the moving mass Meff, damped by sigma1):

  zeta = sigma1 / (2 sqrt(sigma0 Meff))                                 (P1)

The literature's LuGre parameter sets are under critical damping
(Canudas de Wit, Olsson, Astrom, Lischinsky, "A new model for control of
systems with friction", IEEE TAC 40(3), 1995: sigma0 = 1e5 N/m,
sigma1 = sqrt(1e5) N s/m on 1 kg, zeta = 0.5; machines/reference.json:
0.085); ZETA_MAX allows twice critical damping before a value is called
non-physical.

A shape parameter (model.RHO_BOUNDS, BETA_BOUNDS, VS_BOUNDS) within
EDGE of a bound of its search is on that bound: the Stribeck velocity at
its floor, Fs = Fc (beta = 1), a presliding zone Fc/sigma0 of 1 nm or 1 mm.
"""
import math

from . import causes as causes_
from . import model

ZETA_MAX = 2.0
EDGE = 1e-3  # relative distance to a search bound that counts as on it
NON_PHYSICAL = "non-physical"


def damping_ratio(p):
    """(P1) of model.json-style parameters; None without a bristle (sigma0 or Meff not > 0)."""
    s0, m = p.get("sigma0_Npm", 0.0), p.get("Meff_kg", 0.0)
    if not (s0 > 0.0 and m > 0.0):
        return None
    # (P1)
    return p.get("sigma1_Nspm", 0.0) / (2.0 * math.sqrt(s0 * m))


def _on_edge(v, lo, hi):
    return v <= lo * (1.0 + EDGE) or v >= hi * (1.0 - EDGE)


def unphysical(fit):
    """{param: reason} of the fit's values that are no measurement of an axis
    (the parameters an element set replaces are not judged)."""
    p = fit.params()
    unused = {k for m in causes_.of(fit.causes) for k in getattr(m, "UNUSED_PARAMS", ())}
    out = {}
    zeta = damping_ratio(p)
    if zeta is not None and zeta > ZETA_MAX and "sigma1_Nspm" not in unused:
        out["sigma1_Nspm"] = (f"{NON_PHYSICAL}: a bristle damping ratio sigma1 / (2 sqrt(sigma0 Meff)) = {zeta:.3g}, "
                              f"above {ZETA_MAX:g} (the literature's LuGre sets are under critical damping, 1)")
    rho, beta, vs = fit.shape
    if _on_edge(vs, *model.VS_BOUNDS):
        why = f"the Stribeck velocity {vs:.3g} m/s is on its search bound {model.VS_BOUNDS} (the log pulls it beyond)"
        out["vs_mps"] = why
        out["Fs_N"] = why + ": the stiction level goes with it"
    elif beta <= model.BETA_BOUNDS[0] * (1.0 + EDGE):
        out["Fs_N"] = "Fs = Fc: the Stribeck curve's Fs/Fc is on its search bound 1 (no hump the log could show)"
    if "sigma0_Npm" not in unused and _on_edge(rho, *model.RHO_BOUNDS):
        why = (f"the presliding zone Fc/sigma0 = {1.0 / rho:.3g} m is on its search bound "
               f"({1.0 / model.RHO_BOUNDS[1]:g} .. {1.0 / model.RHO_BOUNDS[0]:g} m)")
        out["sigma0_Npm"] = why
        out.setdefault("sigma1_Nspm", why + ": the bristle damping goes with it")
    return out
