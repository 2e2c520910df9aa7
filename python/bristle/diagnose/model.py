# SPDX-License-Identifier: Apache-2.0
"""The force model fitted to a log: the nominal (thesis) model and its
extensions by the causes (causes/, one module each).

Force needed over interval k (load side):

  F = Meff a + sigma2 v + Fc (rho z) + sigma1 dz/dt                  nominal

with z from lugre.bristle along the measured path and the shape
(rho = sigma0/Fc, beta = Fs/Fc, vs). A cause extends it through the hooks of
its module (causes/__init__.py): columns added to the force, a factor on the
friction, the Stribeck curve in -x, the friction columns split by
direction, the force it is compared with. Columns that are nonlinear in the
motion (the LuGre ones, a ripple) are computed from the filtered position
and filtered once more (signals.Prepared.lp), like the force they are
compared with; a and v are linear in the position and are not.

Given the shape and the causes' nonlinear parameters (`nl`) the force is
linear in the rest (`coef`), which is solved by least squares on the
training part (variable projection); the shape and `nl` are searched
around that.
"""
import math

import numpy as np
from scipy import optimize

from . import causes as causes_
from . import lugre
from .signals import relerr

# bounds of the shape search
RHO_BOUNDS = (1e3, 1e9)      # sigma0 / Fc, 1/m: presliding lengths from 1 nm to 1 mm
BETA_BOUNDS = (1.0, 10.0)    # Fs / Fc
VS_BOUNDS = (1e-7, 0.1)      # Stribeck velocity, m/s
SHAPE_STARTS = ((2e5, 1.5, 1e-3), (2e6, 2.0, 3e-5))


class Fit:
    """One fitted model: causes, shape, nonlinear cause parameters, linear
    coefficients; predicts the force over the intervals of a Prepared log."""

    def __init__(self, causes, shape, nl, coef):
        self.causes = tuple(m.NAME for m in causes_.of(causes))
        self.shape = tuple(shape)
        self.nl = dict(nl)
        self.coef = dict(coef)

    def target(self, prep):
        return target(prep, self.causes, self.nl)

    def predict(self, prep):
        cols = columns(prep, self.shape, self.causes, self.nl)
        return sum(self.coef.get(k, 0.0) * c for k, c in cols.items())

    def residual(self, prep):
        return self.target(prep) - self.predict(prep)

    def relerr(self, prep, sl):
        y = self.target(prep)
        return relerr(y[sl], (y - self.predict(prep))[sl])

    def params(self):
        """Physical parameters, load side: model.json's "params" (params.py)."""
        c, (rho, beta, vs) = self.coef, self.shape
        Fc = c["Fc"]
        p = {
            "Meff_kg": c["Meff"],
            "sigma2_Nspm": c["sigma2"],
            "Fc_N": Fc,
            "Fs_N": beta * Fc,
            "vs_mps": vs,
            "sigma0_Npm": rho * Fc,
            "sigma1_Nspm": c.get("sigma1", 0.0),
        }
        for m in causes_.of(self.causes):
            p.update(m.params(c, self.nl, p))
        for adjust in causes_.hooks(causes_.of(self.causes), "adjust_nominal"):
            adjust(p, self.nl)
        return {k: float(v) for k, v in p.items()}

    def cause_params(self, cause):
        """The parameters the spec asks a finding of this cause to report
        (and what a cause reports from its nonlinear parameters: a list)."""
        m = causes_.get(cause)
        out = m.report_params(self.params())
        if hasattr(m, "report_nl"):
            out.update(m.report_nl(self.nl))
        return out


def from_params(p, causes, nl=None):
    """A Fit from physical parameters (a saved model); nl: nonlinear
    parameters that p does not hold (model.json's element set), taken where
    the causes' own do not give them."""
    Fc = p["Fc_N"]
    shape = (p["sigma0_Npm"] / Fc, p["Fs_N"] / Fc, p["vs_mps"])
    coef = {"Meff": p["Meff_kg"], "sigma2": p["sigma2_Nspm"], "Fc": Fc, "sigma1": p["sigma1_Nspm"]}
    nl = dict(nl or {})
    for m in causes_.of(causes):
        c, n = m.from_params(p)
        coef.update(c)
        nl.update(n)
    return Fit(causes, shape, nl, coef)


