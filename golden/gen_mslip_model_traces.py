# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the Maxwell-slip estimation model (br_model_ms_step,
docs/modules/model.md "Maxwell-slip model"), called by golden/gen_traces.py
(docs/golden.md, "model_ms"):

  model_ms.csv  one-step rows: the state (theta, omega, g_p), the element
                deflections and the torque (float32 values), and the state
                and elements after the step, from golden/ref/mslip.py's
                model_step (float64), with the reference machine's mechanics
                and four elements (breakaways 2, 5, 10, 20 um at Fs, shares
                0.1-0.4). Speeds from the circle's (1e-5 m/s) to 0.05 m/s,
                the elements anywhere inside their bounds, g_p in [Fc, 1.5 Fs].
"""
import numpy as np

from ref import model as rmodel
from ref import mslip as rmslip

D_M = (2e-6, 5e-6, 10e-6, 20e-6)
SHARE = (0.1, 0.2, 0.3, 0.4)
PASSES = 2  # BR_MODEL_MS_PASSES of firmware/include/bristle/br_model.h (the C test checks it)
ROWS = 600


def generate(out_dir, m, gt):
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["model_ms"])
    f32, h = gt.f32, gt.DT
    mp = rmodel.ModelParams.from_machine(m)
    p0 = rmslip.MslipParams.from_breakaway(D_M, SHARE, m["Fs_N"], 0.0)
    p = rmslip.MslipParams(k=tuple(f32(k) for k in p0.k), share=tuple(f32(a) for a in p0.share), sigma2=0.0)
    L = mp.L
    rows = []
    for i in range(ROWS):
        v = rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-7.0, np.log10(0.05))
        omega = f32(v / L)
        gp = f32(rng.uniform(m["Fc_N"], 1.5 * m["Fs_N"]))
        theta = f32(rng.uniform(-100.0, 100.0))
        d = rmslip.bounds(p, gp)
        # inside the bounds (a hair within: the C's float bound may round below the reference's)
        z = [f32(e) for e in rng.uniform(-0.999, 0.999, len(d)) * d]
        u = f32(rng.uniform(-0.3, 0.3))
        th1, om1, z1 = rmslip.model_step(mp, p, theta, omega, gp, z, u, h, PASSES)
        rows.append([i, u, theta, omega, gp] + z + [th1, om1] + [float(e) for e in z1] + [rmslip.force(p, z, 0.0)])
    n = len(D_M)
    meta = gt.machine_meta(m, ["J_kgm2", "M_kg", "L_mprad", "sigma2_Nspm", "sigma0_Npm", "sigma1_Nspm",
                               "Fc_N", "Fs_N", "vs_mps"]) + [
        ("dt_s", h), ("passes", PASSES), ("n", n), ("k_Npm", p.k), ("share", p.share)]
    cols = (["k", "u", "theta", "omega", "gp"] + ["z%d" % (j + 1) for j in range(n)] + ["theta1", "omega1"] +
            ["z%d_1" % (j + 1) for j in range(n)] + ["fnl"])
    return gt.write_trace(out_dir, "model_ms", meta, cols, rows, [
        "br_model_ms_step one step per row: inputs (float32 values) and the state, elements after it;",
        "fnl = sum k_i z_i at the row's input."])
