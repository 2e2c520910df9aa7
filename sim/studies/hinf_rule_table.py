# SPDX-License-Identifier: Apache-2.0
"""The H-inf weights from the machine (firmware/design/hinf_weights.py) on
machines/ and on fleet axes (docs/modules/hinf.md, "Weights from the
machine"): whether the file's own weights hold, the rule's loop frequency and
what bounds it, the sampled loop's spectral radius, phase and upper gain
margins at each period; then how many of the fleet's axes the encoder bounds.

Usage: hinf_rule_table.py [--seed S] [--axes 25,55,...] [--n 200]"""
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
    return "| %s | %s | %.3g / %.3g ms | %.2f Hz (%s) | %s | %s | %s |" % (
        name, "refused: %s" % why if why else "holds", w["check_dt_s"][0] * 1e3, w["check_dt_s"][-1] * 1e3,
        info["omega0_rad_s"] / (2.0 * math.pi), info["bound"], " / ".join("%.4f" % c[1] for c in d["checks"]),
        " / ".join("%.1f°" % r["pm_deg"] for r in s), " / ".join("%.1f" % r["gm_up"] for r in s))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seed", type=int, default=20261201)
    ap.add_argument("--axes", default="25,55,124,128,136,137,184,176")
    ap.add_argument("--n", type=int, default=200, help="the fleet's axes counted for the encoder bound")
    a = ap.parse_args()
    print("| machine | its own weights | periods | w0 (bound) | sampled spectral radius | phase margin | "
          "gain margin up |\n|---|---|---|---|---|---|---|")
    folder = os.path.join(fleet_axis.REPO, "machines")
    for f in sorted(os.listdir(folder)):
        if f.endswith(".json"):
            print(row("machines/" + f, machine.load(os.path.join(folder, f))))
    for i in (int(x) for x in a.axes.split(",") if x):
        print(row("fleet axis %d" % i, fleet_axis.given_file(fleet_axis.draw(a.seed, i), "fleet-%04d" % i)))
    bound = [i for i in range(a.n) if hinf_weights.suggest(
        fleet_axis.given_file(fleet_axis.draw(a.seed, i), "fleet-%04d" % i))[1]["bound"] == "encoder"]
    print("\nthe encoder bounds w0 on %d of %d axes: %s" % (len(bound), a.n, ", ".join(map(str, bound))))


if __name__ == "__main__":
    main()
