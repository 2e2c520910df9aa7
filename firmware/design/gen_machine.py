#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes a machine description's headers below a generated-header root
(default firmware/gen/, machine machines/reference.json):

  bristle_gen/machine/br_machine.h    BR_MACHINE_*: mechanics, encoder, amplifier,
                                      nominal friction, control period and torque
                                      limit, axis limits
  bristle_gen/est/br_est_machine.h    BR_EST_PF_*, BR_EST_UKF_*: the estimator
                                      section (the PF's period, particles, noise
                                      variances, spreads, g_p range, gates)

With --tuned also bristle_gen/est/br_pf_tuned.h and br_ukf_tuned.h, the
variances the circle runs with, taken from the estimator section as they are
(for a machine without a Nelder-Mead tuning; the reference machine's come from
`make tune`, sim/apps/br_tune_est.c).

Usage: gen_machine.py [--machine FILE] [--gen-root DIR] [--tuned]
A bad machine file: "FILE: field a.b.c: problem" lines, exit status 1."""
import argparse
import os

import numpy as np

import machine

# (C name, value in the file or derived, comment); floats get a double and an _F float literal
def est_rank(m, name):
    """name's place in control.estimator (1 first), 0 when it is not listed"""
    order = [e for e in m["control"]["estimator"].split(",")]
    return order.index(name) + 1 if name in order else 0


def machine_fields(m, p):
    ctl, lim = m["control"], m["limits"]
    return [
        ("BR_MACHINE_LEAD_MPRAD", p["L_mprad"], "L = lead / (2 pi), m/rad"),
        ("BR_MACHINE_M_KG", p["M_kg"], "table mass"),
        ("BR_MACHINE_J_KGM2", p["J_kgm2"], "motor + screw inertia"),
        ("BR_MACHINE_SIGMA2_NSPM", p["sigma2_Nspm"], "viscous friction"),
        ("BR_MACHINE_SIGMA0_NPM", p["sigma0_Npm"], "bristle stiffness"),
        ("BR_MACHINE_SIGMA1_NSPM", p["sigma1_Nspm"], "bristle damping"),
        ("BR_MACHINE_FC_N", p["Fc_N"], "Coulomb friction"),
        ("BR_MACHINE_FS_N", p["Fs_N"], "maximum stiction"),
        ("BR_MACHINE_VS_MPS", p["vs_mps"], "Stribeck velocity"),
        ("BR_MACHINE_COUNTS_PER_REV", p["counts_per_rev"], "encoder counts per motor revolution"),
        ("BR_MACHINE_RAD_PER_COUNT", p["rad_per_count"], "2 pi / counts_per_rev"),
        ("BR_MACHINE_TAU_PER_DUTY_NM", p["tau_per_duty_Nm"], "amplifier torque at duty 1"),
        ("BR_MACHINE_DUTY_LIMIT", m["amplifier"]["duty_limit"], "largest |duty| the amplifier accepts"),
        ("BR_MACHINE_COUNTER_BITS", m["encoder"]["counter_bits"], "width of the encoder's hardware counter"),
        ("BR_MACHINE_CTRL_PERIOD_S", ctl["period_s"], "control period (H-inf only, H-inf + UKF)"),
        ("BR_MACHINE_CTRL_PERIOD_NS", int(round(ctl["period_s"] * 1e9)), "the same in whole nanoseconds (an MCU tick)"),
        ("BR_MACHINE_TORQUE_LIMIT_NM", ctl["torque_limit_Nm"], "controller torque saturation"),
        ("BR_MACHINE_EST_RANK_PF", est_rank(m, "pf"), "control.estimator: the image's order of preference,\n"
         " * 1 first, 0 not listed; each board runs the first it can (hal/stm32/image/br_image_main.c): the PF"),
        ("BR_MACHINE_EST_RANK_UKF", est_rank(m, "ukf"), "the UKF"),
        ("BR_MACHINE_EST_RANK_NONE", est_rank(m, "none"), "none: H-infinity only"),
        ("BR_MACHINE_MAX_SPEED_MPS", lim["max_speed_mps"], "largest table speed the axis is used at"),
        ("BR_MACHINE_MAX_SPEED_COUNTS_PER_S", lim["max_speed_mps"] / (p["L_mprad"] * p["rad_per_count"]),
         "that speed in encoder counts per second (max_speed / (L rad_per_count)); times the period:\n"
         " * the largest encoder delta of one period (br_app_guard_cfg)"),
        ("BR_MACHINE_TRAVEL_M", lim["travel_m"], "stroke of the table, from BR_MACHINE_TRAVEL_MIN_M"),
        ("BR_MACHINE_TRAVEL_MIN_M", machine.limit_defaults(m)[2],
         "position of the stroke's low end (position 0 is encoder count 0)"),
        ("BR_MACHINE_LOOP_PERIOD_S", machine.loop_period_s(m),
         "the longest period the application may run at (control or PF period; machine.loop_period_s)"),
        ("BR_MACHINE_COAST_M", machine.coast_m(m),
         "how far the axis coasts from the speed fault's speed with the outputs off (machine.coast_m)"),
        ("BR_MACHINE_COAST_IN_STROKE", machine.coast_in_stroke(m),
         "limits.coast_stop: 1 stroke (the reference limiter caps the speed toward each end so that\n"
         " * a coast from it stops inside the stroke), 0 external"),
        ("BR_MACHINE_STOP_BOUND_M", machine.stop_bound_m(m),
         "stopping distance the soft travel limits keep from the stroke's ends (machine.stop_bound_m;\n"
         " * br_app_motion_cfg derives the same in float32)"),
        ("BR_MACHINE_ACTUATOR_DELAY_S", m.get("causes", {}).get("actuator_delay", {}).get("delay_s", 0.0),
         "causes.actuator_delay.delay_s, 0 without it: the force a command gives reaches the axis so\n"
         " * late (the stuck-encoder model, br_app_motion_cfg)"),
        ("BR_MACHINE_MAX_ACCEL_MPS2", machine.limit_defaults(m)[0],
         "the reference limiter's and the braking ramp's acceleration (br_app_motion_cfg)"),
        ("BR_MACHINE_MAX_FOLLOWING_M", machine.limit_defaults(m)[1],
         "largest |reference - position| before the axis brakes (br_app_motion_cfg)"),
    ]