def _neg_ratio(mods, nl):
    """The Stribeck curve's scale in -x inside the bristle dynamics."""
    ratio = 1.0
    for hook in causes_.hooks(mods, "stribeck_neg_ratio"):
        ratio *= hook(nl)
    return ratio


FRICTION_HOOKS = ("stribeck_neg_ratio", "friction_scale", "friction_columns", "presliding_phi")


def _friction_columns(prep, shape, mods, nl):
    """The friction columns (viscous, LuGre level, sigma1) with what the
    causes do to the friction; a presliding cause replaces the bristle's
    level and rate columns by its own (causes/presliding_hysteresis.py)."""
    fmods = [m for m in mods if any(hasattr(m, h) for h in FRICTION_HOOKS)]

    def make():
        rho, beta, vs = shape
        ratio = _neg_ratio(fmods, nl)
        presliding = causes_.hooks(fmods, "presliding_phi")
        if presliding:
            phis, zd = presliding[0](prep, shape, ratio, nl)
        else:
            phi, zd = prep.memo(("bristle", shape, ratio),
                                lambda: lugre.bristle_columns(prep.dx, prep.dt, rho, beta, vs, neg_ratio=ratio))
            phis = {"Fc": phi}
        v = prep.v
        for scale in causes_.hooks(fmods, "friction_scale"):
            k = scale(prep, nl)
            phis = {name: k * phi for name, phi in phis.items()}
            zd, v = k * zd, k * v
        split = causes_.hooks(fmods, "friction_columns")
        level = phis.get("Fc", np.zeros(prep.n))
        cols = split[0](prep, nl, v, level) if split else {"sigma2": v, "Fc": prep.lp(level)}
        if "Fc" not in phis:   # the split form of the element set: one level column per element
            for name in ("Fc", "Fc_neg_split"):
                cols.pop(name, None)
            cols.update({name: prep.lp(phi) for name, phi in phis.items()})
        cols["sigma1"] = prep.lp(zd)
        return cols

    key = ("friction", shape) + tuple((m.NAME,) + tuple(nl.get(k) for k in m.NL) for m in fmods)
    return prep.memo(key, make)


def columns(prep, shape, causes, nl):
    """Design columns over all intervals, by coefficient name."""
    mods = causes_.of(causes)
    cols = {"Meff": prep.a}
    cols.update(_friction_columns(prep, shape, mods, nl))
    for load in causes_.hooks(mods, "load_columns"):
        cols.update(load(prep, nl))
    return cols


def target(prep, causes, nl):
    """The force the model is compared with: the filtered log's, or what a
    cause makes of it (a dead time)."""
    for hook in causes_.hooks(causes_.of(causes), "target"):
        return hook(prep, nl)
    return prep.y


# the physical lower bound of each linear coefficient (params.NOMINAL, the
# asymmetric cause's sigma2 + dsigma2_neg >= 0): a solution outside them is
# solved again with the bounds (docs/diagnose.md, "Identifiability")
COEF_LOWER = {"Meff": 1e-9, "sigma2": 0.0, "Fc": 1e-9, "sigma1": 0.0, "sigma2_neg": 0.0}
# the split form of a presliding element set: each element's Fc alpha_i >= 0
COEF_LOWER.update({name: 0.0 for m in causes_.REGISTRY for name in getattr(m, "ELEMENT_COLS", ())})

# a parameter held at a value (prep.fixed, identify.py) as a linear
# constraint on one coefficient: coef = value + sum(a * other coef)
FIXED_COEF = {"Meff_kg": ("Meff", {}), "sigma2_Nspm": ("sigma2", {}), "Fc_N": ("Fc", {}),
              "sigma1_Nspm": ("sigma1", {}), "dsigma2_neg_Nspm": ("sigma2_neg", {"sigma2": 1.0})}
