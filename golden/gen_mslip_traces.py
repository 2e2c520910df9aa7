# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the firmware's Maxwell-slip clamp kernel (br_mslip_step,
docs/modules/mslip.md), called by golden/gen_traces.py (docs/golden.md,
"mslip"):

  mslip.csv  four elements of unequal shares (breakaways 2, 5, 10, 20 um at
             Fs, shares 0.1-0.4), driven along a position path of reversals
             at shrinking and growing amplitudes (inner loops inside outer
             ones: the non-local memory), a jump larger than every
             breakaway within one step, and a stop; the level g is eq. 5's
             g(v) of the reference machine at the step's mean speed.

Inputs (dx, v, g) are written as float32 values, so the C test reads them
exactly and only its own arithmetic differs from the float64 reference
(golden/ref/mslip.py). The element set is a test choice inside
presliding.md's ranges; the C test reads it from the header.
"""
import numpy as np

from ref import mslip as rmslip

D_M = (2e-6, 5e-6, 10e-6, 20e-6)
SHARE = (0.1, 0.2, 0.3, 0.4)
STEPS = 3000


def path(rng, dt):
    """Positions x_k, k = 0..STEPS: a reversal sequence of amplitudes 0.5-40 um
    (outer, inner and re-opened loops), a 60 um jump in one step, a pause."""
    t = np.arange(STEPS + 1) * dt
    env = 20e-6 * (1.0 + np.sin(2.0 * np.pi * t / 1.1)) + 0.5e-6
    x = env * np.sin(2.0 * np.pi * t / 0.19) + 3e-6 * np.sin(2.0 * np.pi * t / 0.023 + rng.uniform(0, 6.28))
    x[2000:] += 60e-6          # a jump of 60 um within one step (the clamp bounds every element)
    x[2600:2700] = x[2600]     # a stop: the elements hold
    return x


def generate(out_dir, m, gt):
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["mslip"])
    dt = gt.DT
    x = path(rng, dt)
    p0 = rmslip.MslipParams.from_breakaway(D_M, SHARE, m["Fs_N"], m["sigma2_Nspm"])
    # the element set as the firmware reads it: float32 stiffnesses and shares
    p = rmslip.MslipParams(k=tuple(gt.f32(k) for k in p0.k), share=tuple(gt.f32(a) for a in p0.share),
                           sigma2=gt.f32(p0.sigma2))
    z = np.zeros(len(D_M))
    rows = []
    for i in range(STEPS):
        dx = gt.f32(x[i + 1] - x[i])
        v = gt.f32(dx / dt)
        # eq. 5 at the step's speed
        g = gt.f32(m["Fc_N"] + (m["Fs_N"] - m["Fc_N"]) * np.exp(-abs(v) / m["vs_mps"]))
        z = rmslip.move(p, z, dx, g)
        rows.append([i, dx, v, g, rmslip.force(p, z, v)] + [float(e) for e in z])
    meta = [("n", len(D_M)), ("k_Npm", p.k), ("share", p.share), ("sigma2_Nspm", p.sigma2), ("dt_s", dt)]
    cols = ["k", "dx", "v", "g", "F"] + ["z%d" % (i + 1) for i in range(len(D_M))]
    return gt.write_trace(out_dir, "mslip", meta, cols, rows, [
        "br_mslip_step (clamp form) from undeflected elements, never reset: the travel, speed and",
        "level of each step (float32 values), the force and element deflections after it."])
