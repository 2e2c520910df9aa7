# SPDX-License-Identifier: Apache-2.0
"""The H-inf weights from the machine (firmware/design/hinf_weights.py) on
machines/ and on fleet axes (docs/modules/hinf.md, "Weights from the
machine"): whether the file's own weights hold, the rule's loop frequency and
what bounds it, how far a stiction step moves the axis against its
following-error limit, the sampled loop's spectral radius, phase and upper
gain margins at each period; then how many of the fleet's axes each bound
holds. The fleet's axes with the given file's friction (the reference's,
assumed), or with --friction truth their drawn friction (what the diagnosis
identifies, and so what machine.json's weights are derived for).

Usage: hinf_rule_table.py [--seed S] [--axes 25,55,...] [--n 200] [--friction given|truth]"""
import argparse
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fleet_axis  # noqa: E402  (puts firmware/design on the path)
import hinf_weights  # noqa: E402
import loop_analysis  # noqa: E402
import machine  # noqa: E402
import synth_hinf  # noqa: E402


def row(name, m):
    why = hinf_weights.refusal(m)
    hinf, info = hinf_weights.suggest(m)
    mm = hinf_weights.with_hinf(m, hinf)
    p, w = machine.params(mm), synth_hinf.weights(mm)
    d = synth_hinf.design(p, w)
    A, B2 = synth_hinf.plant(p)
    res = loop_analysis.analyse(A, B2, d["K"], w["check_dt_s"])
    s = [res[k] for k in w["check_dt_s"]]
    hz = 1.0 / (2.0 * math.pi)
    step = "%.3g / %.3g mm" % (info["friction_step_m"] * 1e3, info["following_m"] * 1e3)
    if hinf_weights.friction_shortfall(info):
        step += " (beyond: needs %.1f Hz, %.3g of Nyquist)" % (
            info["omega_friction_rad_s"] * hz, info["omega_friction_rad_s"] / info["nyquist_rad_s"])
    return "| %s | %s | %.3g / %.3g ms | %.2f Hz (%s) | %s | %s | %s | %s |" % (
        name, "refused: %s" % why if why else "holds", w["check_dt_s"][0] * 1e3, w["check_dt_s"][-1] * 1e3,
        info["omega0_rad_s"] * hz, info["bound"], step, " / ".join("%.4f" % c[1] for c in d["checks"]),
        " / ".join("%.1f°" % r["pm_deg"] for r in s), " / ".join("%.1f" % r["gm_up"] for r in s))


def fleet_file(seed, i, friction):
    ax = fleet_axis.draw(seed, i)
    g = fleet_axis.given_file(ax, "fleet-%04d" % i)
    return g if friction == "given" else fleet_axis.truth_file(ax, g)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=20261201)
    ap.add_argument("--axes", default="25,55,124,128,136,137,184,176")
    ap.add_argument("--n", type=int, default=200, help="the fleet's axes counted by what bounds w0")
    ap.add_argument("--friction", choices=("given", "truth"), default="given",
                    help="the fleet's axes with the given file's friction or their drawn one")
    a = ap.parse_args()
    print("| machine | its own weights | periods | w0 (bound) | stiction step / following limit | "
          "sampled spectral radius | phase margin | gain margin up |\n|---|---|---|---|---|---|---|---|")
    folder = os.path.join(fleet_axis.REPO, "machines")
    for f in sorted(os.listdir(folder)):
        if f.endswith(".json"):
            print(row("machines/" + f, machine.load(os.path.join(folder, f))))
    for i in (int(x) for x in a.axes.split(",") if x):
        print(row("fleet axis %d" % i, fleet_file(a.seed, i, a.friction)))
    bounds, short = {}, []
    for i in range(a.n):
        info = hinf_weights.suggest(fleet_file(a.seed, i, a.friction))[1]
        bounds.setdefault(info["bound"], []).append(i)
        if hinf_weights.friction_shortfall(info):
            short.append(i)
    for b, axes in sorted(bounds.items()):
        print("\nthe %s bounds w0 on %d of %d axes%s" % (b, len(axes), a.n, "" if b == "period" else
                                                        ": " + ", ".join(map(str, axes))))
    print("\nthe stiction step beyond the following limit at the raised w0: %d of %d axes: %s"
          % (len(short), a.n, ", ".join(map(str, short)) or "none"))


if __name__ == "__main__":
    main()
