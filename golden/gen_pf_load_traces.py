# SPDX-License-Identifier: Apache-2.0
"""Golden traces of the particle filter with the shared external force
(docs/modules/pf.md, "External force"), called by golden/gen_traces.py
(docs/golden.md, "pf_load"):

  pf_load.csv    golden/ref/pf.py with cfg.load on ukf_load.csv's input
                 (est_input.csv's counts without the encoder faults, the
                 torque raised by L F_step over [LOAD_ON_K, LOAD_OFF_K):
                 gen_load_traces.load_inputs), one row per step: the input,
                 status, origin, noise position, outliers, re-anchoring,
                 re-acquisition, max log-weight, mean state, F_hat, ESS, F_d,
                 F_d through the compensation's notch,
                 P after the update and before it (Pm), the cloud's mean
                 innovation d and spread v
  pf_load_x.csv  the particle set after step k, float32-rounded, at every
                 re-synchronisation point of the C test (k + 1 a multiple of
                 SYNC_EVERY, or step k + 1 re-acquires, undoes or is an
                 outlier), with the resampling index of each particle at step
                 k + 1: the C test restarts from the set and compares that one
                 step
  pf_glitch.csv, pf_glitch_x.csv  the same with est_input.csv's two encoder
                 faults kept (a spike at k = 600, a slip at 870): each is
                 re-acquired as a load and undone at the next step
                 (docs/modules/pf.md, "A glitch is not a load")
Both carry the last re-acquisition kept for its undo after each step
(alt_*: its correction e, nu1, P as predicted), which the C test seeds as it
seeds the state.

The particle filter's configuration is pf.csv's (gen_est_traces.pf_cfg); the
load's is the machine loader's (machine.pf_load: max_N = the actuator's
force, q per step) with the fault campaign's LOAD_Q_N2_PER_S at the input's
1.5 ms. Same conventions as gen_traces.py (write_trace, f32, '%.17g'; the
particle sets '%.9g' of float32 values as pf_x.csv).
"""
import copy
import dataclasses

from ref import MACHINE_JSON, machine_module
from ref import pf as rpf
import gen_est_traces as gest
import gen_load_traces as gload

SYNC_EVERY = 10

P_NAMES = ["00", "01", "02", "11", "12", "22"]
PF_LOAD_COLUMNS = (["k", "counts", "frac", "u_prev_Nm", "status", "origin_counts", "noise_pos", "n_outliers",
                    "reanchored", "load_acq", "lmax", "theta", "omega", "z", "gp", "F_hat", "ess", "Fd", "Fd_comp"]
                   + ["P" + n for n in P_NAMES] + ["Pm" + n for n in P_NAMES] + ["innov_d", "spread_v"]
                   + ["load_undo", "alt", "alt_e0", "alt_e1", "alt_e2", "alt_nu1"] + ["alt_P" + n for n in P_NAMES])
PF_LOAD_X_COLUMNS = ["k", "j", "theta", "omega", "z", "gp", "idx_next"]


def load_cfg(f32):
    """machine.pf_load of the reference machine with estimator.pf.load =
    {q_N2_per_s: LOAD_Q_N2_PER_S} at the input's period."""
    mm = machine_module()
    mach = copy.deepcopy(mm.load_or_exit(MACHINE_JSON))
    mach["estimator"]["pf"]["load"] = {"q_N2_per_s": gload.LOAD_Q_N2_PER_S}
    mach["estimator"]["pf"]["period_s"] = gest.EST_DT
    ld = mm.pf_load(mach)
    return rpf.LoadCfg(q_N2=f32(ld["q_N2"]), max_N=f32(ld["max_N"]))


def upper(P):
    return [P[i][j] for i in range(3) for j in range(i, 3)]


def run(cfg, inputs):
    """pf.py with cfg.load on inputs; returns (step rows, the particle set
    after each step, the resampling indices of each step)."""
    pf = rpf.Pf(cfg)
    rows, sets, idx = [], [], []
    for k, counts, frac, u_prev in inputs:
        st = pf.step(counts, frac, u_prev)
        assert st in (rpf.BR_OK, rpf.BR_W_OUTLIER), (k, st)
        primed = k == 0
        lmax = 0.0 if primed else max(pf.l)
        Pm = pf.P if primed else pf.Pm
        if pf.alt is None:
            alt = [0, 0.0, 0.0, 0.0, 0.0] + [0.0] * 6
        else:
            e, P_A, nu1 = pf.alt
            alt = [1, *e, nu1, *upper(P_A)]
        rows.append([k, counts, frac, u_prev, st, pf.origin, pf.noise_pos, pf.n_outliers, int(pf.reanchored),
                     int(pf.load_acq), lmax, *pf.mean, pf.F_hat, pf.ess, pf.Fd, pf.Fd_comp, *upper(pf.P), *upper(Pm),
                     pf.d, pf.v, int(pf.load_undo and not primed), *alt])
        sets.append([x.copy() for x in pf.x])
        idx.append(None if primed else list(pf.idx))
    return rows, sets, idx


