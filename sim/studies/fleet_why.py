# SPDX-License-Identifier: Apache-2.0
"""Why the fleet's estimators stop (docs/fleet.md, "Why runs are lost"):
reads a fleet study's out folder (axes/<i>/truth.json, diagnose/machine.json
and each run's JSON) and splits every estimator run by the axis's properties,
printing a markdown table of faulted runs per class:

  the friction-transient displacement d = Fc h^2 / (2 Meff): how far a force
  error the size of Coulomb friction moves the axis in one estimator period
  h (the UKF at the control period, the PF at its own), by quartile;
  the moving mass, the period, the encoder, an actuator delay in periods,
  and whether the PF's g_p follows the Stribeck curve (gp_curve).

    python sim/studies/fleet_why.py out/fleet"""
import glob
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from runs import refused  # noqa: E402

CTRLS = ("hinf_ukf", "hinf_pf")


def load(path):
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def axis_props(ax):
    """the truth's properties a class is drawn on, or None for an axis the chain did not finish"""
    try:
        truth = load(os.path.join(ax, "truth.json"))
        mj = load(os.path.join(ax, "diagnose", "machine.json"))
    except (OSError, ValueError):
        return None
    mech, fr = truth["mechanics"], truth["friction"]
    L = mech["lead_m_per_rev"] / (2.0 * math.pi)
    delay = truth.get("causes", {}).get("actuator_delay", {}).get("delay_s", 0.0)
    return {"Meff_kg": mech["table_mass_kg"] + mech["inertia_kgm2"] / L ** 2, "Fc_N": fr["Fc_N"],
            "T_s": truth["control"]["period_s"], "T_pf_s": mj["estimator"]["pf"]["period_s"],
            "bits": int(round(math.log2(truth["encoder"]["counts_per_rev"]))),
            "delay_periods": delay / truth["control"]["period_s"],
            "gp_curve": "gp_curve" in mj["estimator"]["pf"]}


def runs(root):
    """one row per estimator run: its controller, its axis's properties and whether it faulted"""
    out = []
    for ax in sorted(glob.glob(os.path.join(root, "axes", "*"))):
        p = axis_props(ax)
        if p is None:
            continue
        for ctrl in CTRLS:
            for f in sorted(glob.glob(os.path.join(ax, "*_%s.json" % ctrl))):
                raw = load(f)
                r = raw.get("controllers", raw).get(ctrl)  # br_robust_run nests, br_track does not
                if r is None or refused(r):
                    continue  # not run: refused at init (fleet.py counts it apart)
                h = p["T_pf_s"] if ctrl == "hinf_pf" else p["T_s"]
                out.append(dict(p, ctrl=ctrl, faulted=bool(r.get("faulted")),
                                d_m=p["Fc_N"] * h * h / (2.0 * p["Meff_kg"])))
    return out


def split(rows, ctrl):
    rs = [r for r in rows if r["ctrl"] == ctrl]
    d = np.array([r["d_m"] for r in rs])
    f = np.array([r["faulted"] for r in rs])
    lines = []
    q = np.quantile(d, [0.0, 0.25, 0.5, 0.75, 1.0])
    for k, (a, b) in enumerate(zip(q[:-1], q[1:])):
        sel = (d >= a) & ((d < b) if k < 3 else (d <= b))
        lines.append(("Fc h²/(2 Meff) in %.2g … %.2g m" % (a, b), int(f[sel].sum()), int(sel.sum())))
    for name, test in (("Meff < 5 kg", lambda r: r["Meff_kg"] < 5.0), ("Meff ≥ 5 kg", lambda r: r["Meff_kg"] >= 5.0),
                       ("period < 0.5 ms", lambda r: r["T_s"] < 5e-4), ("period ≥ 0.5 ms", lambda r: r["T_s"] >= 5e-4),
                       ("encoder ≥ 2^22", lambda r: r["bits"] >= 22), ("encoder < 2^22", lambda r: r["bits"] < 22),
                       ("delay ≥ 4 periods", lambda r: r["delay_periods"] >= 4.0),
                       ("delay < 4 periods", lambda r: r["delay_periods"] < 4.0)):
        sel = [r for r in rs if test(r)]
        lines.append((name, sum(r["faulted"] for r in sel), len(sel)))
    if ctrl == "hinf_pf":
        for name, on in (("gp_curve on", True), ("gp_curve off", False)):
            sel = [r for r in rs if r["gp_curve"] == on]
            lines.append((name, sum(r["faulted"] for r in sel), len(sel)))
    return lines


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: fleet_why.py OUT_DIR (a fleet study's out folder)")
    rows = runs(sys.argv[1])
    if not rows:
        sys.exit("fleet_why.py: %s: no estimator runs" % sys.argv[1])
    for ctrl in CTRLS:
        print("\n%s: faulted runs by class\n\n| class | faulted | runs | share |\n|---|---|---|---|" % ctrl)
        for name, nf, n in split(rows, ctrl):
            print("| %s | %d | %d | %s |" % (name, nf, n, "%.0f %%" % (100.0 * nf / n) if n else "—"))


if __name__ == "__main__":
    main()
