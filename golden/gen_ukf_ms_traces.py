# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the UKF with Maxwell-slip elements (docs/modules/ukf.md,
"Maxwell-slip elements"), called by golden/gen_traces.py (docs/golden.md,
"ukf_ms"):

  ukf_ms.csv  golden/ref/ukf.py with cfg.mslip (the hardware-like plant's
              element set: breakaways 2, 5, 10, 20 um at the machine's Fs,
              equal shares; k_i = share_i Fs / d_i in float32) on the
              estimators' recorded input (est_input.csv) with its two
              encoder faults, so the outlier path and the re-anchoring (which
              moves the elements with the position's jump) are in it. The
              input columns (counts, frac, u_prev_Nm) are in the trace itself.

The element set is the simulator's hardware-like plant's
(sim/lib/circle/br_circle.c), its truth side written out here again on purpose:
the trace checks the filter's arithmetic, not the plant.
Same conventions as gen_traces.py (write_trace, f32, '%.17g').
"""
import dataclasses

from ref import mslip as rmslip
from ref import ukf as rukf
import gen_est_traces as gest

D_M = (2e-6, 5e-6, 10e-6, 20e-6)
SHARE = (0.25, 0.25, 0.25, 0.25)
PASSES = 2  # BR_MODEL_MS_PASSES (the C test checks it)

NE = len(D_M)
COLUMNS = (["k", "counts", "frac", "u_prev_Nm"] + gest.UKF_COLUMNS[1:] + ["e%d" % i for i in range(NE)])


def ms_params(m, f32):
    """The element set in float32 (k_i, share_i), sigma2 0 (the model's own viscous term)."""
    p = rmslip.MslipParams.from_breakaway(D_M, SHARE, m["Fs_N"], 0.0)
    return rmslip.MslipParams(k=tuple(f32(k) for k in p.k), share=tuple(f32(a) for a in p.share), sigma2=0.0)


def run(cfg, inputs):
    u = rukf.Ukf(cfg)
    rows = []
    for k, counts, frac, u_prev in inputs:
        st = u.step(counts, frac, u_prev)
        assert st in (rukf.BR_OK, rukf.BR_W_OUTLIER), (k, st)
        P = [u.P[i][j] for i in range(4) for j in range(i, 4)]
        rows.append([k, counts, frac, u_prev, st, u.origin, u.n_outliers, int(u.reanchored), *u.x, *P, u.F_hat,
                     u.nu, u.S, *u.Pm_diag, *[float(e) for e in u.el]])
    return rows


def generate(out_dir, m, gt, rows_in):
    """Writes ukf_ms.csv from the recorded input rows_in (gen_est_traces's
    est_input rows); gt is the gen_traces module. Returns the path."""
    f32 = gt.f32
    p = ms_params(m, f32)
    cfg = dataclasses.replace(gest.ukf_cfg(m, f32), mslip=p, ms_passes=PASSES)
    inputs = [(r[0], r[2], r[3], r[4]) for r in rows_in]
    rows = run(cfg, inputs)
    meta = gest.ukf_meta(cfg) + [("ms_n", NE), ("ms_k_Npm", p.k), ("ms_share", p.share), ("ms_passes", PASSES)]
    return gt.write_trace(out_dir, "ukf_ms", meta, COLUMNS, rows, [
        "golden/gen_ukf_ms_traces.py: golden/ref/ukf.py (float64) with Maxwell-slip",
        "elements (cfg.mslip, ms_* in this header) on est_input.csv's input, its encoder",
        "faults kept. One row per step (k = 0 primes): the input, status, origin,",
        "consecutive outliers, re-anchored (0/1), posterior mean (theta relative to",
        "origin; z, the elements' common error, 0 after an update), P (upper",
        "triangle), F_hat (sum k_i e_i), innovation nu and its variance S (0 when",
        "priming), diagonal of the last P-, the elements e0.. after the step."])