def sync_points(rows):
    """The steps k after which the C test restarts from the reference's set:
    k + 1 a multiple of SYNC_EVERY, or step k + 1 re-acquires, undoes or is an
    outlier."""
    c_st, c_acq = PF_LOAD_COLUMNS.index("status"), PF_LOAD_COLUMNS.index("load_acq")
    c_undo = PF_LOAD_COLUMNS.index("load_undo")
    return [k for k in range(len(rows) - 1)
            if (k + 1) % SYNC_EVERY == 0 or rows[k + 1][c_acq] or rows[k + 1][c_undo]
            or rows[k + 1][c_st] == rpf.BR_W_OUTLIER]


def generate(out_dir, m, gt, rows_in):
    """Writes pf_load.csv, pf_load_x.csv, pf_glitch.csv and pf_glitch_x.csv
    from the recorded input rows_in (est_input's rows); gt is the gen_traces
    module. Returns the paths."""
    f32 = gt.f32
    pcfg, crc = gest.pf_cfg(m, f32)
    ld = load_cfg(f32)
    cfg = dataclasses.replace(pcfg, load=ld)
    F_step = gload.LOAD_STEP_FRAC * ld.max_N
    meta = gest.pf_meta(cfg, crc) + [
        ("load_q_N2", ld.q_N2), ("load_max_N", ld.max_N), ("load_q_N2_per_s", gload.LOAD_Q_N2_PER_S),
        ("load_on_k", gload.LOAD_ON_K), ("load_off_k", gload.LOAD_OFF_K), ("load_step_N", F_step)]
    paths = []
    for name, faults, what in (("pf_load", False, "without its encoder faults"),
                               ("pf_glitch", True, "with its encoder faults")):
        rows, sets, idx = run(cfg, gload.load_inputs(rows_in, gt, cfg.model.L, F_step, faults))
        rows_x = []
        for k in sync_points(rows):
            for j in range(cfg.m):
                rows_x.append([k, j, *(gest.np.float32(v) for v in sets[k][j]), idx[k + 1][j]])
        paths.append(gt.write_trace(out_dir, name, meta, PF_LOAD_COLUMNS, rows, [
            "golden/gen_pf_load_traces.py: golden/ref/pf.py (float64) with the shared external",
            "force F_d (cfg.load) on est_input.csv's counts (%s) and" % what,
            "frac, the torque u_prev_Nm raised by L load_step_N over steps [load_on_k,",
            "load_off_k) (a load the plant never got). One row per step (k = 0 primes): the",
            "input, status, origin, noise position, consecutive outliers, re-anchored (0/1),",
            "load re-acquired (0/1), max log-weight of the moved cloud (0 when priming),",
            "mean state, F_hat (mean f_nl + Fd_comp within +-load_max_N), ESS, F_d, Fd_comp",
            "(F_d through the compensation's notch at the Nyquist frequency), the common",
            "error's P after the update and Pm before it (after the period's growth and any",
            "re-acquisition or undo; P0 when priming), the cloud's d = mean theta_j - y and",
            "v = var theta_j (predicted, or moved by an undo; 0 when priming), the last",
            "re-acquisition undone (0/1), and the re-acquisition kept for the next step's",
            "undo (alt 0/1, its correction e, nu1, P as predicted; 0 when none)."]))
        paths.append(gt.write_trace(out_dir, name + "_x", meta + [("sync_every", SYNC_EVERY)], PF_LOAD_X_COLUMNS,
                                    rows_x, [
            "golden/gen_pf_load_traces.py: the particle set of %s.csv after step k," % name,
            "theta relative to the origin, rounded to float32 and printed with '%.9g'",
            "(exact), and idx_next = the resampling index of particle j at step k + 1; at",
            "every k with k + 1 a multiple of sync_every or step k + 1 a re-acquisition, an",
            "undo or an outlier: the C test restarts from the set and compares step k + 1."],
            value_fmt=gest.fmt_f32))
    return paths
