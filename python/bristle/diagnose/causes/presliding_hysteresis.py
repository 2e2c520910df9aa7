# SPDX-License-Identifier: Apache-2.0
"""presliding_hysteresis: presliding friction with non-local memory that
LuGre's single bristle cannot follow (../shared/spec/presliding.md): after a
reversal the force builds over a travel and with a shape of its own, the
curve of a Maxwell-slip element set (Al-Bender, Lampaert, Swevers, IEEE TAC
50(11), 2005).

Force model (docs/diagnose.md, "presliding_hysteresis"): the LuGre level
column Fc (rho z) is replaced by the clamp form of the generalized
Maxwell-slip friction with the same Stribeck curve, elements i with
breakaway displacement d_i at Fs and share alpha_i (sum 1):

  Delta_i(v) = d_i g(v) / Fs = d_i gn(v) / beta         (gn = g / Fc, lugre.stribeck)
  z_i       <- clamp(z_i + dx, -Delta_i, +Delta_i)       (presliding.md, C -> infinity)
  F          = sum_i alpha_i Fs z_i / d_i = Fc [beta sum_i alpha_i u_i],  u_i = z_i / d_i

so the force is linear in Fc given the shape and the element set; the
elements' damping, sigma1 on each element's rate (the plant's, plant.md),
is the column sum_i dz_i/dt (v times the number of elements sticking). rho
(LuGre's sigma0 / Fc) does not enter.

Search (the element set): the split form, one column beta u_i per element of
a fixed grid of GRID_N breakaway displacements (geometric from GRID_MIN_M,
at least GRID_MIN_QUANTA position steps, to GRID_MAX_M), whose coefficients
Fc alpha_i are solved by bounded least squares (>= 0, model.COEF_LOWER):
the weights that stay above MIN_SHARE of their sum are the element set.

What a log pins: the elements' stiffnesses k_i = alpha_i Fs / d_i (the
force-travel curve after a reversal) and the sliding level; the breakaway
displacements at Fs, and so presliding_m, scale with the Fs the fit finds,
which a log with little sliding near the Stribeck velocity does not fix
(d_i / Fs is what the curve shows). On such a log presliding_m is as good
as Fs (docs/diagnose.md, "presliding_hysteresis").

The clamp recursion along the measured path is a composition of clamps:
with y_k = z_k - x_k (x the path), y_k = clamp(y_k-1, -Delta_k - x_k,
Delta_k - x_k), and the composition of two clamps is a clamp, so
`clamp_scan` evaluates it for all k by a parallel prefix (Hillis-Steele) in
log2(n) vectorised passes, as lugre.affine_scan does for the bristle.

Reported (measured-log.md): presliding_m, the travel after a slow reversal
from steady sliding at which the force has covered 90 % of its swing from
-Fs to +Fs (sum_i alpha_i min(x / d_i, 2) = 1.8), and the elements as
{breakaway_m, share}. The element set goes into model.json's "presliding"
object and machine.json's friction_model (maxwell_slip), which the firmware
estimators read (docs/modules/mslip.md)."""
import itertools
import math

import numpy as np
from scipy import optimize

from .. import lugre

NAME = "presliding_hysteresis"
MEANING = ("presliding friction with non-local memory that LuGre's single bristle cannot follow: after a "
           "reversal the force builds over a travel and with a shape of its own (a Maxwell-slip element set)")
ACTION = ("Expect it on rolling contacts (ball screw, recirculating guides): it is the contact, not a fault. Give "
          "the estimators the element set (machine.json's friction_model, maxwell_slip, written by this "
          "diagnosis); a change of presliding_m over the machine's life follows the preload and the lubricant.")
