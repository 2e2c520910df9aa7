# SPDX-License-Identifier: Apache-2.0
"""Golden traces of the friction estimators (PF, UKF), called by
golden/gen_traces.py (see docs/golden.md, "Estimator traces"):

  est_input.csv  the recorded closed-loop input: encoder counts and applied
                 torque of one axis of the circle, float64 plant
                 (golden/ref/plant.py) + eq. 7 controller (golden/ref/ctrl.py)
                 + the reference PF's compensation, with two injected encoder
                 faults
  pf.csv         the reference PF (golden/ref/pf.py) on that input: status,
                 origin, noise position, max log-weight, estimate per step
  pf_w.csv       its integer weights W and resampling indices, per step
  pf_x.csv       the whole particle set every PF_X_EVERY steps (comparison
                 and re-synchronisation points of the C test)
  ukf.csv        the reference UKF (golden/ref/ukf.py) on the same input:
                 status, origin, mean, covariance, F_hat, innovation per step

Same conventions as gen_traces.py (write_trace, f32, fixed seeds, '%.17g').
"""
import math
import os
import re
import sys

import numpy as np

from ref import MACHINE_JSON, REPO_ROOT, machine_module
from ref import ctrl as rctrl
from ref import lugre as rlugre
from ref import model as rmodel
from ref import pf as rpf
from ref import plant as rplant
from ref import ukf as rukf

DESIGN_DIR = os.path.join(REPO_ROOT, "firmware", "design")
NOISE_HEADER = os.path.join(REPO_ROOT, "firmware", "gen", "bristle_gen", "est", "br_noise_table.h")

# the closed-loop recording: x axis of the thesis circle (A = 1e-4 m, T = 8 s)
# at the PF's 1.5 ms, from rest; 1600 steps = 2.4 s (reversal at 2.0 s)
EST_DT = 1.5e-3
EST_STEPS = 1600
CIRCLE_A_M = 1.0e-4
CIRCLE_T_S = 8.0
# counts at the start: the encoder crosses the int32 wrap at k = 407 (0.61 s)
COUNTS0 = 2**31 - 6000
PLANT_NSUB = 20
TORQUE_RIPPLE_NM = 5.0e-4   # seeded white torque disturbance on the plant input
# injected encoder faults: a one-step spike (one outlier step), then a
# permanent slip (reanchor_after outliers, then the re-anchoring)
SPIKE_STEP, SPIKE_COUNTS = 600, 500
SLIP_STEP, SLIP_COUNTS = 870, 1000

PF_M = 128
PF_BLOCK = 8          # particles per pf_w row
PF_X_EVERY = 10       # pf_x: the whole particle set every 10th step


def fmt_f32(v):
    """pf_x values: float32 (the C filter's storage, which the test restarts
    from), printed with '%.9g', which round-trips float32 exactly."""
    if isinstance(v, (int, np.integer)):
        return "%d" % int(v)
    s = "%.9g" % float(v)
    assert np.float32(float(s)) == np.float32(v)
    return s


def noise_table():
    """The PF's ROM table exactly as firmware/design/gen_noise.py writes it,
    of the length in firmware/gen/bristle_gen/est/br_noise_table.h (BR_NOISE_LEN)."""
    sys.path.insert(0, DESIGN_DIR)
    try:
        import gen_noise
    finally:
        sys.path.remove(DESIGN_DIR)
    with open(NOISE_HEADER, "r", encoding="utf-8") as f:
        n = int(re.search(r"#define\s+BR_NOISE_LEN\s+(\d+)u?", f.read()).group(1))
    t = gen_noise.table(n)
    assert t.dtype == np.float32 and len(t) == n
    return tuple(float(v) for v in t), fnv1a32(t)


def fnv1a32(t):
    """FNV-1a (32 bit) over the bytes of the float32 bit patterns, each word
    least significant byte first (the C test recomputes it from br_noise_table)."""
    h = 2166136261
    for w in t.view(np.uint32):
        w = int(w)
        for s in (0, 8, 16, 24):
            h ^= (w >> s) & 0xFF
            h = (h * 16777619) & 0xFFFFFFFF
    return h


def model_params_f32(m, f32):
    """Eq. 6 parameters rounded to float32: what the C configuration holds."""
    lp = rlugre.LugreParams(sigma0=f32(m["sigma0_Npm"]), sigma1=f32(m["sigma1_Nspm"]),
                            Fc=f32(m["Fc_N"]), Fs=f32(m["Fs_N"]), vs=f32(m["vs_mps"]))
    return rmodel.ModelParams(J=f32(m["J_kgm2"]), M=f32(m["M_kg"]), L=f32(m["L_mprad"]),
                              sigma2=f32(m["sigma2_Nspm"]), lugre=lp)


