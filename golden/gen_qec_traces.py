# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the reversal (quadrant-error) compensation's pulse
(br_qec_set_ref / br_qec_comp, docs/modules/qec.md), called by
golden/gen_traces.py (docs/golden.md, "qec"):

  qec.csv  a reference velocity that starts from rest, reverses at
           accelerations from 1.6e-4 to 4.7e-3 m/s^2 (the acceleration term takes
           the amplitude from A0 down to its floor 0 with A1 < 0), rests at
           exactly 0 between two moves in the same direction (no reversal)
           and reverses again; the pulse after each step.

Inputs (v, a) are float32 values, so the C test reads them exactly and only
its own arithmetic differs from the float64 reference (golden/ref/qec.py).
The pulse's parameters are a test choice (A1 < 0 reaches the floor).
"""
import numpy as np

from ref import qec as rqec

STEPS = 3000
A0_N, A1_KG, TAU_S = 5.0, -2000.0, 0.05


def reference(rng, dt):
    """v_k and a_k: a sinusoid of period 0.4 s whose amplitude drifts from
    1e-5 to 3e-4 m/s (reversals at accelerations 1.6e-4 .. 4.7e-3 m/s^2), a
    rest at exactly 0 (rows 1200-1299) between two moves the same way."""
    t = np.arange(STEPS) * dt
    w, wm = 2.0 * np.pi / 0.4, 2.0 * np.pi / 2.3
    ph = rng.uniform(0.0, 2.0 * np.pi)
    env = 1e-5 + 1.45e-4 * (1.0 + np.sin(wm * t + ph))
    denv = 1.45e-4 * wm * np.cos(wm * t + ph)
    v = env * np.sin(w * t)
    a = denv * np.sin(w * t) + env * w * np.cos(w * t)
    v[:20] = 0.0                     # at rest: no pulse before the first motion
    a[:20] = 0.0
    v[1200:1300] = 0.0               # a rest at exactly 0: the direction is kept
    a[1200:1300] = 0.0
    v[1300:1400] = np.abs(v[1300:1400]) * np.sign(v[1199])  # resumes the way it went
    return v, a


def generate(out_dir, m, gt):
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["qec"])
    dt = gt.DT
    v, a = reference(rng, dt)
    v = [gt.f32(x) for x in v]
    a = [gt.f32(x) for x in a]
    A0, A1, tau = gt.f32(A0_N), gt.f32(A1_KG), gt.f32(TAU_S)
    p, since = rqec.pulse(v, a, A0, A1, tau, dt)
    rows = [[k, v[k], a[k], since[k], p[k]] for k in range(STEPS)]
    meta = [("A0_N", A0), ("A1_kg", A1), ("tau_s", tau), ("dt_s", gt.f32(dt))]
    return gt.write_trace(out_dir, "qec", meta, ["k", "v", "a", "since", "p"], rows, [
        "br_qec_set_ref then br_qec_comp per row from rest: the reference (float32 values), the steps",
        "since the last reversal (-1: none yet) and the pulse after the step."])
