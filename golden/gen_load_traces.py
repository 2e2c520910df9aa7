# SPDX-License-Identifier: Apache-2.0
"""Golden trace of the UKF with the external-force state (docs/modules/ukf.md,
"External force"), called by golden/gen_traces.py (docs/golden.md,
"ukf_load"):

  ukf_load.csv  golden/ref/ukf.py with cfg.load (n = 5, F_d and the load
                re-acquisition) on the estimators' recorded input
                (est_input.csv) without its two encoder faults, with a load
                step: from step LOAD_ON_K to LOAD_OFF_K the torque the filter
                is told is the applied torque plus L F_step, which the plant
                never received -- to the filter, an external force
                F_d = F_step that comes on and goes off again. The input
                columns (counts, frac, u_prev_Nm) are in the trace itself.
  ukf_glitch.csv the same with est_input.csv's two encoder faults kept (a
                500-count spike, a 1000-count slip from then on, both while
                the load is on): either is within what a load explains
                (|dF| <= 2 max_N), is re-acquired, and the next step undoes
                the re-acquisition (docs/modules/ukf.md, "A glitch is not a
                load"; without the undo a lasting period-2 cycle,
                docs/golden.md, "ukf_glitch").
Both carry the re-acquisition's alternative after each step (alt_*), which
the C one-step comparison seeds as it seeds the state.

The load configuration is the machine loader's (machine.ukf_load: P0 = the
actuator's force squared, the bound = the actuator's force) with the fault
campaign's random walk LOAD_Q_N2_PER_S, per step at the input's 1.5 ms.
Same conventions as gen_traces.py (write_trace, f32, fixed seeds, '%.17g').
"""
import copy
import dataclasses

from ref import MACHINE_JSON, machine_module
from ref import ukf as rukf
import gen_est_traces as gest

# the fault campaign's random walk of F_d (docs/modules/ukf.md, "External force")
LOAD_Q_N2_PER_S = 1.0e4
# the load step: F_step = LOAD_STEP_FRAC x the actuator's force over [LOAD_ON_K, LOAD_OFF_K)
LOAD_ON_K = 300
LOAD_OFF_K = 1200
LOAD_STEP_FRAC = 0.25

NS = rukf.NX + 1
UKF_LOAD_P_COLUMNS = ["P%d%d" % (i, j) for i in range(NS) for j in range(i, NS)]
UKF_ALT_COLUMNS = (["alt", "alt_origin", "alt_nu", "alt_theta", "alt_omega", "alt_z", "alt_gp", "alt_Fd"]
                   + ["alt_" + c for c in UKF_LOAD_P_COLUMNS])
UKF_LOAD_COLUMNS = (["k", "counts", "frac", "u_prev_Nm", "status", "origin_counts", "n_outliers", "reanchored",
                     "load_acq", "load_undo", "theta", "omega", "z", "gp", "Fd"] + UKF_LOAD_P_COLUMNS
                    + ["F_hat", "innov", "innov_var"] + ["Pm%d%d" % (i, i) for i in range(NS)] + UKF_ALT_COLUMNS)


def alt_row(u):
    """The held alternative after a step (docs/modules/ukf.md, "A glitch is
    not a load"): pending (0/1), origin, nu_1, mean, P (upper); 0 when none."""
    a = u.alt
    if a is None:
        return [0] * len(UKF_ALT_COLUMNS)
    return [1, a["origin"], a["nu"], *a["x"]] + [a["P"][i][j] for i in range(NS) for j in range(i, NS)]


def load_cfg(f32):
    """machine.ukf_load of the reference machine with estimator.ukf.load =
    {q_N2_per_s: LOAD_Q_N2_PER_S}, per step at the input's period."""
    mm = machine_module()
    mach = copy.deepcopy(mm.load_or_exit(MACHINE_JSON))
    mach["estimator"]["ukf"]["load"] = {"q_N2_per_s": LOAD_Q_N2_PER_S}
    mach["control"]["period_s"] = gest.EST_DT
    ld = mm.ukf_load(mach)
    return rukf.LoadCfg(q_N2=f32(ld["q_N2"]), p0_N2=f32(ld["p0_N2"]), max_N=f32(ld["max_N"]))


