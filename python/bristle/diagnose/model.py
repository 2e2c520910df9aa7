"""The force model fitted to a log: the nominal (thesis) model and its
extensions by the causes of ../shared/spec/measured-log.md.

Force needed over interval k (load side), with k(x) = max(0, 1 + s x):

  F = M a + k(x) [ Fv_d v + Fc_d (rho z) + sigma1 dz/dt ]            nominal: k = 1, one Fv, one Fc
      + offset + A sin(2 pi x / P + phase)                            offset, position_ripple
  compared with the logged force delayed by the dead time d           actuator_delay

Fv_d, Fc_d: one value each (nominal) or one per direction
(asymmetric_friction: Fv by the sign of v; the whole Stribeck curve in -x is
c = Fc_neg / Fc times that in +x, inside the bristle dynamics too, exactly as
the plant simulator does). z follows lugre.bristle with the shape
(rho = sigma0/Fc, beta = Fs/Fc, vs) and c. Columns that
are nonlinear in the motion (the LuGre ones, the ripple) are computed from the
filtered position and filtered once more (signals.Prepared.lp), like the force
they are compared with; a and v are linear in the position and are not.

Given the shape and the causes' nonlinear parameters (P, s, d) the force is
linear in the rest, which is solved by least squares on the training part
(variable projection); the shape and (P, s, d) are searched around that.
"""
import math

import numpy as np
from scipy import optimize

from . import lugre
from .signals import relerr

CAUSES = ("offset", "asymmetric_friction", "position_ripple", "position_gradient", "actuator_delay")

# bounds of the searches
RHO_BOUNDS = (1e3, 1e9)      # sigma0 / Fc, 1/m: presliding lengths from 1 nm to 1 mm
BETA_BOUNDS = (1.0, 10.0)    # Fs / Fc
VS_BOUNDS = (1e-7, 0.1)      # Stribeck velocity, m/s
DELAY_MAX_S = 0.02           # actuator dead time searched over 0 .. 20 ms
PERIODOGRAM_DECIMATE = 4     # the residual is low-passed far below the sampling rate
FC_RATIO_BOUNDS = (0.2, 5.0)  # Fc_neg / Fc
SHAPE_STARTS = ((2e5, 1.5, 1e-3), (2e6, 2.0, 3e-5))


class Fit:
    """One fitted model: causes, shape, nonlinear cause parameters, linear
    coefficients; predicts the force over the intervals of a Prepared log."""

    def __init__(self, causes, shape, nl, coef):
        self.causes = tuple(c for c in CAUSES if c in causes)
        self.shape = tuple(shape)
        self.nl = dict(nl)
        self.coef = dict(coef)

    def has(self, cause):
        return cause in self.causes

    def target(self, prep):
        return _target(prep, self.causes, self.nl)

    def predict(self, prep):
        cols = columns(prep, self.shape, self.causes, self.nl)
        return sum(self.coef.get(k, 0.0) * c for k, c in cols.items())

    def residual(self, prep):
        return self.target(prep) - self.predict(prep)

    def relerr(self, prep, sl):
        y = self.target(prep)
        return relerr(y[sl], (y - self.predict(prep))[sl])

    def params(self):
        """Physical parameters, load side (the names of model.json)."""
        c, (rho, beta, vs) = self.coef, self.shape
        asym = self.has("asymmetric_friction")
        Fc = c["Fc"]
        Fv = c["Fv_pos"] if asym else c["Fv"]
        p = {
            "M_kg": c["M"],
            "Fv_Nspm": Fv,
            "Fc_N": Fc,
            "Fs_N": beta * Fc,
            "vs_mps": vs,
            "sigma0_Npm": rho * Fc,
            "sigma1_Nspm": c.get("sigma1", 0.0),
        }
        if asym:
            p["Fc_neg_N"] = self.nl["fc_ratio"] * Fc
            p["Fv_neg_Nspm"] = c["Fv_neg"]
        if self.has("offset"):
            p["offset_N"] = c["offset"]
        if self.has("position_ripple"):
            a_s, a_c = c["ripple_sin"], c["ripple_cos"]
            p["ripple_amp_N"] = math.hypot(a_s, a_c)
            p["ripple_period_m"] = self.nl["period_m"]
            p["ripple_phase_rad"] = math.atan2(a_c, a_s)
        if self.has("position_gradient"):
            p["grad_per_m"] = self.nl["grad_per_m"]
        if self.has("actuator_delay"):
            p["delay_s"] = self.nl["delay_s"]
        return {k: float(v) for k, v in p.items()}

    def cause_params(self, cause):
        """The parameters the spec asks a finding to report."""
        p = self.params()
        if cause == "offset":
            return {"force_N": p["offset_N"]}
        if cause == "asymmetric_friction":
            return {"Fc_pos_N": p["Fc_N"], "Fc_neg_N": p["Fc_neg_N"],
                    "Fv_pos_Nspm": p["Fv_Nspm"], "Fv_neg_Nspm": p["Fv_neg_Nspm"]}
        if cause == "position_ripple":
            return {"period_m": p["ripple_period_m"], "amplitude_N": p["ripple_amp_N"],
                    "phase_rad": p["ripple_phase_rad"]}
        if cause == "position_gradient":
            return {"relative_slope_per_m": p["grad_per_m"]}
        if cause == "actuator_delay":
            return {"delay_s": p["delay_s"]}
        raise ValueError(cause)