def cause_params(m):
    """Every cause parameter of the schema, in its order: (field, value, meaning);
    0 (off) for a cause the file leaves out. The field is br_causes_t's."""
    out = []
    for cause, sec in machine.SCHEMA["causes"].items():
        given = m.get("causes", {}).get(cause, {})
        for field, leaf in sec.section.items():
            out.append((field, given.get(field, 0.0), "%s: %s" % (cause, leaf.doc)))
    return out


def render_causes(m):
    """BR_MACHINE_CAUSES: the br_causes_t initialiser of the machine's causes
    (what a diagnosis found; all 0 is the thesis model)."""
    rows = ["    .%s = %s, /* %s */ \\" % (f, machine.c_float(v), d) for f, v, d in cause_params(m)]
    return (["", "/* the causes a diagnosis found (the file's \"causes\"), a br_causes_t initialiser;",
             " * all 0: the thesis model */", "#define BR_MACHINE_CAUSES \\", "{ \\"] + rows + ["}"])


def render_mslip(m):
    """BR_MACHINE_MSLIP, the br_mslip_cfg_t initialiser of the estimators'
    Maxwell-slip friction (friction_model maxwell_slip); nothing for LuGre, so a
    file without the section gives the header it gave before it existed."""
    el = machine.mslip_elements(m)
    if not el:
        return []
    k = ", ".join(machine.c_float(e[0]) for e in el)
    a = ", ".join(machine.c_float(e[1]) for e in el)
    return ["", "/* the estimators' friction (friction_model maxwell_slip, docs/modules/mslip.md): a",
            " * br_mslip_cfg_t initialiser, k_i = share_i Fs / breakaway_i; the viscous friction",
            " * stays the model's sigma2 (eq. 6), so the elements' own is 0 */",
            "#define BR_MACHINE_MSLIP \\",
            "{ \\",
            "    .n = %d, \\" % len(el),
            "    .k_Npm = {%s}, \\" % k,
            "    .share = {%s}, \\" % a,
            "    .sigma2_Nspm = 0.0f \\",
            "}"]


