# SPDX-License-Identifier: Apache-2.0
"""An interval for every parameter of the extended model, and the
parameters the log cannot identify (docs/diagnose.md, "Intervals").

Delete-a-block jackknife over the training part: it is cut into K
consecutive blocks; for each, the model is fitted again without that block
(the shape searched again from the fit's, in REFIT_NFEV evaluations, each
cause's nonlinear parameters searched again, the linear ones solved). With
theta_i the K estimates and theta_bar their mean,

  se = sqrt((K - 1) / K * sum (theta_i - theta_bar)^2),  interval = theta +- Z se

Blocks rather than samples because the residual is correlated in time.
A parameter is flagged "not identified" when its interval is wider than
its value (the log does not fix even its order of magnitude), or when it
lies below what the log resolves: a Stribeck velocity under the log's
velocity resolution (position step / period) leaves vs and Fs free; a
presliding length Fc/sigma0 under a few position steps leaves sigma0 and
sigma1 free.
"""
import copy

import numpy as np

from . import machinejson, model

K = 5
Z = 1.96
REFIT_NFEV = 8


def _refit(prep, fit, train_idx):
    p = copy.copy(prep)
    p.train = train_idx
    p._memo = prep._memo  # the column blocks are over the whole log: shared
    f = model.fit_shape(p, fit.causes, fit.nl, starts=(fit.shape,), max_nfev=REFIT_NFEV)
    nl = dict(f.nl)
    for c in f.causes:
        others = model.solve(p, f.shape, tuple(x for x in f.causes if x != c), nl)
        extra = model.search_cause(p, others, c, f.causes, nl)
        if extra:
            nl.update(extra)
    return model.solve(p, f.shape, f.causes, nl)


def jackknife(prep, fit):
    """{param: (low, high)} for model.json's parameters and the findings'
    report parameters of `fit`."""
    idx = np.arange(prep.train.start, prep.train.stop)
    blocks = np.array_split(idx, K)
    ests = []
    for b in range(K):
        keep = np.concatenate([blocks[j] for j in range(K) if j != b])
        f = _refit(prep, fit, keep)
        p = f.params()
        for c in f.causes:
            p.update({f"{c}.{k}": v for k, v in f.cause_params(c).items()})
        ests.append(p)
    full = fit.params()
    for c in fit.causes:
        full.update({f"{c}.{k}": v for k, v in fit.cause_params(c).items()})
    out = {}
    for k, v in full.items():
        if not isinstance(v, float):
            continue  # an element set (a list): its presliding_m has the interval
        th = np.array([e.get(k, np.nan) for e in ests])
        if not np.all(np.isfinite(th)):
            continue
        se = float(np.sqrt((K - 1) / K * np.sum((th - th.mean()) ** 2)))
        out[k] = (v - Z * se, v + Z * se)
    return out


def unidentified(prep, p, ivals):
    """{param: reason} for the parameters the log cannot identify."""
    out = {}
    q = machinejson.encoder_step(prep.pos)
    v_res = q / prep.dt if q > 0 else 0.0
    if p["vs_mps"] < v_res:
        for k in ("vs_mps", "Fs_N"):
            out[k] = (f"the Stribeck velocity {p['vs_mps']:.2g} m/s is below the log's velocity resolution "
                      f"{v_res:.2g} m/s (position step / period): the log cannot show the Stribeck hump")
    if q > 0 and p["Fc_N"] / p["sigma0_Npm"] < machinejson.PRESLIDING_MIN_QUANTA * q:
        for k in ("sigma0_Npm", "sigma1_Nspm"):
            out[k] = (f"the presliding length Fc/sigma0 = {p['Fc_N'] / p['sigma0_Npm']:.2g} m is under "
                      f"{machinejson.PRESLIDING_MIN_QUANTA:g} position steps ({q:.2g} m)")
    for k, (lo, hi) in ivals.items():
        v = p.get(k)
        if v is None or k in out or v == 0.0:
            continue
        if hi - lo > abs(v):
            out[k] = f"its 95 % interval {lo:.3g} .. {hi:.3g} is wider than its value"
    return out