def from_params(p, causes):
    """A Fit from physical parameters (a saved model)."""
    Fc = p["Fc_N"]
    shape = (p["sigma0_Npm"] / Fc, p["Fs_N"] / Fc, p["vs_mps"])
    coef = {"M": p["M_kg"], "sigma1": p.get("sigma1_Nspm", 0.0), "Fc": Fc}
    nl = {}
    if "asymmetric_friction" in causes:
        coef.update(Fv_pos=p["Fv_Nspm"], Fv_neg=p["Fv_neg_Nspm"])
        nl["fc_ratio"] = p["Fc_neg_N"] / Fc
    else:
        coef.update(Fv=p["Fv_Nspm"])
    if "offset" in causes:
        coef["offset"] = p["offset_N"]
    if "position_ripple" in causes:
        A, ph = p["ripple_amp_N"], p["ripple_phase_rad"]
        coef.update(ripple_sin=A * math.cos(ph), ripple_cos=A * math.sin(ph))
        nl["period_m"] = p["ripple_period_m"]
    if "position_gradient" in causes:
        nl["grad_per_m"] = p["grad_per_m"]
    if "actuator_delay" in causes:
        nl["delay_s"] = p["delay_s"]
    return Fit(causes, shape, nl, coef)


def _cached(prep, key, make):
    """Per-log memo of column blocks (the searches reuse them many times)."""
    cache = prep.__dict__.setdefault("_model_cache", {})
    if key not in cache:
        if len(cache) > 64:
            cache.clear()
        cache[key] = make()
    return cache[key]


def _friction_columns(prep, shape, causes, nl):
    """The friction columns (viscous, LuGre level, sigma1), with the gradient
    and the direction split applied."""
    grad = nl["grad_per_m"] if "position_gradient" in causes else None
    asym = "asymmetric_friction" in causes
    split = nl.get("fc_split", False)  # asymmetric: Fc per sign of z, z symmetric (first estimate of c)
    ratio = nl["fc_ratio"] if asym and not split else 1.0

    def make():
        rho, beta, vs = shape
        phi, zd = _cached(prep, ("bristle", shape, ratio),
                          lambda: lugre.bristle_columns(prep.dx, prep.dt, rho, beta, vs, neg_ratio=ratio))
        v = prep.v
        if grad is not None:
            k = np.maximum(0.0, 1.0 + grad * prep.xm)
            phi, zd, v = k * phi, k * zd, k * v
        cols = {}
        if asym:
            cols["Fv_pos"] = np.maximum(v, 0.0)
            cols["Fv_neg"] = np.minimum(v, 0.0)
        else:
            cols["Fv"] = v
        if split:
            cols["Fc"] = prep.lp(np.maximum(phi, 0.0))
            cols["Fc_neg_split"] = prep.lp(np.minimum(phi, 0.0))
        else:
            cols["Fc"] = prep.lp(phi)
        cols["sigma1"] = prep.lp(zd)
        return cols

    return _cached(prep, ("friction", shape, grad, asym, ratio, split), make)


def columns(prep, shape, causes, nl):
    """Design columns over all intervals, by coefficient name."""
    cols = {"M": prep.a}
    cols.update(_friction_columns(prep, shape, causes, nl))
    if "offset" in causes:
        cols["offset"] = _cached(prep, ("ones",), lambda: np.ones(prep.n))
    if "position_ripple" in causes:
        P = nl["period_m"]

        def make():
            th = 2.0 * np.pi * prep.xm / P
            return prep.lp(np.sin(th)), prep.lp(np.cos(th))

        cols["ripple_sin"], cols["ripple_cos"] = _cached(prep, ("ripple", P), make)
    return cols


def _target(prep, causes, nl):
    if "actuator_delay" not in causes:
        return prep.y
    d = nl.get("delay_s", 0.0)
    return _cached(prep, ("target", d), lambda: prep.y_delayed(d))