def model_meta(mp):
    return [("J_kgm2", mp.J), ("M_kg", mp.M), ("L_mprad", mp.L), ("sigma2_Nspm", mp.sigma2),
            ("sigma0_Npm", mp.lugre.sigma0), ("sigma1_Nspm", mp.lugre.sigma1),
            ("Fc_N", mp.lugre.Fc), ("Fs_N", mp.lugre.Fs), ("vs_mps", mp.lugre.vs)]


def est_section(name):
    """The machine file's estimator settings (estimator.pf or .ukf) with their
    per-step values (the loader's est_per_step: machine-file.md)."""
    mm = machine_module()
    mach = mm.load_or_exit(MACHINE_JSON)
    return mach["estimator"][name], mm.est_per_step(mach, name)


def pf_cfg(m, f32):
    """The traced PF: the machine file's (x0 spread, g_p range, outlier gate,
    noise_skip) with m = 128 particles and a tuning that mostly holds lock
    with so few (R = 10 rpc^2, q_theta = rpc^2, q_gp = 1 N^2; the
    1500-particle tuning loses lock every few steps at m = 128), fixed here,
    independent of later tuning of the demo. All values float32-exact."""
    rpc = m["rad_per_count"]
    e, ps = est_section("pf")
    table, crc = noise_table()
    cfg = rpf.PfCfg(
        model=model_params_f32(m, f32), dt=f32(EST_DT), m=PF_M,
        q_var=(f32(rpc * rpc), f32(5.0e-6), f32(1.0e-14), f32(1.0)),
        r_var=f32(10.0 * rpc * rpc), gp0=f32(ps["gp0_N"]),
        x0_std=(f32(ps["x0_theta_counts"] * rpc), f32(ps["x0_omega_radps"]), f32(ps["x0_z_m"]), f32(ps["x0_gp_N"])),
        gp_min=f32(ps["gp_min_N"]), gp_max=f32(ps["gp_max_N"]),
        outlier_sigma=f32(e["outlier_gate_sigma"]), reanchor_after=e["reanchor_after"],
        rad_per_count=f32(rpc), noise=table, noise_skip=e["noise_skip"])
    return cfg, crc


def pf_meta(cfg, crc):
    return model_meta(cfg.model) + [
        ("dt_s", cfg.dt), ("n_particles", cfg.m), ("q_var", cfg.q_var), ("r_var_rad2", cfg.r_var),
        ("gp0_N", cfg.gp0), ("x0_std", cfg.x0_std), ("gp_min_N", cfg.gp_min),
        ("gp_max_N", cfg.gp_max), ("outlier_sigma", cfg.outlier_sigma),
        ("reanchor_after", cfg.reanchor_after), ("rad_per_count", cfg.rad_per_count),
        ("noise_len", len(cfg.noise)), ("noise_fnv1a", crc), ("noise_skip", cfg.noise_skip),
        ("w_bits", rpf.W_BITS)]


EST_INPUT_COLUMNS = ["k", "t", "counts", "frac", "u_prev_Nm", "fault", "ref_counts",
                     "theta_rad", "omega_radps", "z_m", "fnl_N", "comp_N", "tau_Nm"]
PF_COLUMNS = ["k", "status", "origin_counts", "noise_pos", "lmax", "theta", "omega", "z", "gp",
              "F_hat", "ess", "n_outliers", "reanchored", "F_hat_pred"]
PF_W_COLUMNS = (["k", "j0"] + ["W%d" % i for i in range(PF_BLOCK)]
                + ["idx%d" % i for i in range(PF_BLOCK)])
PF_X_COLUMNS = ["k", "j", "theta", "omega", "z", "gp"]