OPTION = "--gms"   # br_simlog's Maxwell-slip plant (the elements' breakaway displacements)
PARAMS = ()        # the element set is a list: model.json's "presliding" object (modelfile.py)
NL = ("ps_grid", "ps_breakaway", "ps_share")
HOOK = "state"
GRID_N = 8                 # firmware/include/bristle/br_mslip.h's BR_MSLIP_MAX
GRID_MIN_M = 0.3e-6        # presliding.md's range of breakaway displacements: 0.3 .. 30 um
GRID_MAX_M = 30e-6
GRID_MIN_QUANTA = 2.0      # a breakaway shorter than two position steps is not seen in a log
# a log with fewer presliding samples (moving, within GRID_MAX_M of a reversal, in the
# training part) cannot show the cause: the identification run has 415, the 5 mm/s
# back-and-forth 47, EMPS 45, and on each the element set lost to (or tied with) the
# bristle on held-out data; the thesis circle has 4000 (docs/diagnose.md)
MIN_PRESLIDING_SAMPLES = 500
MIN_SHARE = 0.01          # an element carrying less of the level is not worth its cycles in the estimator
ELEMENT_COLS = tuple(f"ps_el{i}" for i in range(GRID_N))
OWN_SHAPE = True           # the base's Stribeck shape was fitted with a bristle: searched again (model.add_with_shape)
SHAPE_UNUSED = (0,)        # rho, in model.fit_shape's (log rho, beta, log vs)
UNUSED_PARAMS = ("sigma0_Npm",)   # the element set's initial stiffness, not a fitted one: identify.py skips it
# detection_limits.py: the size is the largest breakaway d_max over LuGre's Fs / sigma0 (ref's
# presliding_scale_m), the elements at the demo's hardware-like shape (2, 5, 10, 20 um: docs/demo.md),
# equal shares, each element's mode on the moving mass at the damping ratio of LuGre's bristle mode
# (ref's presliding_zeta, br_simlog --gms-zeta): the plant's presliding dynamics change with d_max only
# in their length scale, not in their damping (docs/detection-limits.md); the ladder from 0.05 (its top,
# 6.4, puts d_max at 28.8 um, within the grid's GRID_MAX_M); on identification logs with the reversal
# segment (DETECTION_LOG: docs/diagnose.md asks for it, too few samples near reversals otherwise)
DETECTION_SHAPE = (0.1, 0.25, 0.5, 1.0)
DETECTION = ("largest breakaway d_max / LuGre's Fs/sigma0 (elements at 0.1, 0.25, 0.5, 1 d_max)", "", 0.05,
             lambda s, ref: ["--gms", ",".join(f"{s * ref['presliding_scale_m'] * f:.6g}" for f in DETECTION_SHAPE),
                             "--gms-zeta", f"{ref['presliding_zeta']:.6g}"])
DETECTION_LOG = "ident with the reversal segment"


def clamp_scan(lo, hi, y0):
    """y_k = clamp(y_k-1, lo_k, hi_k) for k = 0.. along the last axis
    (lo <= hi), y_-1 = y0: the clamps composed by a parallel prefix."""
    lo = np.array(lo, dtype=float)
    hi = np.array(hi, dtype=float)
    n = lo.shape[-1]
    s = 1
    while s < n:
        # map k after map k - s: clamp(clamp(y, a, b), c, d) = clamp(y, clip(a, c, d), clip(b, c, d))
        c, d = lo[..., s:], hi[..., s:]
        a = np.clip(lo[..., :-s], c, d)
        b = np.clip(hi[..., :-s], c, d)
        lo[..., s:], hi[..., s:] = a, b
        s *= 2
    return np.clip(y0, lo, hi)


def element_states(dx, dt, d, beta, vs, neg_ratio=1.0):
    """(u, rate) along the displacements dx (one per interval) for the
    breakaway displacements d (array), from undeflected elements, each of
    shape (len(d), len(dx)): u_i = z_i / d_i, the mean of each interval's start
    and end, and dz_i/dt over the interval (v while the element sticks, 0 at
    its bound)."""
    dx = np.asarray(dx, dtype=float)
    d = np.asarray(d, dtype=float)[:, None]
    x = np.cumsum(dx)
    # Delta_i at the interval's velocity (presliding.md: alpha_i s(v) / k_i = d_i s(v) / Fs)
    delta = d * (lugre.stribeck(dx / dt, beta, vs, neg_ratio) / beta)[None, :]
    # the clamp in y = z - x: y_k = clamp(y_k-1, -Delta_k - x_k, Delta_k - x_k)
    y = clamp_scan(-delta - x, delta - x, 0.0)
    z_end = y + x
    z_start = np.concatenate([np.zeros((len(d), 1)), z_end[:, :-1]], axis=1)
    return 0.5 * (z_start + z_end) / d, (z_end - z_start) / dt


def grid(prep):
    """The breakaway displacements the split form searches over."""
    from ..machinejson import encoder_step  # the log's position step
    lo = max(GRID_MIN_M, GRID_MIN_QUANTA * encoder_step(prep.pos))
    return tuple(float(g) for g in np.geomspace(lo, max(GRID_MAX_M, 4.0 * lo), GRID_N))