def solve(prep, shape, causes, nl):
    """Linear least squares of the coefficients on the training part; sigma1
    is kept >= 0 (dropped when the free solution is negative). The fit keeps
    its training sum of squares (train_sse)."""
    cols = columns(prep, shape, causes, nl)
    y = _target(prep, causes, nl)
    names = list(cols)
    tr = prep.train
    yt = y[tr]
    for _ in range(2):
        X = np.column_stack([cols[k][tr] for k in names])
        sol, *_ = np.linalg.lstsq(X, yt, rcond=None)
        coef = dict(zip(names, sol))
        if coef.get("sigma1", 0.0) >= 0.0:
            break
        names.remove("sigma1")
    coef.setdefault("sigma1", 0.0)
    fit = Fit(causes, shape, nl, coef)
    fit.train_resid = yt - X @ sol
    fit.train_sse = float(fit.train_resid @ fit.train_resid)
    return fit


def train_sse(fit, prep):
    return fit.train_sse


def fit_shape(prep, causes, nl, starts=SHAPE_STARTS, max_nfev=40):
    """Searches the LuGre shape (log rho, beta, log vs) by bounded least
    squares on the training residual, the coefficients solved inside."""
    lo = np.array([math.log(RHO_BOUNDS[0]), BETA_BOUNDS[0], math.log(VS_BOUNDS[0])])
    hi = np.array([math.log(RHO_BOUNDS[1]), BETA_BOUNDS[1], math.log(VS_BOUNDS[1])])

    def unpack(u):
        return (math.exp(u[0]), u[1], math.exp(u[2]))

    def resid(u):
        shape = unpack(u)
        r = solve(prep, shape, causes, nl).train_resid
        prep.__dict__.get("_model_cache", {}).pop(("bristle", shape, nl.get("fc_ratio", 1.0)), None)
        return r

    best = None
    for s in starts:
        u0 = np.clip([math.log(s[0]), s[1], math.log(s[2])], lo + 1e-9, hi - 1e-9)
        r = optimize.least_squares(resid, u0, bounds=(lo, hi), diff_step=1e-4, x_scale=[1.0, 0.5, 1.0],
                                   max_nfev=max_nfev, xtol=1e-5, ftol=1e-7)
        if best is None or r.cost < best.cost:
            best = r
    return solve(prep, unpack(best.x), causes, nl)