# a shape parameter held: its index in (rho, beta, vs) and its value from
# the held parameters (the machine file's ratio to Fc for sigma0 and Fs)
FIXED_SHAPE = {"sigma0_Npm": (0, lambda f: f["sigma0_Npm"] / f["Fc_ref_N"]),
               "Fs_N": (1, lambda f: f["Fs_N"] / f["Fc_ref_N"]),
               "vs_mps": (2, lambda f: f["vs_mps"])}


def _held(prep, cols):
    """{coef: (value, {other: a})} of the parameters held on this log."""
    fixed = getattr(prep, "fixed", None) or {}
    out = {}
    for name, v in fixed.items():
        if name in FIXED_COEF and FIXED_COEF[name][0] in cols:
            coef, tie = FIXED_COEF[name]
            out[coef] = (v, {k: a for k, a in tie.items() if k in cols})
    # a tie to a held coefficient is a value (the ties are one level deep: FIXED_COEF)
    for e, (v, tie) in list(out.items()):
        held = {k: a for k, a in tie.items() if k in out}
        out[e] = (v + sum(a * out[k][0] for k, a in held.items()), {k: a for k, a in tie.items() if k not in held})
    return out


def solve(prep, shape, causes, nl):
    """Linear least squares of the coefficients on the training part, the
    held parameters (prep.fixed) substituted, within COEF_LOWER (bounded
    least squares when the free solution leaves them). The fit keeps its
    training residual and sum of squares (train_sse)."""
    cols = columns(prep, shape, causes, nl)
    y = target(prep, causes, nl)
    tr = prep.train
    held = _held(prep, cols)
    free = [k for k in cols if k not in held]
    # coef_e = v_e + sum a_ek coef_k: its column moves to the target and onto the others'
    yt = y[tr].copy()
    Xc = {k: cols[k][tr].copy() for k in free}
    for e, (v, tie) in held.items():
        yt -= v * cols[e][tr]
        for k, a in tie.items():
            Xc[k] += a * cols[e][tr]
    X = np.column_stack([Xc[k] for k in free])
    sol, *_ = np.linalg.lstsq(X, yt, rcond=None)
    lo = np.array([COEF_LOWER.get(k, -np.inf) for k in free])
    if np.any(sol < lo):
        sol = optimize.lsq_linear(X, yt, bounds=(lo, np.full(len(free), np.inf)), method="bvls").x
    coef = dict(zip(free, sol))
    for e, (v, tie) in held.items():
        coef[e] = v + sum(a * coef[k] for k, a in tie.items())
    coef.setdefault("sigma1", 0.0)
    fit = Fit(causes, shape, nl, coef)
    fit.train_resid = yt - X @ sol
    fit.train_sse = float(fit.train_resid @ fit.train_resid)
    return fit


def _held_shape(prep):
    """{index in (log rho, beta, log vs): value} of the held shape parameters."""
    fixed = getattr(prep, "fixed", None) or {}
    out = {}
    for name, (i, value) in FIXED_SHAPE.items():
        if name in fixed:
            v = value(fixed)
            out[i] = math.log(v) if i != 1 else v
    return out


