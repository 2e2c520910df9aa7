# SPDX-License-Identifier: Apache-2.0
"""What a log can identify, parameter by parameter, and the fit that takes
what it cannot from the machine file (docs/diagnose.md, "Identifiability").

A circle of 0.1 mm, a slow back-and-forth at one speed or a sweep does not
move the axis the way long moves at several speeds do: on the thesis circle
(speeds under 0.25 mm/s, ten Stribeck velocities) the viscous force sigma2 v
is a few mN beside a Coulomb level of 7 N, and a free fit put sigma2 at
-134 N s/m.

Sensitivity (at the machine file's values p0, the extended model's causes):
the relative sensitivity column of parameter i over the training part,

  S_i = dF / d(theta_i / s_i),    s_i = |p0 of the parameter's scale| (SCALE)

(a finite difference of step H s_i), and with the extended fit's training
residual RMS sigma and the filtered residual's correlation (one independent
sample per 1 / (2 fc)), kappa = 1 / (2 fc dt), the relative standard error

  rse_i = sigma sqrt(kappa) sqrt([(S^T S)^-1]_ii)

over the parameters still free. The worst parameter with Z rse_i > REL_95
(its 95 % interval wider than +-50 % of the machine file's value) is the
log's weakest; it is set aside and the rest assessed again, until every
remaining one passes. The parameters set aside are not identified.

Held at the machine file's value (prep.fixed, model.solve / fit_shape), the
extended model refitted with every parameter held so far:
  - each parameter set aside, in that order: either the log cannot tell the
    machine file's value from its own fit (the held-out relerr rises by no
    more than HOLD_TOL relative and the free fit is not better consistently
    over the held-out blocks, selection.block_p_value, p < P_MAX; or the
    free fit put it on its physical bound), or it is poorly determined (the
    log shows a difference but does not fix the value): held either way,
    the report saying which;
  - the moving mass or the Coulomb level on its floor (model.COEF_LOWER,
    FLOOR): the log pulls a strictly positive quantity to zero or below (a
    log whose accelerations are too small to weigh the mass: a fleet axis of
    1.3 kg moved at under 0.5 m/s^2 fitted Meff = 1e-9 kg, a model the
    closed-loop re-simulation cannot integrate); the nominal model too,
    refitted with it held (apply, "nominal_held");
  - sigma1 when the bristle damping ratio is non-physical (physical.py);
  - sigma0 at a zone of ZONE_STEPS position steps when the log cannot tell
    the fit from that model (the log does not show presliding, whatever the
    fitted sigma0 says); sigma0 and sigma1 are then kept out of machine.json.
Kept out of machine.json (the model keeps its fit): a nominal parameter a
borderline cause moves beyond its jackknife interval and by more than REL_95
of its value when added, and the values on a search bound (physical.py).
Every fit is also bounded to the physical ranges (model.COEF_LOWER).
"""
import math

import numpy as np

from . import causes as causes_
from . import intervals, machinejson, model, params, physical, selection

Z = 1.96
REL_95 = 0.5     # a parameter is identified when its 95 % interval is within +-50 % of its scale
H = 1e-3         # finite-difference step, in units of the scale
HOLD_TOL = 0.05  # held-out relerr may rise 5 % (relative) when a parameter is held
ZONE_STEPS = 0.5  # the presliding zone of the visibility test, in position steps
# strictly positive parameters: a fit on their floor (model.COEF_LOWER) is no value (the log pulls them to <= 0)
FLOOR = ("Meff_kg", "Fc_N")
# the parameters assessed and the machine-file parameter that gives each its scale
SCALE = {"Meff_kg": "Meff_kg", "sigma2_Nspm": "sigma2_Nspm", "Fc_N": "Fc_N", "Fs_N": "Fs_N", "vs_mps": "vs_mps",
         "sigma0_Npm": "sigma0_Npm", "sigma1_Nspm": "sigma1_Nspm",
         "dFc_neg_N": "Fc_N", "dsigma2_neg_Nspm": "sigma2_Nspm"}
# what the log must contain for each (the reason given with a parameter not identified)
NEEDS = {"Meff_kg": "accelerations",
         "sigma2_Nspm": "sliding at several speeds well above the Stribeck velocity",
         "Fc_N": "sliding in both directions",
         "Fs_N": "breakaway and speeds around the Stribeck velocity",
         "vs_mps": "speeds around the Stribeck velocity, a few times the velocity resolution",
         "sigma0_Npm": "reversals with a presliding travel of several position steps",
         "sigma1_Nspm": "fast presliding (reversals at high acceleration)",
         "dFc_neg_N": "sliding in -x",
         "dsigma2_neg_Nspm": "sliding in -x at several speeds"}
