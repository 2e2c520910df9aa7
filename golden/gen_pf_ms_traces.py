# SPDX-License-Identifier: Apache-2.0
"""Golden traces of the particle filter with Maxwell-slip elements
(docs/modules/pf.md, "Maxwell-slip elements"), called by golden/gen_traces.py
(docs/golden.md, "pf_ms"):

  pf_ms.csv    golden/ref/pf.py with cfg.mslip (the hardware-like plant's
               element set, the one ukf_ms.csv uses: gen_ukf_ms_traces.ms_params)
               on the estimators' recorded input (est_input.csv) with its two
               encoder faults, one row per step: the input, status, origin,
               noise position, outlier run, re-anchored, max log-weight, mean
               state, F_hat, ESS, the mean elements
  pf_ms_x.csv  the particle set after step k (theta, omega, z, g_p and the
               elements e0..e3), float32-rounded, at every re-synchronisation
               point of the C test (k + 1 a multiple of SYNC_EVERY, or step
               k + 1 an outlier or a re-anchoring), with the resampling index
               of each particle at step k + 1: the C test restarts from the
               set and compares that one step

The particle filter's configuration is pf.csv's (gen_est_traces.pf_cfg).
Same conventions as gen_traces.py (write_trace, f32, '%.17g'; the particle
sets '%.9g' of float32 values as pf_x.csv).
"""
import dataclasses

from ref import pf as rpf
import gen_est_traces as gest
import gen_ukf_ms_traces as gums

SYNC_EVERY = 10
NE = len(gums.D_M)

PF_MS_COLUMNS = ["k", "counts", "frac", "u_prev_Nm", "status", "origin_counts", "noise_pos", "n_outliers",
                 "reanchored", "lmax", "theta", "omega", "z", "gp", "F_hat", "ess"] + ["em%d" % i for i in range(NE)]
PF_MS_X_COLUMNS = ["k", "j", "theta", "omega", "z", "gp"] + ["e%d" % i for i in range(NE)] + ["idx_next"]


def run(cfg, inputs):
    """pf.py with cfg.mslip on inputs; returns (step rows, the particle set and
    elements after each step, the resampling indices of each step)."""
    pf = rpf.Pf(cfg)
    rows, sets, idx = [], [], []
    for k, counts, frac, u_prev in inputs:
        st = pf.step(counts, frac, u_prev)
        assert st in (rpf.BR_OK, rpf.BR_W_OUTLIER), (k, st)
        primed = k == 0
        lmax = 0.0 if primed else max(pf.l)
        rows.append([k, counts, frac, u_prev, st, pf.origin, pf.noise_pos, pf.n_outliers,
                     int(pf.reanchored and not primed), lmax, *pf.mean, pf.F_hat, pf.ess,
                     *(sum(e[i] for e in pf.e) / cfg.m for i in range(NE))])
        sets.append([(x.copy(), e.copy()) for x, e in zip(pf.x, pf.e)])
        idx.append(None if primed else list(pf.idx))
    return rows, sets, idx


def sync_points(rows):
    """The steps k after which the C test restarts from the reference's set:
    k + 1 a multiple of SYNC_EVERY, or step k + 1 an outlier or a re-anchoring."""
    c_st, c_re = PF_MS_COLUMNS.index("status"), PF_MS_COLUMNS.index("reanchored")
    return [k for k in range(len(rows) - 1)
            if (k + 1) % SYNC_EVERY == 0 or rows[k + 1][c_re] or rows[k + 1][c_st] == rpf.BR_W_OUTLIER]


def generate(out_dir, m, gt, rows_in):
    """Writes pf_ms.csv and pf_ms_x.csv from the recorded input rows_in
    (est_input's rows); gt is the gen_traces module. Returns the paths."""
    f32 = gt.f32
    pcfg, crc = gest.pf_cfg(m, f32)
    p = gums.ms_params(m, f32)
    cfg = dataclasses.replace(pcfg, mslip=p, ms_passes=gums.PASSES)
    inputs = [(r[0], r[2], r[3], r[4]) for r in rows_in]
    rows, sets, idx = run(cfg, inputs)
    rows_x = []
    for k in sync_points(rows):
        for j in range(cfg.m):
            x, e = sets[k][j]
            rows_x.append([k, j, *(gest.np.float32(v) for v in x), *(gest.np.float32(v) for v in e),
                           idx[k + 1][j]])
    meta = gest.pf_meta(cfg, crc) + [("ms_n", NE), ("ms_k_Npm", p.k), ("ms_share", p.share),
                                     ("ms_passes", gums.PASSES)]
    paths = [gt.write_trace(out_dir, "pf_ms", meta, PF_MS_COLUMNS, rows, [
        "golden/gen_pf_ms_traces.py: golden/ref/pf.py (float64) with Maxwell-slip elements",
        "(cfg.mslip: ms_k_Npm, ms_share; ms_passes trapezoidal passes) on est_input.csv's",
        "input with its encoder faults. One row per step (k = 0 primes): the input,",
        "status, origin, noise position, consecutive outliers, re-anchored (0/1), max",
        "log-weight (0 when priming), mean state, F_hat (mean sum k_i e_i), ESS, the",
        "mean elements em0..em3."])]
    paths.append(gt.write_trace(out_dir, "pf_ms_x", meta + [("sync_every", SYNC_EVERY)], PF_MS_X_COLUMNS,
                                rows_x, [
        "golden/gen_pf_ms_traces.py: the particle set of pf_ms.csv after step k, theta",
        "relative to the origin, with each particle's elements e0..e3, rounded to float32",
        "and printed with '%.9g' (exact), and idx_next = the resampling index of particle",
        "j at step k + 1; at every k with k + 1 a multiple of sync_every or step k + 1 an",
        "outlier or a re-anchoring: the C test restarts from the set and compares step k + 1."],
        value_fmt=gest.fmt_f32))
    return paths
