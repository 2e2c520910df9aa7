#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The estimators' settings in physical units (docs/machine-file.md,
"Estimator settings in physical units"; firmware/design/machine.py
est_per_step):

- each per-step value the firmware receives follows the machine as physics
  says, computed here from the equations with the file's numbers: an
  encoder with 8x the counts gives 64x the count variances beyond the
  quantisation's 1/12; twice the friction gives twice the g_p levels and 4x
  their variances; the omega noise of a white table force scales with
  L^2 / Jeff^2; the UKF's theta noise is theta_m2_per_s T / L^2;
- est_physical is est_per_step's inverse;
- upgrade_machine.py turns a format-1 file into a format-2 file that gives
  every per-step value's float32 back, and refuses a broken file with its
  name, writing nothing.

Usage: test_est_units.py --work DIR"""
import argparse
import copy
import json
import math
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import DESIGN, check, result  # noqa: E402
import machine  # noqa: E402
import upgrade_machine  # noqa: E402


def close(a, b, rel=1e-12):
    return abs(a - b) <= rel * max(abs(a), abs(b))


def loaded(raw, work, name):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        json.dump(raw, f, indent=2)
    return machine.load(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", required=True)
    work = ap.parse_args().work
    os.makedirs(work, exist_ok=True)
    with open(machine.REFERENCE_MACHINE) as f:
        good = json.load(f)
    ref = machine.load(machine.REFERENCE_MACHINE)
    P, U = machine.est_per_step(ref, "pf"), machine.est_per_step(ref, "ukf")

    # the equations, with the file's numbers
    lead, M, J = good["mechanics"]["lead_m_per_rev"], good["mechanics"]["table_mass_kg"], good["mechanics"]["inertia_kgm2"]
    L = lead / (2.0 * math.pi)
    cpr = good["encoder"]["counts_per_rev"]
    m_per_count = lead / cpr
    Tu, Tp = good["control"]["period_s"], good["estimator"]["pf"]["period_s"]
    eu, ep = good["estimator"]["ukf"], good["estimator"]["pf"]
    check(close(U["q_theta_rad2"], eu["process_noise"]["theta_m2_per_s"] * Tu / L ** 2),
          "UKF q_theta = theta_m2_per_s T / L^2")
    check(close(P["q_theta_counts2"], ep["process_noise"]["theta_m2_per_s"] * Tp / m_per_count ** 2),
          "PF q_theta in counts^2 = theta_m2_per_s T / (lead / counts_per_rev)^2")
    check(close(P["r_counts2"], 1.0 / 12.0 + ep["position_noise_m2"] / m_per_count ** 2),
          "R = 1/12 count^2 + position_noise_m2 in counts^2")
    Fs, Fc = good["friction"]["Fs_N"], good["friction"]["Fc_N"]
    Jeff = J + M * L ** 2
    check(close(U["q_omega_rad2ps2"], eu["process_noise"]["force_Fs2_s"] * Fs ** 2 * Tu * (L / Jeff) ** 2),
          "q_omega of a white table force: S Fs^2 T L^2 / Jeff^2")
    check(close(P["gp_min_N"], ep["gp_min_Fc"] * Fc) and close(P["gp_max_N"], ep["gp_max_Fs"] * Fs),
          "g_p range from Fc and Fs")

    # invariance: the same file on other machines
    fine = copy.deepcopy(good)
    fine["encoder"]["counts_per_rev"] = 8 * cpr
    m8 = loaded(fine, work, "enc8.json")
    Pf, Uf = machine.est_per_step(m8, "pf"), machine.est_per_step(m8, "ukf")
    check(close(Pf["q_theta_counts2"], 64.0 * P["q_theta_counts2"]), "8x the counts: 64x theta's noise in counts^2")
    check(close(Pf["r_counts2"] - 1.0 / 12.0, 64.0 * (P["r_counts2"] - 1.0 / 12.0)),
          "8x the counts: R beyond the quantisation 64x in counts^2")
    check(close(Uf["p0_theta_counts2"] - 1.0 / 12.0, 64.0 * (U["p0_theta_counts2"] - 1.0 / 12.0)),
          "8x the counts: P0 of theta beyond the quantisation 64x")
    check(close(Uf["q_theta_rad2"], U["q_theta_rad2"]) and close(Pf["q_omega_rad2ps2"], P["q_omega_rad2ps2"]),
          "8x the counts: noise in rad unchanged")
    strong = copy.deepcopy(good)
    strong["friction"]["Fs_N"], strong["friction"]["Fc_N"] = 2.0 * Fs, 2.0 * Fc
    Ps = machine.est_per_step(loaded(strong, work, "fr2.json"), "pf")
    check(all(close(Ps[k], 2.0 * P[k]) for k in ("gp0_N", "gp_min_N", "gp_max_N", "x0_gp_N", "x0_z_m")),
          "2x the friction: 2x the g_p levels and spreads, and z's (zs = Fs / sigma0)")
    check(all(close(Ps[k], 4.0 * P[k]) for k in ("q_gp_N2", "q_omega_rad2ps2", "q_z_m2", "dlyid_q_force_N2ps")),
          "2x the friction: 4x the force-like variances")
    heavy = copy.deepcopy(good)
    heavy["mechanics"]["table_mass_kg"] = 4.0 * M
    Ph = machine.est_per_step(loaded(heavy, work, "mass4.json"), "pf")
    Jh = J + 4.0 * M * L ** 2
    check(close(Ph["q_omega_rad2ps2"], P["q_omega_rad2ps2"] * (Jeff / Jh) ** 2),
          "4x the mass: omega's noise by (Jeff / Jeff')^2")
    slow = copy.deepcopy(good)
    slow["estimator"]["pf"]["period_s"] = 2.0 * Tp
    Pt = machine.est_per_step(loaded(slow, work, "period2.json"), "pf")
    check(all(close(Pt[k], 2.0 * P[k]) for k in ("q_theta_counts2", "q_omega_rad2ps2", "q_z_m2", "q_gp_N2",
                                                  "adapt_alpha")),
          "twice the period: twice every variance per step (per-second noise), twice the NIS smoothing")
    check(close(Pt["r_counts2"], P["r_counts2"]), "twice the period: R unchanged")

    # R's floor from the friction transient over a period (docs/fleet.md, "Holding on the
    # fleet's axes"): d = Fc T^2 / (2 Meff) beyond the bristles' zone zs = Fs / sigma0
    Meff = Jeff / L ** 2
    for est, T in (("pf", Tp), ("ukf", Tu)):
        check(Fc * T ** 2 / (2.0 * Meff) < Fs / good["friction"]["sigma0_Npm"],
              "the reference's %s: the transient over a period within the bristles' zone (no floor)" % est)
    stiff = copy.deepcopy(good)
    stiff["friction"]["sigma0_Npm"] *= 100.0
    Pk = machine.est_per_step(loaded(stiff, work, "stiff.json"), "pf")
    d, zs = Fc * Tp ** 2 / (2.0 * Meff), Fs / stiff["friction"]["sigma0_Npm"]
    floor = ((d - zs) / 8.0) ** 2
    check(floor > ep["position_noise_m2"] and close(Pk["r_counts2"], 1.0 / 12.0 + floor / m_per_count ** 2),
          "100x the bristle stiffness: R = 1/12 + ((d - zs) / 8)^2 in counts^2, above the file's")
    rough = copy.deepcopy(stiff)
    rough["friction"]["Fs_N"] = rough["friction"]["Fc_N"] = 10.0 * Fs
    rough["estimator"]["pf"]["period_s"] = 10.0 * Tp
    check(machine.est_per_step(rough, "pf")["r_counts2"] == machine.R_COUNTS2_MAX,
          "a floor beyond the firmware's bound on R: R at the bound")

    # the outlier gate's transient term (docs/modules/pf.md, "The gate", eq. G1):
    # d = k (Fs - Fc) T^2 / (2 Meff) in m, / L in the firmware's rad; absent = 0
    g0 = copy.deepcopy(good)
    for est in ("pf", "ukf"):
        g0["estimator"][est].pop("outlier_transient_k", None)
    m0 = loaded(g0, work, "gate_0.json")
    check(all(machine.gate_transient_rad(m0, est) == 0.0 for est in ("pf", "ukf")),
          "no outlier_transient_k: no transient term (the thesis gate)")
    gk = copy.deepcopy(good)
    gk["estimator"]["pf"]["outlier_transient_k"] = 1.0
    gk["estimator"]["ukf"]["outlier_transient_k"] = 1.0 / 3.0
    mk = loaded(gk, work, "gate_k.json")
    check(close(machine.gate_transient_rad(mk, "pf"), (Fs - Fc) * Tp ** 2 / (2.0 * Meff) / L),
          "k = 1: the PF's transient term (Fs - Fc) T^2 / (2 Meff) / L rad")
    check(close(machine.gate_transient_rad(mk, "ukf"), (Fs - Fc) * Tu ** 2 / (6.0 * Meff) / L),
          "k = 1/3 at the UKF's period: (Fs - Fc) T^2 / (6 Meff) / L rad")
    gk8 = copy.deepcopy(gk)
    gk8["encoder"]["counts_per_rev"] = 8 * cpr
    check(close(machine.gate_transient_rad(loaded(gk8, work, "gate_k8.json"), "pf"),
                machine.gate_transient_rad(mk, "pf")),
          "8x the counts: the transient term in rad unchanged (8x in counts)")
    gk2 = copy.deepcopy(gk)
    gk2["estimator"]["pf"]["period_s"] = 2.0 * Tp
    check(close(machine.gate_transient_rad(loaded(gk2, work, "gate_t2.json"), "pf"),
                4.0 * machine.gate_transient_rad(mk, "pf")),
          "twice the period: four times the transient term")
    for bad in (-0.1, machine.GATE_TRANSIENT_K_MAX * 1.01):
        gb = copy.deepcopy(good)
        gb["estimator"]["pf"]["outlier_transient_k"] = bad
        try:
            loaded(gb, work, "gate_bad.json")
            refused = False
        except machine.MachineError as e:
            refused = "estimator.pf.outlier_transient_k" in str(e)
        check(refused, "outlier_transient_k %g refused, named" % bad)

    # est_physical inverts est_per_step
    for est, vals in (("pf", P), ("ukf", U)):
        phys = machine.est_physical(ref, est, vals)
        ok = True
        for field, v in phys.items():
            node = good["estimator"][est]
            for k in field.split("."):
                node = node[k]
            ok = ok and close(v, node, 1e-9)
        check(ok, "est_physical(est_per_step()) gives %s's fields back" % est)

    # format 1 -> format 2: every per-step float32 back
    v1 = copy.deepcopy(good)
    v1["format_version"] = 1
    for est, vals in (("pf", P), ("ukf", U)):
        e = v1["estimator"][est]
        for sec in ("process_noise", "x0_std", "p0_var"):
            e.pop(sec, None)
        for f in ("position_noise_m2", "gp0_Fs", "gp_min_Fc", "gp_max_Fs"):
            e.pop(f)
        e["delay_id"].pop("q_force_Fs2_per_s")
        if est == "pf":
            e["adapt"].pop("tau_s")
        for old, key in {**upgrade_machine.V1_FIELDS[est], **upgrade_machine.V1_FIELDS["both"]}.items():
            node = e
            ks = old.split(".")
            for k in ks[:-1]:
                node = node.setdefault(k, {})
            node[ks[-1]] = vals[key]
    old_path, new_path = os.path.join(work, "v1.json"), os.path.join(work, "v2.json")
    with open(old_path, "w") as f:
        json.dump(v1, f)
    r = subprocess.run([sys.executable, os.path.join(DESIGN, "upgrade_machine.py"), old_path, new_path],
                       capture_output=True, text=True)
    check(r.returncode == 0, "upgrade_machine.py converts a format-1 file (%s)" % r.stderr.strip())
    if r.returncode == 0:
        up = machine.load(new_path)
        for est, vals in (("pf", P), ("ukf", U)):
            back = machine.est_per_step(up, est)
            same = [k for k in vals if np.float32(back[k]) == np.float32(vals[k])]
            check(len(same) == len(vals), "format 1 -> 2: %s's %d per-step values the same float32 (%s differ)"
                  % (est, len(vals), sorted(set(vals) - set(same))))
    broken = copy.deepcopy(v1)
    del broken["estimator"]["pf"]["r_var_counts2"]
    with open(old_path, "w") as f:
        json.dump(broken, f)
    os.remove(new_path) if os.path.exists(new_path) else None
    r = subprocess.run([sys.executable, os.path.join(DESIGN, "upgrade_machine.py"), old_path, new_path],
                       capture_output=True, text=True)
    check(r.returncode != 0 and old_path in r.stderr and "field estimator.pf.r_var_counts2: missing" in r.stderr
          and "Traceback" not in r.stderr and not os.path.exists(new_path),
          "upgrade_machine.py: a broken file is named, nothing written (%r)" % r.stderr.strip())

    return result()


if __name__ == "__main__":
    sys.exit(main())