# parameters that can be held at the machine file's value (model.FIXED_COEF, FIXED_SHAPE)
HOLDABLE = set(model.FIXED_COEF) | set(model.FIXED_SHAPE)
# the nominal model's parameters: what machine.json can take from the machine file instead
NOMINAL = {q.name for q in params.NOMINAL}


def prior(machine):
    """The load-side values of a machine file (firmware/design/machine.py's
    dict): the moving mass J/L^2 + M, the friction, the causes' parameters
    (0 when it states none)."""
    L = machine["mechanics"]["lead_m_per_rev"] / (2.0 * math.pi)
    p = {"Meff_kg": machine["mechanics"]["inertia_kgm2"] / L ** 2 + machine["mechanics"]["table_mass_kg"]}
    p.update({k: float(v) for k, v in machine["friction"].items() if k in SCALE})
    for c in machine.get("causes", {}).values():
        p.update({k: float(v) for k, v in c.items()})
    return p


def _assessed(fit):
    """The parameters assessed: SCALE's that the fit has and uses (an element
    set replaces sigma0 and sigma1: causes' UNUSED_PARAMS)."""
    unused = {k for m in causes_.of(fit.causes) for k in getattr(m, "UNUSED_PARAMS", ())}
    return [k for k in SCALE if k in fit.params() and k not in unused]


def sensitivity(prep, fit, p0):
    """{param: S_i} over the training part at p0 (the fit's other parameters,
    a cause's own, kept), for the parameters of fit that SCALE lists."""
    point = dict(fit.params())
    for k in _assessed(fit):
        point[k] = p0.get(k, 0.0)
    tr = prep.train

    def pred(p):
        return model.from_params(p, fit.causes, nl=fit.nl).predict(prep)[tr]

    y0 = pred(point)
    out = {}
    for k in _assessed(fit):
        s = abs(p0[SCALE[k]])
        p = dict(point)
        p[k] += H * s
        out[k] = (pred(p) - y0) / H
    return out


def rel_se(S, names, sigma, kappa):
    """{name: relative standard error} of the parameters named, the others' columns left out."""
    X = np.column_stack([S[k] for k in names])
    inv = np.linalg.pinv(X.T @ X)
    return {k: float(sigma * math.sqrt(kappa * max(inv[i, i], 0.0))) for i, k in enumerate(names)}


def assess(prep, fit, p0):
    """[(param, rse when set aside)] in the order set aside, and {param: rse} of the rest."""
    S = sensitivity(prep, fit, p0)
    sigma = float(np.sqrt(np.mean(fit.train_resid ** 2))) if hasattr(fit, "train_resid") else 0.0
    # a model fitted on a finite log never reaches zero: at least 0.1 % of the force
    sigma = max(sigma, 1e-3 * float(np.sqrt(np.mean(prep.y[prep.train] ** 2))))
    kappa = max(1.0, 1.0 / (2.0 * prep.fc_hz * prep.dt))
    names = [k for k in S if np.any(S[k] != 0.0)]
    aside = [(k, math.inf) for k in S if k not in names]  # no effect at all on this log
    while names:
        r = rel_se(S, names, sigma, kappa)
        worst = max(names, key=lambda k: r[k])
        if Z * r[worst] <= REL_95:
            return aside, r
        aside.append((worst, r[worst]))
        names.remove(worst)
    return aside, {}


def _refit(prep, fit, fixed):
    prep.fixed = fixed
    f = model.solve(prep, fit.shape, fit.causes, fit.nl)
    return model.refine(prep, f, rounds=1)


class _Holder:
    """The parameters held so far at the machine file's values, and the
    extended model refitted with them (best)."""

    def __init__(self, prep, fit, p0):
        self.prep, self.free, self.p0 = prep, fit, p0
        self.fixed = {"Fc_ref_N": p0["Fc_N"]}
        self.best = fit
        self.held = {}   # {param: {"value", "rse", "why"}} in the order held
        self.kept_out = {}  # {param: why}: the model keeps the fit, machine.json the machine file's value
        self.moves = {}

    def trial(self, extra):
        """The free fit refitted with the parameters held so far and `extra` ({param: value})."""
        return _refit(self.prep, self.free, dict(self.fixed, **extra))

    def take(self, names, trial, why, rse=math.inf):
        """Holds `names` at the machine file's values; trial is the refit with them held."""
        te = self.prep.test
        rel = (self.best.relerr(self.prep, te), trial.relerr(self.prep, te))
        for k in names:
            fitted = self.best.params().get(k)
            self.fixed[k] = self.p0.get(k, 0.0)
            self.held[k] = {"value": self.p0.get(k, 0.0), "rse": _r(rse), "fitted": fitted,
                            "relerr_percent": list(rel), "why": why}
        self.best = trial