def fit_shape(prep, causes, nl, starts=SHAPE_STARTS, max_nfev=40):
    """Searches the LuGre shape (log rho, beta, log vs) by bounded least
    squares on the training residual, the coefficients solved inside; a
    held shape parameter (prep.fixed) is not searched."""
    lo = np.array([math.log(RHO_BOUNDS[0]), BETA_BOUNDS[0], math.log(VS_BOUNDS[0])])
    hi = np.array([math.log(RHO_BOUNDS[1]), BETA_BOUNDS[1], math.log(VS_BOUNDS[1])])
    ratio = _neg_ratio(causes_.of(causes), nl)
    held = _held_shape(prep)
    # a shape parameter the causes' friction does not use (rho with a Maxwell-slip element set)
    for i in {i for m in causes_.of(causes) for i in getattr(m, "SHAPE_UNUSED", ())}:
        held.setdefault(i, math.log(starts[0][0]) if i != 1 else starts[0][1])
    free = [i for i in range(3) if i not in held]

    def unpack(uf):
        u = [held.get(i, 0.0) for i in range(3)]
        for i, x in zip(free, uf):
            u[i] = x
        return (math.exp(u[0]), u[1], math.exp(u[2]))

    def resid(uf):
        shape = unpack(uf)
        r = solve(prep, shape, causes, nl).train_resid
        prep.forget(("bristle", shape, ratio))  # a shape is seldom seen twice
        return r

    if not free:
        return solve(prep, unpack(()), causes, nl)
    best = None
    for s in starts:
        u0 = np.clip([math.log(s[0]), s[1], math.log(s[2])], lo + 1e-9, hi - 1e-9)[free]
        r = optimize.least_squares(resid, u0, bounds=(lo[free], hi[free]), diff_step=1e-4,
                                   x_scale=np.array([1.0, 0.5, 1.0])[free], max_nfev=max_nfev, xtol=1e-5, ftol=1e-7)
        if best is None or r.cost < best.cost:
            best = r
    return solve(prep, unpack(best.x), causes, nl)


def search_cause(prep, base, cause, causes, nl):
    """The nonlinear parameters of `cause` in the model base.shape + causes
    ({} when it has none, None when the log cannot show it)."""
    def fit_with(extra):
        return solve(prep, base.shape, causes, dict(nl, **extra))

    return causes_.get(cause).search(prep, base, fit_with)


def add_cause(prep, base, cause):
    """base + cause with base's shape held: the cause's nonlinear parameters
    searched, the coefficients solved. None if the cause cannot be fitted.
    A cause that replaces the bristle (OWN_SHAPE: an element set) has its
    shape searched with it (add_with_shape)."""
    if getattr(causes_.get(cause), "OWN_SHAPE", False):
        return add_with_shape(prep, base, cause)
    causes = base.causes + (cause,)
    extra = search_cause(prep, base, cause, causes, base.nl)
    if extra is None:
        return None
    return solve(prep, base.shape, causes, dict(base.nl, **extra))


def add_with_shape(prep, base, cause, max_nfev=20):
    """base + cause when the cause replaces the friction the base's shape was
    fitted with: from the base's shape and each of SHAPE_STARTS, the cause's
    search at that shape, the shape searched with it, the cause searched again
    at the shape found; the lowest training error. None if it cannot be fitted."""
    causes = base.causes + (cause,)
    best = None
    for start in (base.shape,) + SHAPE_STARTS:
        at = solve(prep, start, base.causes, base.nl)
        extra = search_cause(prep, at, cause, causes, base.nl)
        if extra is None:
            continue
        fit = fit_shape(prep, causes, dict(base.nl, **extra), starts=(start,), max_nfev=max_nfev)
        extra = search_cause(prep, fit, cause, causes, fit.nl)
        fit = solve(prep, fit.shape, causes, dict(fit.nl, **extra))
        if best is None or fit.train_sse < best.train_sse:
            best = fit
    return best


def refine(prep, fit, rounds=2, max_nfev=40):
    """Alternates the shape search (from the current shape) and each cause's
    nonlinear search (the others held)."""
    for _ in range(rounds):
        fit = fit_shape(prep, fit.causes, fit.nl, starts=(fit.shape,), max_nfev=max_nfev)
        nl = dict(fit.nl)
        for c in fit.causes:
            others = solve(prep, fit.shape, tuple(x for x in fit.causes if x != c), nl)
            extra = search_cause(prep, others, c, fit.causes, nl)
            if extra:
                nl.update(extra)
        fit = solve(prep, fit.shape, fit.causes, nl)
    return fit


def fit_nominal(prep):
    """The thesis model: rigid body + viscous + symmetric LuGre with Stribeck."""
    return fit_shape(prep, (), {})
