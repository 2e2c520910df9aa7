# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the extended estimation model (the causes of a diagnosis),
called by golden/gen_traces.py (docs/golden.md, "Extended model"):

  model_ext.csv  one-step rows of br_model_step_at for each cause alone and
                 for all of them together: the model's clock n (the step
                 starts at t = n dt), the load position p0 of theta's
                 origin, x_k (theta relative to p0), u_k, the expected
                 status and branch, x_{k+1}, and the force to compensate at
                 x_k, from golden/ref/model.py's extended model (float64)

The causes' sizes are set relative to the machine (its Coulomb level, viscous
friction and lead), so the trace follows the machine description.
Same conventions as gen_traces.py (write_trace, f32, fixed seeds, '%.17g').
"""
import math

import numpy as np

from ref import model as rmodel

EXT_COLUMNS = ["k", "seg", "n", "p0", "u", "theta", "omega", "z", "gp", "status", "branch",
               "theta1", "omega1", "z1", "gp1", "fcomp"]
EXT_SEG_NAMES = ["offset", "asymmetric_friction", "position_ripple", "position_gradient", "all", "friction_drift"]
ROWS_PER_SEG = 400
# the order of a segment's cause values in its seg<n> metadata line (the model.json names)
CAUSE_KEYS = ["offset_N", "dFc_neg_N", "dsigma2_neg_Nspm", "ripple_amp_N", "ripple_period_m",
              "ripple_phase_rad", "grad_per_m", "drift_per_s"]
# the model's clock of a row: up to this many steps (40 s at the traces' 1 ms)
CLOCK_MAX = 40000
DRIFT = 0.02  # 1/s: the friction level grows by 2 % of its starting value a second (s up to 1.8)


def seg_causes(m):
    """The cause sets of segments 1..6, relative to the machine (float32-exact:
    the C side reads them into float)."""
    def f32(x):
        return float(np.float32(x))
    lead_m = 2.0 * math.pi * m["L_mprad"]
    off = rmodel.Causes(offset=f32(0.4 * m["Fc_N"]))
    asym = rmodel.Causes(dFc_neg=f32(0.3 * m["Fc_N"]), dsigma2_neg=f32(0.6 * m["sigma2_Nspm"]))
    rip = rmodel.Causes(ripple_amp=f32(0.1 * m["Fc_N"]), ripple_period=f32(lead_m / 3.0), ripple_phase=f32(0.4))
    grad = rmodel.Causes(grad=2.0)
    drift = rmodel.Causes(drift=f32(DRIFT))
    both = rmodel.Causes(offset=off.offset, dFc_neg=asym.dFc_neg, dsigma2_neg=asym.dsigma2_neg,
                         ripple_amp=rip.ripple_amp, ripple_period=rip.ripple_period,
                         ripple_phase=rip.ripple_phase, grad=grad.grad, drift=drift.drift)
    return [off, asym, rip, grad, both, drift]


def generate(out_dir, m, gt):
    """Writes model_ext.csv; gt is the gen_traces module. Returns the path."""
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["model_ext"])
    p = rmodel.ModelParams.from_machine(m)
    L, s0, rpc = p.L, p.lugre.sigma0, m["rad_per_count"]
    f32, DT = gt.f32, gt.DT
    rows = []
    skipped = 0
    for seg, c in enumerate(seg_causes(m), start=1):
        for i in range(ROWS_PER_SEG):
            gp = f32(rng.uniform(m["Fc_N"], m["Fs_N"]))
            # speeds from presliding to long stroke, both directions; every
            # tenth row faster than the RK4 limit (the bounded scheme)
            lo, hi = (0.5, 1.8) if i % 10 == 0 else (-4.0, 0.0)
            w = f32((1.0 if rng.random() < 0.5 else -1.0) * 10.0 ** rng.uniform(lo, hi))
            z = f32(rng.uniform(-1.0, 1.0) * gp / s0)
            # theta within a few counts of its origin, as the estimators keep it
            th = f32(rng.uniform(-20.0, 20.0) * rpc)
            p0 = f32(rng.uniform(-0.15, 0.15))
            u = f32(rng.uniform(-0.5, 0.5) * m["tau_per_duty_Nm"])
            n = int(rng.integers(0, CLOCK_MAX + 1))
            t = n * DT
            x = np.array([th, w, z, gp], dtype=np.float64)
            status, x1, branch = rmodel.step_ext(p, c, p0, x, u, DT, t)
            ws = []
            x_rk = rmodel.rk4_ext(p, c, p0, x, u, DT, t, ws)
            if any(abs(rmodel.ah_ext(p, c, wv, gp, DT) / rmodel.RK4_AH_MAX - 1.0) < gt.BRANCH_MARGIN
                   for wv in [x[1]] + ws + [x_rk[1]]):
                skipped += 1
                continue
            fc = rmodel.fcomp_ext(p, c, p0, x, t)
            rows.append([len(rows), seg, n, p0, u, *x, status, branch, *x1, fc])
    meta = gt.machine_meta(m, gt.MODEL_KEYS) + [("dt_s", DT), ("skipped_near_branch_threshold", skipped)]
    meta.append(("causes_order", " ".join(CAUSE_KEYS)))
    for seg, (name, c) in enumerate(zip(EXT_SEG_NAMES, seg_causes(m)), start=1):
        meta.append(("seg%d_name" % seg, name))
        meta.append(("seg%d" % seg, [c.offset, c.dFc_neg, c.dsigma2_neg, c.ripple_amp, c.ripple_period,
                                     c.ripple_phase, c.grad, c.drift]))
    return gt.write_trace(out_dir, "model_ext", meta, EXT_COLUMNS, rows, [
        "br_model_step_at one-step rows of the extended model (golden/ref/model.py,",
        "float64): segment seg's causes in the seg<n> metadata line (causes_order); n the",
        "model's clock (the step starts at t = n dt_s: the friction scale 1 + drift t); p0 the load",
        "position of theta's origin, x_k (theta relative to it) and u_k (float32-",
        "exact), expected status and branch (0 RK4, 1 bounded), x_{k+1}, and",
        "fcomp = the force to compensate at x_k (F - sigma2 v)."])