def apply(prep, diag, p0, say=print):
    """Assesses the extended model of diag, holds at the machine file's
    values what the log cannot determine (set aside by the assessment,
    non-physical, a presliding zone the log does not show, moved by a
    borderline cause beyond its interval) and refits; replaces diag.extended
    and returns the report's "identifiability" block."""
    nominal_held = _hold_nominal_floor(prep, diag, p0, say)
    fit = diag.extended
    aside, rest = assess(prep, fit, p0)
    te = prep.test
    free_rel = fit.relerr(prep, te)
    h = _Holder(prep, fit, p0)
    kept = []
    for k, r in aside:
        if k not in HOLDABLE:
            kept.append((k, r))
            continue
        trial = h.trial({k: p0.get(k, 0.0)})
        if _at_bound(fit, k) or not _tells(prep, trial, fit, free_rel):
            why = (f"the log cannot separate it (95 % interval ±{_pct(r)} of the machine file's value; it needs "
                   f"{NEEDS[k]}): taken from the machine file")
        else:
            # poorly determined: the log shows a difference, but does not fix the value
            why = (f"poorly determined (95 % interval ±{_pct(r)} of the machine file's value; it needs {NEEDS[k]}): "
                   f"the log's fit {h.best.params()[k]:.4g} is no measurement, the machine file's value is taken")
        h.take((k,), trial, why, r)
    _hold_floor(h)
    _hold_unphysical(h)
    _hold_presliding(h)
    _hold_distorted(h, diag)
    _flag_bounds(h)
    prep.fixed = h.fixed if set(h.fixed) - {"Fc_ref_N"} else None  # best was refitted with exactly these
    diag.extended = h.best
    out = {"method": "relative standard error at the machine file's values, sensitivities over the training part "
                     f"(docs/diagnose.md, Identifiability); identified when {Z:g} rse <= {REL_95:g}",
           "identified": {k: _r(v) for k, v in rest.items() if k not in h.held and k not in h.kept_out},
           "held": h.held, "kept_out": {k: v for k, v in h.kept_out.items() if k not in h.held},
           "poorly_determined": {}, "borderline_moves": h.moves, "nominal_held": nominal_held}
    for k, v in h.held.items():
        say(f"identifiability: {k} = {v['value']:.4g}, the machine file's: {v['why']}")
    for k, r in kept:
        out["poorly_determined"][k] = {"rse": _r(r),
                                       "why": f"weakly determined (95 % interval ±{_pct(r)} of the machine file's "
                                              f"value; it needs {NEEDS[k]}); a cause's parameter: kept as fitted"}
    for k, why in out["kept_out"].items():
        say(f"identifiability: {k} not written to machine.json: {why}")
    if h.held:
        say(f"identifiability: extended model refitted with {', '.join(h.held)} held: held-out relerr "
            f"{free_rel:.4g} % -> {h.best.relerr(prep, te):.4g} %")
    return out


def _floor_why(name, fitted):
    return (f"on its floor ({fitted:.3g}, model.COEF_LOWER): the log pulls it to zero or below, it needs "
            f"{NEEDS[name]}: taken from the machine file")


def _hold_floor(h):
    """A FLOOR parameter of the extended model on its floor held at the machine file's value."""
    for k in FLOOR:
        if k not in h.fixed and _at_bound(h.best, k):
            h.take((k,), h.trial({k: h.p0[k]}), _floor_why(k, h.best.params()[k]))


def _hold_nominal_floor(prep, diag, p0, say):
    """The nominal model refitted with its FLOOR parameters that are on their
    floor held at the machine file's values (replaces diag.nominal); returns
    {param: {"value", "fitted", "relerr_percent", "why"}} of those held."""
    nom = diag.nominal
    on = [k for k in FLOOR if _at_bound(nom, k)]
    if not on:
        return {}
    fixed = {"Fc_ref_N": p0["Fc_N"], **{k: p0[k] for k in on}}
    held = _refit(prep, nom, fixed)
    prep.fixed = None
    rel = [nom.relerr(prep, prep.test), held.relerr(prep, prep.test)]
    out = {k: {"value": p0[k], "fitted": nom.params()[k], "relerr_percent": rel,
               "why": _floor_why(k, nom.params()[k])} for k in on}
    for k, v in out.items():
        say(f"identifiability: nominal {k} = {v['value']:.4g}, the machine file's: {v['why']}")
    diag.nominal = held
    return out


def _hold_unphysical(h):
    """A non-physical bristle damping (physical.py, P1) held at the machine file's value."""
    why = physical.unphysical(h.best).get("sigma1_Nspm", "")
    if "sigma1_Nspm" not in h.fixed and why.startswith(physical.NON_PHYSICAL):
        h.take(("sigma1_Nspm",), h.trial({"sigma1_Nspm": h.p0["sigma1_Nspm"]}), why + ": taken from the machine file")