def record(m, gt):
    """Closed loop of one circle axis at EST_DT with the reference PF's
    compensation; returns (input rows, pf rows, pf_w rows, pf_x rows, meta)."""
    f32 = gt.f32
    rng = np.random.default_rng(gt.SEED + gt.SEED_OFFSET["est_input"])
    K, ksrc = gt.read_gains()
    rpc, L = m["rad_per_count"], m["L_mprad"]
    tau_max = m["tau_per_duty_Nm"]
    ccfg = rctrl.CtrlCfg(K=K, dt=EST_DT, tau_max=tau_max, tau_per_duty=m["tau_per_duty_Nm"],
                         rad_per_count=rpc, L=L)
    cst = rctrl.CtrlState()
    plant = rplant.Plant(rplant.PlantParams.from_machine(m, PLANT_NSUB), (COUNTS0 + 0.5) * rpc)
    cfg, crc = pf_cfg(m, f32)
    pf = rpf.Pf(cfg)
    w = 2.0 * math.pi / CIRCLE_T_S
    u_prev = 0.0
    rows_in, rows_pf, rows_w, rows_x = [], [], [], []
    for k in range(EST_STEPS):
        t = k * EST_DT
        counts = plant.encoder()
        fault = 0
        if k == SPIKE_STEP:
            counts, fault = rctrl.to_int32(counts + SPIKE_COUNTS), 1
        if k >= SLIP_STEP:
            counts, fault = rctrl.to_int32(counts + SLIP_COUNTS), 2
        # the estimator sees the count's centre and the torque of the last period
        st = pf.step(counts, 0.5, u_prev)
        assert st in (rpf.BR_OK, rpf.BR_W_OUTLIER), (k, st)
        comp = f32(pf.F_hat)
        pos = COUNTS0 + 0.5 + CIRCLE_A_M * math.sin(w * t) / L / rpc
        fl = math.floor(pos)
        ref_c = rctrl.to_int32(fl)
        cs, cst, out = rctrl.step(ccfg, cst, counts, ref_c, f32(pos - fl),
                                  f32(CIRCLE_A_M * w * math.cos(w * t) / L), comp)
        assert cs == rctrl.BR_OK
        tau = f32(out["tau"])
        rows_in.append([k, t, counts, 0.5, u_prev, fault, ref_c, plant.theta, plant.omega,
                        plant.z, plant.fnl, comp, tau])
        lmax = max(pf.l) if k > 0 else 0.0
        rows_pf.append([k, st, pf.origin, pf.noise_pos, lmax, *pf.mean, pf.F_hat, pf.ess,
                        pf.n_outliers, int(pf.reanchored), pf.F_hat_pred])
        if k > 0:
            for j0 in range(0, cfg.m, PF_BLOCK):
                rows_w.append([k, j0] + pf.W[j0:j0 + PF_BLOCK] + pf.idx[j0:j0 + PF_BLOCK])
        if k % PF_X_EVERY == 0:
            for j in range(cfg.m):
                rows_x.append([k, j, *(np.float32(v) for v in pf.x[j])])
        # the plant: commanded torque plus a small seeded ripple, duty clamped
        ripple = TORQUE_RIPPLE_NM * rng.standard_normal()
        plant.step((tau + ripple) / m["tau_per_duty_Nm"], EST_DT)
        u_prev = tau
    meta_in = [("dt_s", f32(EST_DT)), ("rad_per_count", rpc), ("lead_mprad", L), ("K", K),
               ("K_source", ksrc), ("tau_max_Nm", tau_max), ("circle_A_m", CIRCLE_A_M),
               ("circle_T_s", CIRCLE_T_S), ("counts0", COUNTS0), ("n_sub", PLANT_NSUB),
               ("torque_ripple_Nm", TORQUE_RIPPLE_NM), ("spike", (SPIKE_STEP, SPIKE_COUNTS)),
               ("slip", (SLIP_STEP, SLIP_COUNTS))]
    return rows_in, rows_pf, rows_w, rows_x, meta_in, pf_meta(cfg, crc)


def ukf_cfg(m, f32):
    """The traced UKF: the machine file's (estimator.ukf, the hand-tuned
    defaults of docs/modules/ukf.md) at the input's 1.5 ms. All values
    float32-exact."""
    rpc = f32(m["rad_per_count"])
    e, ps = est_section("ukf")
    return rukf.UkfCfg(
        model=model_params_f32(m, f32), dt=f32(EST_DT),
        q_var=(f32(ps["q_theta_rad2"]), f32(ps["q_omega_rad2ps2"]), f32(ps["q_z_m2"]), f32(ps["q_gp_N2"])),
        r_var=f32(ps["r_counts2"] * rpc * rpc), gp0=f32(ps["gp0_N"]),
        p0_var=(f32(ps["p0_theta_counts2"] * rpc * rpc), f32(ps["p0_omega_rad2ps2"]), f32(ps["p0_z_m2"]),
                f32(ps["p0_gp_N2"])),
        gp_min=f32(ps["gp_min_N"]), gp_max=f32(ps["gp_max_N"]), outlier_sigma=f32(e["outlier_gate_sigma"]),
        reanchor_after=e["reanchor_after"], rad_per_count=rpc, alpha=f32(e["alpha"]), beta=f32(e["beta"]),
        kappa=f32(e["kappa"]))


UKF_P_COLUMNS = ["P%d%d" % (i, j) for i in range(4) for j in range(i, 4)]
UKF_COLUMNS = (["k", "status", "origin_counts", "n_outliers", "reanchored", "theta", "omega", "z", "gp"]
               + UKF_P_COLUMNS + ["F_hat", "innov", "innov_var", "Pm00", "Pm11", "Pm22", "Pm33"])