def render_qec(m):
    """BR_MACHINE_QEC_*: the reversal compensation's pulse (reversal_comp,
    docs/modules/qec.md); nothing without the section, so a file without it
    gives the header it gave before it existed."""
    r = m.get("reversal_comp")
    if not r:
        return []
    return [""] + render_defines([
        ("BR_MACHINE_QEC_A0_N", r["A0_N"], "reversal compensation (reversal_comp): pulse amplitude at a = 0"),
        ("BR_MACHINE_QEC_A1_KG", r["A1_kg"], "its change per |reference acceleration|, N per m/s^2"),
        ("BR_MACHINE_QEC_TAU_S", r["tau_s"], "the pulse's decay time constant")])


def render_pf_load(m):
    """BR_EST_PF_LOAD_*, the PF's shared external force (estimator.pf.load,
    docs/modules/pf.md, "External force"); nothing without the block, so a file
    without it gives the header it gave before the block existed
    (br_machine_cfg.h: off)."""
    ld = machine.pf_load(m)
    if ld is None:
        return []
    return [""] + render_defines([
        ("BR_EST_PF_LOAD_Q_N2", ld["q_N2"], "the PF's shared external force: random walk per step"),
        ("BR_EST_PF_LOAD_MAX_N", ld["max_N"], "its bound, and the compensation's (the actuator's force)")])


def est_fields(m):
    """The estimators' settings as the firmware takes them: per step, in its
    state's units, from the file's physical ones (machine.est_per_step)."""
    pf, ukf = m["estimator"]["pf"], m["estimator"]["ukf"]
    P, U = machine.est_per_step(m, "pf"), machine.est_per_step(m, "ukf")
    ld = machine.ukf_load(m)
    out = [("BR_EST_PF_PERIOD_S", pf["period_s"], "the PF's period (its loop runs at it)"),
           ("BR_EST_PF_PERIOD_NS", int(round(pf["period_s"] * 1e9)), "the same in whole nanoseconds (an MCU tick)"),
           ("BR_EST_PF_N_PARTICLES", pf["n_particles"], "particle count")]
    for k, c in (("q_theta_counts2", "Q_THETA_COUNTS2"), ("q_omega_rad2ps2", "Q_OMEGA_RAD2PS2"),
                 ("q_z_m2", "Q_Z_M2"), ("q_gp_N2", "Q_GP_N2")):
        out.append(("BR_EST_PF_" + c, P[k], "process noise variance per step"))
    out.append(("BR_EST_PF_R_COUNTS2", P["r_counts2"], "measurement noise variance (the quantisation's 1/12 and the rest)"))
    for k, c in (("x0_theta_counts", "X0_STD_THETA_COUNTS"), ("x0_omega_radps", "X0_STD_OMEGA_RADPS"),
                 ("x0_z_m", "X0_STD_Z_M"), ("x0_gp_N", "X0_STD_GP_N")):
        out.append(("BR_EST_PF_" + c, P[k], "initial spread"))
    out += gate_fields("PF", pf, P, machine.gate_transient_rad(m, "pf"))
    out.append(("BR_EST_PF_NOISE_SKIP", pf["noise_skip"], "extra noise-table advance per step"))
    out += [("BR_EST_PF_ADAPT_NIS_REF", pf["adapt"]["nis_ref"], "innovation-driven noise of omega, z and g_p (0: off)"),
            ("BR_EST_PF_ADAPT_ALPHA", P["adapt_alpha"], "its NIS smoothing per step (period / tau_s)"),
            ("BR_EST_PF_ADAPT_MAX_SCALE", pf["adapt"]["max_scale"], "its largest variance factor"),
            ("BR_EST_PF_GP_CURVE_ON", 1 if pf.get("gp_curve") else 0,
             "g_p along the Stribeck curve (0: off, g_p a random walk)"),
            ("BR_EST_PF_GP_CURVE_RHO", machine.pf_gp_curve_rho(m), "its offset's factor per step, exp(-period / tau_s)")]
    for k, c in (("q_theta_rad2", "Q_THETA_RAD2"), ("q_omega_rad2ps2", "Q_OMEGA_RAD2PS2"),
                 ("q_z_m2", "Q_Z_M2"), ("q_gp_N2", "Q_GP_N2")):
        out.append(("BR_EST_UKF_" + c, U[k], "process noise variance per step"))
    out.append(("BR_EST_UKF_R_COUNTS2", U["r_counts2"], "measurement noise variance (the quantisation's 1/12 and the rest)"))
    for k, c in (("p0_theta_counts2", "P0_THETA_COUNTS2"), ("p0_omega_rad2ps2", "P0_OMEGA_RAD2PS2"),
                 ("p0_z_m2", "P0_Z_M2"), ("p0_gp_N2", "P0_GP_N2")):
        out.append(("BR_EST_UKF_" + c, U[k], "initial (and recovery) variance"))
    out += gate_fields("UKF", ukf, U, machine.gate_transient_rad(m, "ukf"))
    out += [("BR_EST_UKF_ALPHA", ukf["alpha"], "sigma-point spread"),
            ("BR_EST_UKF_BETA", ukf["beta"], "prior-distribution weight"),
            ("BR_EST_UKF_KAPPA", ukf["kappa"], "secondary scaling"),
            ("BR_EST_UKF_LOAD_Q_N2", ld["q_N2"], "external force: random walk per step (0 with P0: off)"),
            ("BR_EST_UKF_LOAD_P0_N2", ld["p0_N2"], "its initial (and recovery) variance; 0: no external force"),
            ("BR_EST_UKF_LOAD_MAX_N", ld["max_N"], "its bound, and the compensation's (the actuator's force)")]
    return out