def run(cfg, inputs):
    u = rukf.Ukf(cfg)
    rows = []
    for k, counts, frac, u_prev in inputs:
        st = u.step(counts, frac, u_prev)
        assert st in (rukf.BR_OK, rukf.BR_W_OUTLIER), (k, st)
        P = [u.P[i][j] for i in range(NS) for j in range(i, NS)]
        rows.append([k, counts, frac, u_prev, st, u.origin, u.n_outliers, int(u.reanchored), int(u.load_acq),
                     int(u.load_undo), *u.x, *P, u.F_hat, u.nu, u.S, *u.Pm_diag, *alt_row(u)])
    return rows


def load_inputs(rows_in, gt, L, F_step, faults=False):
    """The filter's input (k, counts, frac, u_prev) from est_input's rows
    rows_in: the counts without the injected encoder faults (with them when
    faults), the torque raised by L F_step over steps [LOAD_ON_K, LOAD_OFF_K)
    (float32-exact)."""
    inputs = []
    for r in rows_in:
        k, counts, frac, u_prev, fault = r[0], r[2], r[3], r[4], r[5]
        # the encoder without the injected faults (est_input's fault 1: the spike, 2: the slip)
        if not faults:
            counts = gt.rctrl.to_int32(counts - {0: 0, 1: gest.SPIKE_COUNTS, 2: gest.SLIP_COUNTS}[fault])
        # the torque the filter is told: the applied one, plus L F_step while the load is on
        if LOAD_ON_K <= k < LOAD_OFF_K:
            u_prev = gt.f32(u_prev + L * F_step)
        inputs.append((k, counts, frac, u_prev))
    return inputs


def generate(out_dir, m, gt, rows_in):
    """Writes ukf_load.csv and ukf_glitch.csv from the recorded input rows_in
    (gen_est_traces's est_input rows); gt is the gen_traces module. Returns
    the paths."""
    f32 = gt.f32
    ld = load_cfg(f32)
    cfg = dataclasses.replace(gest.ukf_cfg(m, f32), load=ld)
    F_step = LOAD_STEP_FRAC * ld.max_N
    meta = gest.ukf_meta(cfg) + [
        ("load_q_N2", ld.q_N2), ("load_p0_N2", ld.p0_N2), ("load_max_N", ld.max_N),
        ("load_q_N2_per_s", LOAD_Q_N2_PER_S), ("load_on_k", LOAD_ON_K), ("load_off_k", LOAD_OFF_K),
        ("load_step_N", F_step)]
    rows_desc = [
        "One row per step (k = 0 primes): the input, status, origin, consecutive",
        "outliers, re-anchored (0/1), load re-acquired (0/1), re-acquisition undone",
        "(0/1), posterior mean (theta relative to origin), P (upper triangle), F_hat",
        "(friction + F_d within +-load_max_N), innovation nu and its variance S (0",
        "when priming; after a re-acquisition or an undo the repeated prediction's),",
        "diagonal of the last P-, the held alternative (alt 0/1, its origin, nu_1,",
        "mean, P upper; 0 when none)."]
    paths = []
    for name, faults, what in (("ukf_load", False, "without its encoder faults"),
                               ("ukf_glitch", True, "with its encoder faults")):
        rows = run(cfg, load_inputs(rows_in, gt, cfg.model.L, F_step, faults))
        paths.append(gt.write_trace(out_dir, name, meta, UKF_LOAD_COLUMNS, rows, [
            "golden/gen_load_traces.py: golden/ref/ukf.py (float64) with the external force",
            "F_d (cfg.load, n = 5) on est_input.csv's counts (%s) and" % what,
            "frac, the torque u_prev_Nm raised by L load_step_N over steps [load_on_k,",
            "load_off_k) (a load the plant never got)."] + rows_desc))
    return paths