def presliding_phi(prep, shape, ratio, nl):
    """({column name: unfiltered column}, damping column): the Maxwell-slip
    level column ("Fc") of the element set, or the split form's one per grid
    element; and the elements' summed rate sum_i dz_i/dt (the split form: the
    grid's mean), sigma1's column (one damping sigma1 per element)."""
    _, beta, vs = shape
    if nl.get("ps_grid"):
        key = ("ps_split", shape, ratio, nl["ps_grid"])
        u, rate = prep.memo(key, lambda: element_states(prep.dx, prep.dt, nl["ps_grid"], beta, vs, ratio))
        return {c: beta * ui for c, ui in zip(ELEMENT_COLS, u)}, rate.mean(axis=0)
    d, a = np.asarray(nl["ps_breakaway"]), np.asarray(nl["ps_share"])

    def make():
        u, rate = element_states(prep.dx, prep.dt, d, beta, vs, ratio)
        return beta * (a @ u), rate.sum(axis=0)

    phi, zd = prep.memo(("ps", shape, ratio, nl["ps_breakaway"], nl["ps_share"]), make)
    return {"Fc": phi}, zd


def presliding_samples(prep):
    """The training part's intervals that move within GRID_MAX_M of travel
    after a reversal (the measured path steps): where an element set and a
    bristle differ."""
    s = since_reversal(prep)[prep.train]
    return int(np.count_nonzero((s < GRID_MAX_M) & (prep.dx[prep.train] != 0.0)))


def search(prep, base, fit_with):
    """The element set: the grid's weights by bounded least squares, the
    elements above MIN_SHARE of their sum kept. None when the log has fewer
    than MIN_PRESLIDING_SAMPLES presliding samples (it cannot show the
    cause) or no element carries weight."""
    if presliding_samples(prep) < MIN_PRESLIDING_SAMPLES:
        return None
    g = grid(prep)
    split = fit_with({"ps_grid": g, "ps_breakaway": None, "ps_share": None})
    w = np.array([max(split.coef.get(c, 0.0), 0.0) for c in ELEMENT_COLS])
    if not w.sum() > 0.0:
        return None
    keep = w > MIN_SHARE * w.sum()
    share = w[keep] / w[keep].sum()
    return {"ps_grid": None, "ps_breakaway": tuple(float(x) for x in np.asarray(g)[keep]),
            "ps_share": tuple(float(x) for x in share)}


def presliding_m(breakaway, share):
    """presliding.md's figure of an element set (clamp form, slow reversal):
    the x where sum_i alpha_i min(x / d_i, 2) = 1.8."""
    d = np.asarray(breakaway, dtype=float)
    a = np.asarray(share, dtype=float)
    a = a / a.sum()

    def covered(x):
        return float(a @ np.minimum(x / d, 2.0))

    # piecewise linear and increasing up to 2 d_max: the segment holding 1.8, then the line
    knots = np.sort(np.concatenate([[0.0], 2.0 * d]))
    for x0, x1 in zip(knots[:-1], knots[1:]):
        c0, c1 = covered(x0), covered(x1)
        if c1 >= 1.8:
            return float(x0 + (1.8 - c0) * (x1 - x0) / (c1 - c0))
    return float(knots[-1])


def virgin_curve(breakaway, share, x):
    """The element set's force from undeflected elements over the travel x,
    in Fs: sum_i alpha_i min(x / d_i, 1) (the clamp form at a slow move; the
    curve after a reversal from sliding is twice this one, Masing's rule)."""
    d = np.asarray(breakaway, dtype=float)
    return np.minimum(np.asarray(x, dtype=float)[:, None] / d[None, :], 1.0) @ np.asarray(share, dtype=float)