def delay_id_fields(E, e, per_step):
    """An estimator's delay identification (absent: off, 0 candidates)."""
    d = e.get("delay_id") or {}
    P = "BR_EST_%s_DELAY_ID_" % E
    return [(P + "CANDIDATES", d.get("candidates", 0), "delay identification: candidates (0: off)"),
            (P + "STEP_S", d.get("step_s", 0.0), "their spacing"),
            (P + "Q_FORCE_N2PS", per_step["dlyid_q_force_N2ps"], "friction random walk per second"),
            (P + "MEMORY_S", d.get("memory_s", 0.0), "forgetting time constant"),
            (P + "WARMUP_S", d.get("warmup_s", 0.0), "no switch before"),
            (P + "SWITCH_RATIO", d.get("switch_ratio", 0.0), "switch below this ratio"),
            (P + "STEADY_AFTER_S", (d.get("steady") or {}).get("after_s", 0.0),
             "the steady phase from this time on (0: off)"),
            (P + "STEADY_MEMORY_S", (d.get("steady") or {}).get("memory_s", 0.0), "its forgetting time constant"),
            (P + "STEADY_SWITCH_RATIO", (d.get("steady") or {}).get("switch_ratio", 0.0), "its switch ratio")]


def gate_fields(E, e, per_step, transient_rad):
    return [("BR_EST_%s_GP0_N" % E, per_step["gp0_N"], "initial g_p"),
            ("BR_EST_%s_GP_MIN_N" % E, per_step["gp_min_N"], "g_p range"),
            ("BR_EST_%s_GP_MAX_N" % E, per_step["gp_max_N"], ""),
            ("BR_EST_%s_OUTLIER_SIGMA" % E, e["outlier_gate_sigma"], "outlier gate, standard deviations"),
            ("BR_EST_%s_OUTLIER_TRANSIENT_RAD" % E, transient_rad,
             "the gate's transient term, rad (outlier_transient_k (Fs - Fc) T^2 / (2 Meff) / L; 0: off)"),
            ("BR_EST_%s_REANCHOR_AFTER" % E, e["reanchor_after"], "consecutive outliers before re-anchoring"),
            ("BR_EST_%s_COMP_AHEAD_PERIODS" % E, e["comp_ahead_periods"],
             "compensation lead beyond the actuator delay, periods (0: the filtered estimate)")] + \
        delay_id_fields(E, e, per_step)


def render_defines(fields):
    out = []
    for name, v, doc in fields:
        if doc:
            out.append("/* %s */" % doc)
        if isinstance(v, int):
            out.append("#define %s %du" % (name, v))
        else:
            out.append("#define %s (%s)" % (name, repr(float(v))))
            out.append("#define %s_F (%s)" % (name, machine.c_float(v)))
    return out


