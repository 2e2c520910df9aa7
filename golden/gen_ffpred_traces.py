# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the compensation that predicts (br_ff_pred_N,
docs/modules/ff-pred.md), called by golden/gen_traces.py (docs/golden.md,
"ff_pred"):

  ff_pred.csv  per row an anchor (four element deflections drawn inside
               their bounds at Fs, a quarter of them at a bound: sliding),
               a reference (v, a) and a horizon tau: at rest, in presliding,
               across a reversal (v and a of opposite signs), at the
               Stribeck velocity and well past it, with horizons of half a
               period to BR_FF_PRED_MAX_S; the prediction dF and its bound's
               scale S.

Inputs are float32 values, so the C test reads them exactly and only its own
arithmetic differs from the float64 reference (golden/ref/ffpred.py). The
element set is the hardware-like plant's (breakaways 2, 5, 10, 20 um at Fs,
equal shares; docs/demo.md) at the machine's Fs; the C test reads it from the
header.
"""
import numpy as np

from ref import ffpred as rffpred
from ref import mslip as rmslip

D_M = (2e-6, 5e-6, 10e-6, 20e-6)
SHARE = (0.25, 0.25, 0.25, 0.25)
ROWS = 2000
TAUS = (5e-4, 1e-3, 1.5e-3, 2e-3, 1e-2, 0.1)


def generate(out_dir, m, gt):
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["ff_pred"])
    Fc, Fs, vs = gt.f32(m["Fc_N"]), gt.f32(m["Fs_N"]), gt.f32(m["vs_mps"])
    p0 = rmslip.MslipParams.from_breakaway(D_M, SHARE, Fs, 0.0)
    # the set as the C reads it: float32 stiffness and shares
    p = rmslip.MslipParams(k=tuple(gt.f32(k) for k in p0.k), share=tuple(gt.f32(s) for s in SHARE), sigma2=0.0)
    rows = []
    for r in range(ROWS):
        bnd = rmslip.bounds(p, Fs)
        z = rng.uniform(-1.0, 1.0, 4) * bnd
        if r % 4 == 0:
            z = np.sign(rng.uniform(-1.0, 1.0)) * bnd        # sliding: every element at one bound
        z = [gt.f32(x) for x in z]
        v = gt.f32(np.sign(rng.uniform(-1.0, 1.0)) * 10.0 ** rng.uniform(-8.0, -3.0))
        if r % 10 == 1:
            v = 0.0                                           # at rest (the reversal's instant)
        a = gt.f32(np.sign(rng.uniform(-1.0, 1.0)) * 10.0 ** rng.uniform(-6.0, -1.0))
        tau = gt.f32(TAUS[r % len(TAUS)])
        dF, S = rffpred.prediction(p, np.array(z), v, a, tau, Fc, Fs, vs)
        rows.append([r, tau, v, a] + z + [dF, S])
    meta = [("Fc_N", Fc), ("Fs_N", Fs), ("vs_mps", vs), ("k_Npm", p.k), ("share", p.share)]
    return gt.write_trace(out_dir, "ff_pred", meta,
                          ["row", "tau", "v", "a", "z0", "z1", "z2", "z3", "dF", "S"], rows, [
                              "br_ff_init with the element set and horizon tau, br_ff_set_ref(v, a, 0), then",
                              "br_ff_pred_N with the anchor z0..z3 per row: the prediction dF, N, and the",
                              "bound's scale S (golden/ref/ffpred.py)."])
