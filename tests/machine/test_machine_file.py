#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The machine-file loader (firmware/design/machine.py, docs/machine-file.md):
every machine of machines/ loads; a broken file fails with one
"FILE: field a.b.c: problem" line per problem and exit status 1, without a
traceback, from the loader and from each generator; a machine with no
stabilising H-infinity design is refused by synth_hinf.py.

Usage: test_machine_file.py --work DIR"""
import argparse
import copy
import glob
import json
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import DESIGN, REPO, check, result  # noqa: E402
import machine  # noqa: E402


def write(work, name, obj):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(obj if isinstance(obj, str) else json.dumps(obj, indent=2))
    return path


def run(script, *args):
    p = subprocess.run([sys.executable, os.path.join(DESIGN, script)] + list(args), capture_output=True, text=True)
    return p.returncode, p.stderr


def expect_errors(work, name, obj, wanted):
    """The loader's lines for the file, each wanted text among them, and the same
    from the command line: exit 1, no traceback."""
    path = write(work, name, obj)
    try:
        machine.load(path)
        lines = []
    except machine.MachineError as e:
        lines = e.lines
    for w in wanted:
        found = any(l == "%s: %s" % (machine.display_name(path), w) for l in lines)
        check(found, "%s: reports \"%s\"%s" % (name, w, "" if found else " (got %s)" % lines))
    for script, extra in (("machine.py", [path]), ("gen_machine.py", ["--machine", path, "--gen-root", work]),
                          ("synth_hinf.py", ["--machine", path, "--out", os.path.join(work, "g.h")])):
        rc, err = run(script, *extra)
        check(rc == 1 and "Traceback" not in err and all(w in err for w in wanted),
              "%s: %s exits 1 with the messages, no traceback (rc %d)" % (name, script, rc))


def est_header(work, name, obj):
    """gen_machine.py on obj written as NAME.json: its exit status and the br_est_machine.h it wrote."""
    path = write(work, name + ".json", obj)
    rc, _ = run("gen_machine.py", "--machine", path, "--gen-root", os.path.join(work, name + "_gen"))
    with open(os.path.join(work, name + "_gen", "bristle_gen", "est", "br_est_machine.h")) as f:
        return rc, f.read()


def friction_model_cases(work, good):
    """friction_model (docs/machine-file.md): the Maxwell-slip element set, each
    refusal the firmware's br_mslip_cfg_check / br_model_init would make, and a
    valid set's header (BR_MACHINE_MSLIP: k_i = share_i Fs / d_i)."""
    def fm(**kw):
        b = copy.deepcopy(good)
        b["estimator"]["pf"].pop("load", None)  # the PF's load is LuGre-only (pf_load_mslip.json below)
        b["friction_model"] = dict({"model": "maxwell_slip", "breakaway_m": [2e-6, 5e-6, 1e-5, 2e-5],
                                    "share": [0.25, 0.25, 0.25, 0.25]}, **kw)
        return b
    expect_errors(work, "fm-sum.json", fm(share=[0.25, 0.25, 0.25, 0.26]),
                  ["field friction_model.share: sums to 1.01, must be 1 (within 1e-06)"])
    expect_errors(work, "fm-len.json", fm(share=[0.5, 0.5]),
                  ["field friction_model.share: has 2 entries, breakaway_m 4"])
    expect_errors(work, "fm-many.json", fm(breakaway_m=[1e-6] * 9, share=[1.0 / 9] * 9),
                  ["field friction_model.breakaway_m: has 9 entries, expected 1 to 8",
                   "field friction_model.share: has 9 entries, expected 1 to 8"])
    expect_errors(work, "fm-range.json", fm(breakaway_m=[2e-6, 0.0, 1e-5, 2e-5], share=[0.25, 0.25, "a", 0.25]),
                  ["field friction_model.breakaway_m: entry 1: 0 is outside (0, 0.01]",
                   "field friction_model.share: entry 2: expected a number, got a string"])
    b = fm()
    del b["friction_model"]["share"]
    expect_errors(work, "fm-missing.json", b,
                  ["field friction_model.share: missing (model maxwell_slip needs its element set)"])
    expect_errors(work, "fm-lugre.json", fm(model="lugre"),
                  ["field friction_model.breakaway_m: given with model lugre (only maxwell_slip has elements)",
                   "field friction_model.share: given with model lugre (only maxwell_slip has elements)"])
    expect_errors(work, "fm-model.json", fm(model="gms"),
                  ["field friction_model.model: 'gms' does not match lugre|maxwell_slip"])
    b = fm()
    b["causes"] = {"offset": {"offset_N": 1.0}}
    expect_errors(work, "fm-causes.json", b, ["field friction_model.model: maxwell_slip is not combined with the "
                                              "causes offset yet (only actuator_delay; docs/modules/model.md)"])
    m = machine.load(write(work, "fm-ok.json", fm()))
    check(machine.mslip_elements(m) == [(0.25 * 18.0 / d, 0.25) for d in (2e-6, 5e-6, 1e-5, 2e-5)]
          if m["friction"]["Fs_N"] == 18.0 else len(machine.mslip_elements(m)) == 4,
          "friction_model: k_i = share_i Fs / d_i")
    rc, err = run("gen_machine.py", "--machine", os.path.join(work, "fm-ok.json"), "--gen-root", work)
    with open(os.path.join(work, "bristle_gen", "machine", "br_machine.h")) as f:
        h = f.read()
    check(rc == 0 and "#define BR_MACHINE_MSLIP" in h and ".n = 4," in h,
          "friction_model maxwell_slip: gen_machine.py writes BR_MACHINE_MSLIP")
    lug = copy.deepcopy(good)
    lug["friction_model"] = {"model": "lugre"}
    rc, err = run("gen_machine.py", "--machine", write(work, "fm-lugre-ok.json", lug), "--gen-root", work)
    with open(os.path.join(work, "bristle_gen", "machine", "br_machine.h")) as f:
        h = f.read()
    check(rc == 0 and "BR_MACHINE_MSLIP" not in h, "friction_model lugre: no element set in the header")
    # the firmware's limit is the schema's
    with open(os.path.join(REPO, "firmware", "include", "bristle", "br_mslip.h")) as f:
        mm = re.search(r"#define\s+BR_MSLIP_MAX\s+([0-9]+)", f.read())
    check(mm is not None and int(mm.group(1)) == machine.MSLIP_MAX, "br_mslip.h: BR_MSLIP_MAX is the schema's")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", required=True)
    work = ap.parse_args().work
    os.makedirs(work, exist_ok=True)

    files = sorted(glob.glob(os.path.join(REPO, "machines", "*.json")))
    check(len(files) >= 2, "machines/ holds the reference and at least one other machine")
    for f in files:
        m = machine.load(f)
        check(m["format_version"] == machine.FORMAT_VERSION, "%s loads" % os.path.relpath(f, REPO))
    ref = machine.load(machine.REFERENCE_MACHINE)
    p = machine.params(ref)
    check(p["Fc_N"] == ref["friction"]["Fc_N"] and abs(p["L_mprad"] * 2 * 3.141592653589793 -
                                                     ref["mechanics"]["lead_m_per_rev"]) < 1e-15,
          "params(): symbols and L = lead / 2 pi")

    with open(machine.REFERENCE_MACHINE) as f:
        good = json.load(f)

    bad = copy.deepcopy(good)
    bad["mechanics"]["mass_kg"] = bad["mechanics"].pop("table_mass_kg")
    expect_errors(work, "typo.json", bad, ["field mechanics.mass_kg: unknown field (expected one of: "
                                           "table_mass_kg, inertia_kgm2, lead_m_per_rev)",
                                           "field mechanics.table_mass_kg: missing"])
    bad = copy.deepcopy(good)
    bad["friction"]["Fc_N"] = 0.0
    bad["encoder"]["counter_bits"] = "32"
    bad["estimator"]["pf"]["n_particles"] = machine.PF_MAX_PARTICLES + 1
    bad["estimator"]["ukf"]["comp_ahead_periods"] = 2.5
    bad["estimator"]["ukf"]["delay_id"]["candidates"] = machine.DLYID_MAX_CAND + 1
    bad["estimator"]["pf"]["delay_id"]["switch_ratio"] = 1.0
    expect_errors(work, "range.json", bad, ["field friction.Fc_N: 0 is outside (0, 100000]",
                                            "field encoder.counter_bits: expected an integer, got a string",
                                            "field estimator.pf.n_particles: 2049 is outside [1, 2048]",
                                            "field estimator.ukf.comp_ahead_periods: 2.5 is outside [0, 2]",
                                            "field estimator.ukf.delay_id.candidates: 9 is outside [2, 8]",
                                            "field estimator.pf.delay_id.switch_ratio: 1 is outside (0, 1)"])
    # the schema's firmware limits are the firmware headers' (one home each: the headers)
    for header, name, value in (("br_pf.h", "BR_PF_MAX_PARTICLES", machine.PF_MAX_PARTICLES),
                                ("br_est.h", "BR_EST_AHEAD_MAX_PERIODS", machine.EST_AHEAD_MAX_PERIODS),
                                ("br_dlyid.h", "BR_DLYID_MAX_CAND", machine.DLYID_MAX_CAND),
                                ("br_est.h", "BR_EST_DELAY_HIST", machine.EST_DELAY_MAX_PERIODS + 2)):
        with open(os.path.join(REPO, "firmware", "include", "bristle", header)) as f:
            m = re.search(r"#define\s+%s\s+([0-9.]+)u?f?\b" % name, f.read())
        check(m is not None and float(m.group(1)) == float(value),
              "%s: %s is %s, the machine schema's %s" % (header, name, m and m.group(1), value))
    with open(os.path.join(REPO, "firmware", "include", "bristle", "br_pf.h")) as f:
        m = re.search(r"#define\s+BR_PF_MS_SLOTS\s+\(([0-9]+)u \* BR_PF_MAX_PARTICLES\)", f.read())
    check(m is not None and int(m.group(1)) == machine.PF_MS_SLOTS_PER_PARTICLE,
          "br_pf.h: BR_PF_MS_SLOTS is %s BR_PF_MAX_PARTICLES, the machine schema's %d"
          % (m and m.group(1), machine.PF_MS_SLOTS_PER_PARTICLE))
    bad = copy.deepcopy(good)
    bad["friction"]["Fs_N"] = 0.5 * bad["friction"]["Fc_N"]
    bad["control"]["torque_limit_Nm"] = 2.0 * bad["amplifier"]["torque_per_duty_Nm"]
    bad["estimator"]["ukf"]["gp0_Fs"] = 2.0 * bad["estimator"]["ukf"]["gp_max_Fs"]
    bad["estimator"]["pf"]["adapt"]["tau_s"] = 0.5 * bad["estimator"]["pf"]["period_s"]
    for est in ("pf", "ukf"):
        bad["estimator"][est]["delay_id"]["step_s"] = 0.1  # 7 x 0.1 s: beyond 62 periods of either period
    bad["causes"] = {"actuator_delay": {"delay_s": 0.1}}  # beyond 62 periods of control.period_s
    expect_errors(work, "cross.json", bad, ["field friction.Fs_N: must be >= friction.Fc_N (7 N)",
                                            "field control.torque_limit_Nm: must be <= amplifier.duty_limit * "
                                            "amplifier.torque_per_duty_Nm",
                                            "field estimator.ukf.gp0_Fs: gp0_Fs * Fs_N must lie in "
                                            "[gp_min_Fc * Fc_N, gp_max_Fs * Fs_N]",
                                            "field estimator.pf.adapt.tau_s: must be >= estimator.pf.period_s (alpha = period_s / tau_s <= 1)",
                                            "field causes.actuator_delay.delay_s: must be <= %d periods of "
                                            "control.period_s" % machine.EST_DELAY_MAX_PERIODS,
                                            "field estimator.pf.delay_id.step_s: (candidates - 1) * step_s must be "
                                            "<= %d periods of estimator.pf.period_s" % machine.EST_DELAY_MAX_PERIODS,
                                            "field estimator.ukf.delay_id.step_s: (candidates - 1) * step_s must be "
                                            "<= %d periods of control.period_s" % machine.EST_DELAY_MAX_PERIODS])
    bad = copy.deepcopy(good)
    bad["provenance"] = {"friction.Fc_N": "identified", "mechanics.mass_kg": "given",
                         "causes.offset.offset_N": "measured", "friction": "assumed"}
    expect_errors(work, "provenance.json", bad, [
        "field provenance.mechanics.mass_kg: not a value of the machine file (a field path such as friction.Fc_N "
        "or causes.offset.offset_N)",
        "field provenance.causes.offset.offset_N: 'measured' is not one of identified, derived, assumed, given",
        "field provenance.friction: not a value of the machine file (a field path such as friction.Fc_N "
        "or causes.offset.offset_N)"])
    ok = copy.deepcopy(good)
    ok["provenance"] = {"friction.Fc_N": "identified", "causes.asymmetric_friction.dFc_neg_N": "identified",
                        "mechanics.lead_m_per_rev": "derived", "limits.travel_m": "assumed"}
    m = machine.load(write(work, "provenance-ok.json", ok))
    check(machine.provenance(m, "friction.Fc_N") == "identified" and machine.provenance(m, "friction.Fs_N") == "given",
          "provenance: a listed field has its kind, an unlisted one is given")
    friction_model_cases(work, good)
    bad = copy.deepcopy(good)
    bad["format_version"] = 3
    expect_errors(work, "version.json", bad, ["field format_version: 3 is not a version this loader reads (2)"])
    bad["format_version"] = 1
    expect_errors(work, "version1.json", bad, ["field format_version: 1 is not a version this loader reads (2); "
                                               "format 1's estimator settings were per step and in encoder counts: "
                                               "convert the file with " + machine.FORMAT_UPGRADE])
    # a physical setting whose per-step value the firmware refuses is named by the file's field
    bad = copy.deepcopy(good)
    bad["estimator"]["pf"]["process_noise"]["z_zs2_per_s"] = 1.0e9
    bad["estimator"]["ukf"]["p0_var"]["speed_m2_per_s2"] = 1.0e-60
    fr, lead = good["friction"], good["mechanics"]["lead_m_per_rev"]
    q_z = 1.0e9 * (fr["Fs_N"] / fr["sigma0_Npm"]) ** 2 * good["estimator"]["pf"]["period_s"]
    p0_om = 1.0e-60 / (lead / (2.0 * math.pi)) ** 2
    expect_errors(work, "per-step.json", bad, [
        "field estimator.pf.process_noise.z_zs2_per_s: gives q_z_m2 = %.6g per step on this machine, outside the "
        "firmware's [0, 1e-06]" % q_z,
        "field estimator.ukf.p0_var.speed_m2_per_s2: gives p0_omega_rad2ps2 = %.6g per step on this machine, outside "
        "the firmware's (0 excluded) [0, 1e+06]" % p0_om])
    # a stroke that leaves no travel inside the soft limits (the stop bound at
    # each end, br_app_motion_cfg), and one beyond the int32 position count
    bad = copy.deepcopy(good)
    bad["limits"]["travel_m"] = 1.5 * machine.stop_bound_m(good)
    expect_errors(work, "stroke.json", bad, [
        "field limits.travel_m: %s m leaves no travel inside the soft limits: the axis needs %s m at each end to "
        "brake from the speed fault's speed (docs/reliability.md, \"Drive protections\")"
        % (machine._g(bad["limits"]["travel_m"]), machine._g(machine.stop_bound_m(good)))])
    bad = copy.deepcopy(good)
    bad["limits"].pop("max_accel_mps2", None)
    bad["control"]["torque_limit_Nm"] = 0.5 * good["friction"]["Fs_N"] * good["mechanics"]["lead_m_per_rev"] / (
        2.0 * math.pi)
    expect_errors(work, "accel.json", bad, [
        "field limits.max_accel_mps2: missing, and the default, half of what the actuator gives beyond stiction, is "
        "not positive: control.torque_limit_Nm / L is below friction.Fs_N; give the axis's acceleration"])
    bad = copy.deepcopy(good)
    bad["limits"]["travel_min_m"] = 20.0
    path = write(work, "reach.json", bad)
    try:
        machine.load(path)
        lines = []
    except machine.MachineError as e:
        lines = e.lines
    check(len(lines) == 1 and "field limits.travel_m: the stroke reaches" in lines[0]
          and "beyond the int32 position count (2^31)" in lines[0], "reach.json: a stroke beyond the int32 count (%s)" % lines)
    bad = copy.deepcopy(good)
    bad["limits"]["coast_stop"] = "brake"
    expect_errors(work, "coast.json", bad, ["field limits.coast_stop: 'brake' does not match stroke|external"])
    ext = copy.deepcopy(good)
    ext["limits"]["coast_stop"] = "external"
    check(machine.coast_in_stroke(machine.load(write(work, "coast-ext.json", ext))) == 0
          and machine.coast_in_stroke(machine.load(write(work, "coast-default.json", good))) == 1,
          "limits.coast_stop: external turns the coast envelope off, the default is on")
    path = write(work, "syntax.json", "{\n  \"name\": \"x\",\n}\n")
    rc, err = run("machine.py", path)
    check(rc == 1 and err.startswith("%s: not valid JSON: line 3" % machine.display_name(path))
          and "Traceback" not in err,
          "syntax.json: names the file and the line")

    # the causes a diagnosis found reach the firmware's model configuration
    # (BR_MACHINE_CAUSES, br_machine_cfg.h); a cause left out is 0 (off)
    withc = copy.deepcopy(good)
    withc["estimator"]["pf"].pop("load", None)  # the PF's load needs the thesis model (pf_load_ext.json below)
    withc["causes"] = {"friction_drift": {"drift_per_s": 0.01}, "offset": {"offset_N": -1.5}}
    path = write(work, "causes.json", withc)
    rc, err = run("gen_machine.py", "--machine", path, "--gen-root", os.path.join(work, "causes_gen"))
    with open(os.path.join(work, "causes_gen", "bristle_gen", "machine", "br_machine.h")) as f:
        hdr = f.read()
    check(rc == 0 and ".drift_per_s = %s," % machine.c_float(0.01) in hdr
          and ".offset_N = %s," % machine.c_float(-1.5) in hdr and ".delay_s = %s," % machine.c_float(0.0) in hdr,
          "causes.json: gen_machine.py writes the causes into BR_MACHINE_CAUSES")
    withc["causes"] = {"friction_drift": {"drift_per_s": 2.0}}
    expect_errors(work, "drift.json", withc, ["field causes.friction_drift.drift_per_s: 2 is outside [-1, 1]"])

    # the UKF's external-force state (estimator.ukf.load, docs/modules/ukf.md): absent = 0 (off);
    # present: q per step = q_N2_per_s * control.period_s, P0 and the bound from the actuator's force
    withl = copy.deepcopy(good)
    withl["estimator"]["ukf"]["load"] = {"q_N2_per_s": 1.0e4}
    path = write(work, "load.json", withl)
    rc, err = run("gen_machine.py", "--machine", path, "--gen-root", os.path.join(work, "load_gen"))
    with open(os.path.join(work, "load_gen", "bristle_gen", "est", "br_est_machine.h")) as f:
        hdr = f.read()
    F_act = good["control"]["torque_limit_Nm"] * 2.0 * math.pi / good["mechanics"]["lead_m_per_rev"]
    check(rc == 0 and "#define BR_EST_UKF_LOAD_Q_N2_F (%s)" % machine.c_float(1.0e4 * good["control"]["period_s"]) in hdr
          and "#define BR_EST_UKF_LOAD_P0_N2_F (%s)" % machine.c_float(F_act * F_act) in hdr
          and "#define BR_EST_UKF_LOAD_MAX_N_F (%s)" % machine.c_float(F_act) in hdr,
          "load.json: gen_machine.py writes the UKF's external force (q per step, the actuator's force)")
    withl["estimator"]["ukf"].pop("load")
    off = machine.ukf_load(machine.load(write(work, "ukf_noload.json", withl)))
    check(off == {"q_N2": 0.0, "p0_N2": 0.0, "max_N": 0.0}, "no estimator.ukf.load: the external force is off")
    withl["estimator"]["ukf"]["load"] = {"q_N2_per_s": 0.0}
    expect_errors(work, "load0.json", withl, ["field estimator.ukf.load.q_N2_per_s: 0 is outside (0, 1e+09]"])
    withl["estimator"]["ukf"]["load"] = {"q_N2_per_s": 1.0e-40}
    expect_errors(work, "load_sub.json", withl, [
        "field estimator.ukf.load.q_N2_per_s: gives q_N2 = 1e-43 per step on this machine, outside the "
        "firmware's (0 excluded) [1.17549e-38, 1e+12]"])

    # the delay identification's steady phase (estimator.<est>.delay_id.steady, docs/modules/dlyid.md):
    # absent = 0 (one phase); present: its three values in the header; out of range: the field named
    ones = copy.deepcopy(good)
    ones["estimator"]["pf"]["delay_id"].pop("steady", None)
    rc, hdr = est_header(work, "dly_one", ones)
    check(rc == 0 and "#define BR_EST_PF_DELAY_ID_STEADY_AFTER_S_F (0.000000000e+00f)" in hdr,
          "no estimator.pf.delay_id.steady: the bank's one phase (0 in the header)")
    withs = copy.deepcopy(good)
    withs["estimator"]["pf"]["delay_id"]["steady"] = {"after_s": 0.3, "memory_s": 0.02, "switch_ratio": 0.5}
    rc, hdr = est_header(work, "dly_steady", withs)
    check(rc == 0 and "#define BR_EST_PF_DELAY_ID_STEADY_AFTER_S_F (%s)" % machine.c_float(0.3) in hdr
          and "#define BR_EST_PF_DELAY_ID_STEADY_MEMORY_S_F (%s)" % machine.c_float(0.02) in hdr
          and "#define BR_EST_PF_DELAY_ID_STEADY_SWITCH_RATIO_F (%s)" % machine.c_float(0.5) in hdr,
          "dly_steady.json: gen_machine.py writes the steady phase")
    withs["estimator"]["pf"]["delay_id"]["steady"]["switch_ratio"] = 1.0
    expect_errors(work, "dly_steady_ratio.json", withs,
                  ["field estimator.pf.delay_id.steady.switch_ratio: 1 is outside (0, 1)"])

    # the PF's shared external force (estimator.pf.load, docs/modules/pf.md): absent = no
    # BR_EST_PF_LOAD_* (br_machine_cfg.h: off) and the header of before; present: q per step =
    # q_N2_per_s * estimator.pf.period_s, the bound the actuator's force
    withp = copy.deepcopy(good)
    withp["estimator"]["pf"]["load"] = {"q_N2_per_s": 1.0e4}
    rc, hdr = est_header(work, "pf_load", withp)
    check(rc == 0 and "#define BR_EST_PF_LOAD_Q_N2_F (%s)" % machine.c_float(1.0e4 * good["estimator"]["pf"]["period_s"])
          in hdr and "#define BR_EST_PF_LOAD_MAX_N_F (%s)" % machine.c_float(F_act) in hdr,
          "pf_load.json: gen_machine.py writes the PF's external force (q per PF step, the actuator's force)")
    # the same random walk as a share of the actuator's force (q_Fact2_per_s, the form that holds on another
    # axis): the same header, to the float; both forms, or neither, refused with the field named
    withf = copy.deepcopy(good)
    withf["estimator"]["pf"]["load"] = {"q_Fact2_per_s": 1.0e4 / (F_act * F_act)}
    withf["estimator"]["ukf"]["load"] = {"q_Fact2_per_s": 1.0e4 / (F_act * F_act)}
    rc, hdr = est_header(work, "pf_load_fact", withf)
    check(rc == 0 and "#define BR_EST_PF_LOAD_Q_N2_F (%s)" % machine.c_float(1.0e4 * good["estimator"]["pf"]["period_s"])
          in hdr and "#define BR_EST_UKF_LOAD_Q_N2_F (%s)" % machine.c_float(1.0e4 * good["control"]["period_s"]) in hdr,
          "pf_load_fact.json: q_Fact2_per_s times the actuator's force squared gives the q_N2_per_s header")
    for name, ld in (("both", {"q_N2_per_s": 1.0e4, "q_Fact2_per_s": 0.04}), ("neither", {})):
        withf["estimator"]["pf"]["load"] = ld
        withf["estimator"]["ukf"]["load"] = {"q_Fact2_per_s": 0.04}
        expect_errors(work, "pf_load_%s.json" % name, withf, [
            "field estimator.pf.load: needs exactly one of q_N2_per_s (N^2/s) and q_Fact2_per_s (the actuator's "
            "force squared, per second)"])
    withf["estimator"]["pf"]["load"] = {"q_Fact2_per_s": 1.0e-48}
    expect_errors(work, "pf_load_fact_sub.json", withf, [
        "field estimator.pf.load.q_Fact2_per_s: gives q_N2 = %.6g per step on this machine, outside the "
        "firmware's (0 excluded) [1.17549e-38, 1e+12]" % (1.0e-48 * F_act * F_act * good["estimator"]["pf"]["period_s"])])
    withf["estimator"]["pf"]["load"] = {"q_Fact2_per_s": 200.0}
    expect_errors(work, "pf_load_fact_big.json", withf,
                  ["field estimator.pf.load.q_Fact2_per_s: 200 is outside (0, 100]"])
    noload = copy.deepcopy(good)
    noload["estimator"]["pf"].pop("load", None)
    rc, hdr = est_header(work, "pf_noload", noload)
    check(rc == 0 and machine.pf_load(noload) is None and "BR_EST_PF_LOAD" not in hdr,
          "no estimator.pf.load: the PF's external force is off, nothing in the header")
    withp["estimator"]["pf"]["load"] = {"q_N2_per_s": 0.0}
    expect_errors(work, "pf_load0.json", withp, ["field estimator.pf.load.q_N2_per_s: 0 is outside (0, 1e+09]"])
    withp["estimator"]["pf"]["load"] = {"q_N2_per_s": 2.0e9}
    expect_errors(work, "pf_load_big.json", withp,
                  ["field estimator.pf.load.q_N2_per_s: 2e+09 is outside (0, 1e+09]"])
    withp["estimator"]["pf"]["load"] = {"q_N2_per_s": 1.0e-40}
    expect_errors(work, "pf_load_sub.json", withp, [
        "field estimator.pf.load.q_N2_per_s: gives q_N2 = 1.5e-43 per step on this machine, outside the "
        "firmware's (0 excluded) [1.17549e-38, 1e+12]"])
    withp["estimator"]["pf"]["load"] = {"q_N2_per_s": 1.0e4}
    withp["causes"] = {"offset": {"offset_N": -1.5}}
    expect_errors(work, "pf_load_ext.json", withp, [
        "field estimator.pf.load: needs the thesis model; the causes offset make the estimators' model the "
        "extended one"])
    withp["causes"] = {"actuator_delay": {"delay_s": 1.0e-3}}
    path = write(work, "pf_load_delay.json", withp)
    rc, err = run("gen_machine.py", "--machine", path, "--gen-root", os.path.join(work, "pf_load_delay_gen"))
    check(rc == 0, "pf_load_delay.json: an actuator delay keeps the thesis model (%r)" % err.strip())
    # nor Maxwell-slip elements in the PF's particles (br_pf_init refuses them with the load)
    withp["causes"] = {}
    withp["friction_model"] = {"model": "maxwell_slip", "breakaway_m": [2e-6, 5e-6, 1e-5, 2e-5],
                               "share": [0.25, 0.25, 0.25, 0.25]}
    expect_errors(work, "pf_load_mslip.json", withp, [
        "field estimator.pf.load: needs the LuGre model; with friction_model maxwell_slip the PF's particles carry "
        "elements, which the load's move of the cloud does not"])
    withp.pop("friction_model")

    # weights that make the sampled loop unstable: no design, a clear message
    bad = copy.deepcopy(good)
    bad["control"]["hinf"]["weight_theta_per_rad"] = 1.0e3
    bad["control"]["hinf"]["weight_eps_per_rad_s"] = 1.0e5
    path = write(work, "unstable.json", bad)
    rc, err = run("synth_hinf.py", "--machine", path, "--out", os.path.join(work, "unstable.h"))
    check(rc == 1
          and err.startswith("%s: field control.hinf: the sampled loop is unstable" % machine.display_name(path))
          and "Traceback" not in err, "unstable.json: synth_hinf.py refuses it (%r)" % err.strip())
    check(not os.path.exists(os.path.join(work, "unstable.h")), "unstable.json: no header written")

    return result()


if __name__ == "__main__":
    sys.exit(main())