def position_periodogram(e, x, periods):
    """Amplitude of the best sin/cos fit of e at each period over position x."""
    amps = np.empty(len(periods))
    for i in range(0, len(periods), 64):
        P = np.asarray(periods[i:i + 64])[:, None]
        th = 2.0 * np.pi * x[None, :] / P
        s, c = np.sin(th), np.cos(th)
        ss, cc, sc = (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
        es, ec = s @ e, c @ e
        det = ss * cc - sc * sc
        a = (cc * es - sc * ec) / det
        b = (ss * ec - sc * es) / det
        amps[i:i + 64] = np.hypot(a, b)
    return amps


def ripple_period_range(prep):
    """Periods the ripple test searches: at least the distance the axis
    covers in one filter-cutoff period at its 95th-percentile speed (shorter
    ones are filtered away), at most a third of the travel."""
    sl = prep.whole
    v95 = float(np.percentile(np.abs(prep.v[sl]), 95))
    travel = float(np.ptp(prep.xm[sl]))
    pmin = max(v95 / prep.fc_hz, 1e-5)
    pmax = travel / 3.0
    return pmin, pmax


def fit_ripple_period(prep, base, causes, nl):
    """Period of a position ripple: the highest peak of the training
    residual's periodogram over position, refined by a bounded search."""
    pmin, pmax = ripple_period_range(prep)
    if not pmax > 1.5 * pmin:
        return None
    periods = np.geomspace(pmin, pmax, 400)
    tr = slice(prep.train.start, prep.train.stop, PERIODOGRAM_DECIMATE)
    amps = position_periodogram(base.residual(prep)[tr], prep.xm[tr], periods)
    best = None
    for i in np.argsort(amps)[::-1][:3]:
        P0 = periods[i]
        g = periods[1] / periods[0]

        def sse(lp):
            return train_sse(solve(prep, base.shape, causes, dict(nl, period_m=math.exp(lp))), prep)

        r = optimize.minimize_scalar(sse, bounds=(math.log(P0 / g ** 2), math.log(P0 * g ** 2)), method="bounded",
                                     options={"xatol": 1e-5})
        if best is None or r.fun < best[1]:
            best = (math.exp(r.x), r.fun)
    return best[0]


def fit_gradient(prep, base, causes, nl):
    """Relative slope s of k(x) = 1 + s x: bounded scalar search of the
    training error, within |s| < 0.95 / max|x| (k stays positive on the log)."""
    xmax = float(np.max(np.abs(prep.xm[prep.whole])))
    smax = 0.95 / max(xmax, 1e-6)

    def sse(s):
        return train_sse(solve(prep, base.shape, causes, dict(nl, grad_per_m=s)), prep)

    grid = np.linspace(-smax, smax, 21)
    vals = [sse(s) for s in grid]
    i = int(np.argmin(vals))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    r = optimize.minimize_scalar(sse, bounds=(a, b), method="bounded", options={"xatol": 1e-4 * smax})
    return float(r.x)


def fit_delay(prep, base, causes, nl):
    """Dead time d in 0 .. DELAY_MAX_S: a grid of half a period, then a
    bounded scalar search around its best point."""
    dt = prep.dt

    def sse(d):
        return train_sse(solve(prep, base.shape, causes, dict(nl, delay_s=max(d, 0.0))), prep)

    grid = np.arange(0.0, DELAY_MAX_S + 1e-12, 0.5 * dt)
    vals = [sse(d) for d in grid]
    i = int(np.argmin(vals))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if b <= a:
        return float(grid[i])
    r = optimize.minimize_scalar(sse, bounds=(a, b), method="bounded", options={"xatol": 1e-3 * dt})
    return float(max(r.x, 0.0))


def fit_fc_ratio(prep, base, causes, nl):
    """c = Fc_neg / Fc of asymmetric friction: first from a linear fit with
    the LuGre level split by the sign of z (symmetric bristle dynamics), then
    a bounded scalar search with c inside the bristle dynamics."""
    split = solve(prep, base.shape, causes, dict(nl, fc_split=True, fc_ratio=1.0))
    c0 = split.coef["Fc_neg_split"] / split.coef["Fc"] if split.coef["Fc"] > 0 else 1.0
    c0 = min(max(c0, FC_RATIO_BOUNDS[0]), FC_RATIO_BOUNDS[1])

    def sse(lc):
        return train_sse(solve(prep, base.shape, causes, dict(nl, fc_ratio=math.exp(lc))), prep)

    lo = max(math.log(c0) - 0.2, math.log(FC_RATIO_BOUNDS[0]))
    hi = min(math.log(c0) + 0.2, math.log(FC_RATIO_BOUNDS[1]))
    r = optimize.minimize_scalar(sse, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
    return float(math.exp(r.x))


def fit_cause_nl(prep, base, cause, causes, nl):
    """The nonlinear parameter a cause brings (None when it has none, or
    when it cannot be searched on this log)."""
    if cause == "position_ripple":
        P = fit_ripple_period(prep, base, causes, nl)
        return None if P is None else {"period_m": P}
    if cause == "position_gradient":
        return {"grad_per_m": fit_gradient(prep, base, causes, nl)}
    if cause == "actuator_delay":
        return {"delay_s": fit_delay(prep, base, causes, nl)}
    if cause == "asymmetric_friction":
        return {"fc_ratio": fit_fc_ratio(prep, base, causes, nl)}
    return {}


def add_cause(prep, base, cause):
    """base + cause with base's shape held: the cause's nonlinear parameter is
    searched, the coefficients solved. None if the cause cannot be fitted."""
    causes = base.causes + (cause,)
    extra = fit_cause_nl(prep, base, cause, causes, base.nl)
    if extra is None:
        return None
    return solve(prep, base.shape, causes, dict(base.nl, **extra))


def refine(prep, fit, rounds=2, max_nfev=40):
    """Alternates the shape search (from the current shape) and the causes'
    nonlinear searches."""
    for _ in range(rounds):
        fit = fit_shape(prep, fit.causes, fit.nl, starts=(fit.shape,), max_nfev=max_nfev)
        nl = dict(fit.nl)
        for c in fit.causes:
            others = Fit(tuple(x for x in fit.causes if x != c), fit.shape, nl, fit.coef)
            extra = fit_cause_nl(prep, _refit_without(prep, others), c, fit.causes, nl)
            if extra:
                nl.update(extra)
        fit = solve(prep, fit.shape, fit.causes, nl)
    return fit


def _refit_without(prep, fit):
    return solve(prep, fit.shape, fit.causes, {k: v for k, v in fit.nl.items()})


def fit_nominal(prep):
    """The thesis model: rigid body + viscous + symmetric LuGre with Stribeck."""
    return fit_shape(prep, (), {})