def fewer_elements(breakaway, share, n_max, n_x=256):
    """The element set with at most n_max elements whose force-travel curve is
    closest to the given set's: over every subset of n_max of the given
    breakaway displacements, the shares by non-negative least squares on the
    virgin curve (n_x travels, geometric from d_min / 4 to 2 d_max; the sum 1
    held by a heavy row, then exact), the subset with the smallest largest
    difference kept. Returns (breakaway, share, the largest difference in Fs);
    the set itself, difference 0, when it has n_max elements or fewer."""
    d = np.asarray(breakaway, dtype=float)
    a = np.asarray(share, dtype=float) / math.fsum(share)
    if len(d) <= n_max:
        return tuple(d), tuple(a), 0.0
    x = np.geomspace(d.min() / 4.0, 2.0 * d.max(), n_x)
    target = virgin_curve(d, a, x)
    best = None
    for sub in itertools.combinations(range(len(d)), n_max):
        cols = np.minimum(x[:, None] / d[None, list(sub)], 1.0)
        # the heavy row holds the sum near 1, so it is > 0
        w, _ = optimize.nnls(np.vstack([cols, np.full(n_max, 1.0e3)]), np.append(target, 1.0e3))
        w = w / w.sum()
        err = float(np.max(np.abs(cols @ w - target)))
        if best is None or err < best[2]:
            best = (d[list(sub)], w, err)
    keep = best[1] > 0.0
    return tuple(best[0][keep]), tuple(best[1][keep]), best[2]


def initial_stiffness_Npm(nl, Fs):
    """sum k_i = Fs sum alpha_i / d_i: the elements' stiffness right after a reversal."""
    return Fs * sum(a / d for d, a in zip(nl["ps_breakaway"], nl["ps_share"]))


def adjust_nominal(p, nl):
    """The nominal parameters of a Maxwell-slip model: sigma0_Npm is the
    elements' initial stiffness (comparable with LuGre's, presliding.md);
    sigma1_Nspm stays the fitted damping of each element."""
    p["sigma0_Npm"] = initial_stiffness_Npm(nl, p["Fs_N"])


def elements(nl):
    """model.json's and the report's element set."""
    return {"breakaway_m": [float(d) for d in nl["ps_breakaway"]], "share": [float(a) for a in nl["ps_share"]]}


def from_elements(obj):
    """The fit's nonlinear parameters from model.json's "presliding" object."""
    return {"ps_grid": None, "ps_breakaway": tuple(float(d) for d in obj["breakaway_m"]),
            "ps_share": tuple(float(a) for a in obj["share"])}


def params(coef, nl, p):
    return {}


def from_params(p):
    return {}, {}


def report_params(p):
    return {}


def report_nl(nl):
    """The spec's parameters (measured-log.md) from the element set."""
    return {"presliding_m": presliding_m(nl["ps_breakaway"], nl["ps_share"]),
            "elements": [{"breakaway_m": float(d), "share": float(a)}
                         for d, a in zip(nl["ps_breakaway"], nl["ps_share"])]}


def since_reversal(prep):
    """The travel since the last reversal of the filtered path, per interval,
    m (the filtered path: an encoder's count flickering at rest is no reversal)."""
    dx = np.diff(prep.xf)
    x = np.cumsum(dx)
    s = np.sign(dx)
    # the direction of the last nonzero step, carried over the steps of zero
    idx = np.where(s != 0, np.arange(len(s)), 0)
    np.maximum.accumulate(idx, out=idx)
    direction = s[idx]
    turn = np.flatnonzero(np.diff(direction) != 0) + 1
    start = np.zeros(len(s), dtype=int)
    start[turn] = turn
    np.maximum.accumulate(start, out=start)
    return np.abs(x - x[start] + dx[start])


def evidence(r, p):
    """The nominal residual against the travel since the last reversal."""
    s = since_reversal(r.prep)[r.prep.whole]
    L = p["presliding_m"]
    near = s < L
    far = (s > 3.0 * L) & r.moving
    e_near = float(np.sqrt(np.mean(r.e[near] ** 2))) if near.any() else 0.0
    beyond = (f"against {float(np.sqrt(np.mean(r.e[far] ** 2))):.2f} N in sliding beyond {3e6 * L:.3g} um"
              if far.any() else f"(the log slides nowhere beyond {3e6 * L:.3g} um)")
    els = ", ".join(f"{1e6 * q['breakaway_m']:.3g} um ({100 * q['share']:.0f} %)" for q in p["elements"])
    return (f"The nominal model's residual goes with the travel since the last reversal: RMS {e_near:.2f} N within "
            f"{1e6 * L:.3g} um of a reversal {beyond} (residual vs time since a "
            f"reversal); a Maxwell-slip element set (breakaway {els}) covers 90 % of the swing in "
            f"{1e6 * L:.3g} um with the elements' piecewise-linear curve, which one LuGre bristle cannot.")


def closed_loop(p, plant):
    """The closed-loop re-simulation keeps its LuGre bristle with sigma0 the
    elements' initial stiffness (adjust_nominal): its plant has no element set
    (docs/diagnose.md, "presliding_hysteresis")."""