def run_ukf(cfg, rows_in):
    u = rukf.Ukf(cfg)
    rows = []
    for r in rows_in:
        k, counts, frac, u_prev = r[0], r[2], r[3], r[4]
        st = u.step(counts, frac, u_prev)
        assert st in (rukf.BR_OK, rukf.BR_W_OUTLIER), (k, st)
        P = [u.P[i][j] for i in range(4) for j in range(i, 4)]
        rows.append([k, st, u.origin, u.n_outliers, int(u.reanchored), *u.x, *P, u.F_hat, u.nu, u.S,
                     *u.Pm_diag])
    return rows


def ukf_meta(cfg):
    return model_meta(cfg.model) + [
        ("dt_s", cfg.dt), ("q_var", cfg.q_var), ("r_var_rad2", cfg.r_var), ("gp0_N", cfg.gp0),
        ("p0_var", cfg.p0_var), ("gp_min_N", cfg.gp_min), ("gp_max_N", cfg.gp_max),
        ("outlier_sigma", cfg.outlier_sigma), ("reanchor_after", cfg.reanchor_after),
        ("rad_per_count", cfg.rad_per_count), ("alpha", cfg.alpha), ("beta", cfg.beta),
        ("kappa", cfg.kappa)]


def generate(out_dir, m, gt):
    """Writes the estimator traces; gt is the gen_traces module (write_trace,
    f32, read_gains, SEED, SEED_OFFSET). Returns the paths and the recorded
    input's rows (est_input.csv's, for gen_load_traces.py)."""
    rows_in, rows_pf, rows_w, rows_x, meta_in, meta_pf = record(m, gt)
    paths = [gt.write_trace(out_dir, "est_input", meta_in, EST_INPUT_COLUMNS, rows_in, [
        "Recorded closed-loop input of the estimators: x axis of the circle (A = 1e-4 m,",
        "T = 8 s) from rest at 1.5 ms, float64 plant (golden/ref/plant.py) + eq. 7",
        "(golden/ref/ctrl.py, H-inf gains) + the reference PF's compensation comp_N.",
        "counts = encoder at t_k (fault 1: +500 count spike, fault 2: +1000 count",
        "slip), frac = 0.5, u_prev_Nm = the torque applied over [t_{k-1}, t_k]",
        "(float32-exact); the plant also gets a seeded ripple. Plant state at t_k."])]
    paths.append(gt.write_trace(out_dir, "pf", meta_pf, PF_COLUMNS, rows_pf, [
        "golden/ref/pf.py (float64) on est_input.csv, one row per step (k = 0 primes):",
        "status, origin, noise table position after the step, max log-weight",
        "(0 when priming), mean state (theta relative to origin), F_hat, ESS,",
        "consecutive outliers, re-anchored (0/1), F_hat_pred = mean f_nl of the",
        "resampled set before re-anchoring (= F_hat except on re-anchoring steps)."]))
    paths.append(gt.write_trace(out_dir, "pf_w", meta_pf, PF_W_COLUMNS, rows_w, [
        "golden/ref/pf.py on est_input.csv: integer weights W_j = floor(w_j 2^16) and",
        "resampling indices idx_i of every step k >= 1, %d particles per row" % PF_BLOCK,
        "(W_{j0+i}, idx_{j0+i}, i = 0..%d)." % (PF_BLOCK - 1)]))
    paths.append(gt.write_trace(out_dir, "pf_x", meta_pf + [("every", PF_X_EVERY)], PF_X_COLUMNS, rows_x, [
        "golden/ref/pf.py on est_input.csv: the particle set after step k (resampled,",
        "re-anchored) every %d steps, theta relative to the origin, rounded to" % PF_X_EVERY,
        "float32 and printed with '%.9g' (exact): the C test compares its set with",
        "it and restarts from it."], value_fmt=fmt_f32))
    ucfg = ukf_cfg(m, gt.f32)
    paths.append(gt.write_trace(out_dir, "ukf", ukf_meta(ucfg), UKF_COLUMNS, run_ukf(ucfg, rows_in), [
        "golden/ref/ukf.py (float64) on est_input.csv, one row per step (k = 0 primes):",
        "status, origin, consecutive outliers, re-anchored (0/1), posterior mean",
        "(theta relative to origin), covariance P (upper triangle), F_hat over the",
        "posterior sigma points, innovation nu = y - theta- and its variance S",
        "(0 when priming), diagonal of the predicted covariance P- (incl. Q; P0 when",
        "priming)."]))
    return paths, rows_in