def _flag_bounds(h):
    """The final model's values on a search bound (physical.py) kept out of
    machine.json (h.kept_out): the model keeps them, the log fits them better
    than the machine file's values."""
    for k, why in physical.unphysical(h.best).items():
        if k not in h.fixed:
            h.kept_out.setdefault(k, why + ": machine.json takes the machine file's value")


def _hold_presliding(h):
    """The presliding zone judged by the log, not by the fitted sigma0: the
    model refitted with a zone Fc/sigma0 of ZONE_STEPS position steps (1 nm
    without an encoder step in the log), which no log resolves; when the log
    cannot tell it from the fit (_tells), it does not show presliding: the
    model keeps that zone (the machine file's would put a presliding the log
    has not in it) and sigma0, sigma1 are kept out of machine.json."""
    if "sigma0_Npm" in h.fixed or "sigma0_Npm" not in _assessed(h.best):
        return
    prep = h.prep
    q = machinejson.encoder_step(prep.pos)
    zone = max(ZONE_STEPS * q, 1.0 / model.RHO_BOUNDS[1])
    flat_s0 = h.fixed["Fc_ref_N"] / zone
    flat = h.trial({"sigma0_Npm": flat_s0})
    rel = h.best.relerr(prep, prep.test)
    if _tells(prep, flat, h.best, rel):
        return
    why = (f"the log does not show the presliding zone: with a zone Fc/sigma0 of {zone:.3g} m ({ZONE_STEPS:g} "
           f"position step) the held-out relerr is {flat.relerr(prep, prep.test):.4g} % against the fit's "
           f"{rel:.4g} %, not worse (the fitted zone {h.best.params()['Fc_N'] / h.best.params()['sigma0_Npm']:.3g} m "
           "is no measurement): the model keeps that zone, machine.json takes the machine file's value")
    h.fixed["sigma0_Npm"] = flat_s0
    h.best = flat
    for k in ("sigma0_Npm", "sigma1_Nspm"):
        if k not in h.held:
            h.kept_out[k] = why


def _hold_distorted(h, diag):
    """A borderline cause (selection.borderline: not a finding) that moves a
    parameter beyond its 95 % interval (intervals.jackknife), and by more than
    the REL_95 an identified parameter may be off, when it is added to the
    model distorts it: the value without the cause is no measurement
    either: it is kept out of machine.json (h.kept_out). h.moves: {cause:
    {param: [without, with, interval]}} of every move beyond the interval."""
    border = [c["cause"] for c in selection.borderline(diag)]
    if not border:
        return
    prep = h.prep
    prep.fixed = h.fixed
    ivals = intervals.jackknife(prep, h.best)
    p = h.best.params()
    moved = {}
    for cause in border:
        w = model.add_cause(prep, h.best, cause)
        if w is None:
            continue
        q = model.refine(prep, w, rounds=1, max_nfev=selection.REFINE_NFEV).params()
        mv = {k: [p[k], q[k], list(ivals[k])] for k in _assessed(h.best)
              if k in NOMINAL and k in ivals and k not in h.fixed and not ivals[k][0] <= q[k] <= ivals[k][1]}
        h.moves[cause] = mv
        for k, (a, b, _) in mv.items():
            if abs(b - a) > REL_95 * abs(a):
                moved.setdefault(k, cause)
    for k, cause in moved.items():
        h.kept_out.setdefault(k, f"the borderline {cause} moves it beyond its 95 % interval (the model without it "
                                  f"{p[k]:.4g}, with it {h.moves[cause][k][1]:.4g}): machine.json takes the machine "
                                  "file's value")


def _at_bound(fit, name):
    """The free fit put the parameter on its physical bound (model.COEF_LOWER):
    the log pulls it beyond, to a non-physical value."""
    coef = model.FIXED_COEF.get(name, (None,))[0]
    if name == "dsigma2_neg_Nspm":
        return fit.coef.get("sigma2_neg", 1.0) <= model.COEF_LOWER["sigma2_neg"]
    return coef in model.COEF_LOWER and fit.coef.get(coef, 1.0) <= model.COEF_LOWER[coef]


def _tells(prep, held, free, free_rel):
    """The log tells the held model from the free one: its held-out relerr
    rises by more than HOLD_TOL, or the free model's squared error is lower
    consistently over the held-out blocks (selection's block test, p < P_MAX)."""
    if held.relerr(prep, prep.test) > free_rel * (1.0 + HOLD_TOL) + 1e-9:
        return True
    return selection.block_p_value(prep, held.residual(prep), free.residual(prep)) < selection.P_MAX


def _r(v):
    return None if not math.isfinite(v) else float(v)


def _pct(r):
    return "∞" if not math.isfinite(r) else f"{100 * Z * r:.3g} %"