def render_machine(m):
    out = [
        "/* generated by firmware/design/gen_machine.py from %s -- do not edit */" % machine.c_comment_text(m["file"]),
        "/* SPDX-License-Identifier: Apache-2.0 */",
        "/* The machine's parameters. Each value is given as a double literal (for the",
        " * double-precision simulator) and as a float literal that rounds exactly",
        " * (suffix _F, for the firmware). */",
        "#ifndef BR_GEN_MACHINE_H",
        "#define BR_GEN_MACHINE_H",
        "",
        "/* the machine description these values come from: its path (relative to the",
        " * repository when inside it) as a C string, and the same with every character",
        " * outside [A-Za-z0-9 ._+,:=@%~/-] replaced by _, for a generated comment */",
        "#define BR_MACHINE_FILE %s" % machine.c_string_literal(m["file"]),
        "#define BR_MACHINE_FILE_COMMENT %s" % machine.c_string_literal(machine.c_comment_text(m["file"])),
        "/* the machine file's name ([a-z0-9][a-z0-9_-]*), which the link's hello_reply carries */",
        "#define BR_MACHINE_NAME %s" % machine.c_string_literal(m["name"]),
    ]
    out += render_defines(machine_fields(m, machine.params(m)))
    out += render_causes(m)
    out += render_mslip(m)
    out += render_qec(m)
    out += ["", "#endif", ""]
    return "\n".join(out)


def render_est(m):
    out = [
        "/* generated by firmware/design/gen_machine.py from %s -- do not edit */" % machine.c_comment_text(m["file"]),
        "/* SPDX-License-Identifier: Apache-2.0 */",
        "/* The estimators' settings of the machine description (its \"estimator\" section):",
        " * per step, converted from the file's physical units by machine.est_per_step:",
        " * double and exact float (_F) literals, counts as unsigned integers. Variances",
        " * in counts^2 and spreads in counts are multiplied by BR_MACHINE_RAD_PER_COUNT_F",
        " * (squared) where the configuration is built (sim/lib/circle/br_circle_est.c). */",
        "#ifndef BR_GEN_EST_MACHINE_H",
        "#define BR_GEN_EST_MACHINE_H",
        "",
    ]
    out += render_defines(est_fields(m))
    out += render_pf_load(m)
    out += ["", "#endif", ""]
    return "\n".join(out)


def render_tuned(m, est):
    """The br_<est>_tuned.h of a machine without a tuning: the estimator section's
    variances, in the units and float32 arithmetic of the configuration."""
    f32 = np.float32
    rpc = f32(machine.params(m)["rad_per_count"])
    e = machine.est_per_step(m, est)
    r = f32(e["r_counts2"]) * rpc * rpc
    vals = [("q_omega", e["q_omega_rad2ps2"]), ("q_z", e["q_z_m2"]), ("q_gp", e["q_gp_N2"]), ("r", r)]
    if est == "ukf":
        vals = [("q_theta", e["q_theta_rad2"])] + vals
    E = est.upper()
    out = ["/* generated by firmware/design/gen_machine.py from %s -- do not edit */" % machine.c_comment_text(m["file"]),
           "/* SPDX-License-Identifier: Apache-2.0 */",
           "/* not a tuning result: the variances of the machine file's estimator section, as they are */",
           "#ifndef BR_%s_TUNED_H" % E, "#define BR_%s_TUNED_H" % E, ""]
    for name, v in vals:
        out.append("#define BR_%s_TUNED_%s (%s)" % (E, name, machine.c_float(v)))
    out += ["", "#endif", ""]
    return "\n".join(out)


def write(path, text):
    """through a temporary file and a rename: a failed run leaves the old header"""
    machine.write_atomic(path, text)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--machine", default=machine.REFERENCE_MACHINE, help="machine description (JSON)")
    ap.add_argument("--gen-root", default=machine.GEN_DIR, help="root of bristle_gen/ (default firmware/gen)")
    ap.add_argument("--tuned", action="store_true",
                    help="also write bristle_gen/est/br_{pf,ukf}_tuned.h from the estimator section")
    a = ap.parse_args()
    m = machine.load_or_exit(a.machine)
    root = os.path.join(a.gen_root, "bristle_gen")
    # every header rendered before the first is written
    out = [(os.path.join(root, "machine", "br_machine.h"), render_machine(m)),
           (os.path.join(root, "est", "br_est_machine.h"), render_est(m))]
    if a.tuned:
        out += [(os.path.join(root, "est", "br_%s_tuned.h" % est), render_tuned(m, est)) for est in ("pf", "ukf")]
    for path, text in out:
        write(path, text)


if __name__ == "__main__":
    main()
