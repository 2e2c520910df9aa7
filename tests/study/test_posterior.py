# SPDX-License-Identifier: Apache-2.0
"""The estimators' trace and posterior dump of br_mslip_plants (--pf-trace,
--posterior --at; sim/lib/circle/br_circle_pftrace.h; docs/presliding-plants.md,
"The posterior at a reversal"), on the demo's hardware-like plant (--hw):
one trace row per PF step and axis with the cloud's statistics in range; at
each requested time the truth, every particle of the PF and the UKF's mean and
sigma; the plot script draws the figure from it; bad --at lists and a
--posterior without --at are refused with exit 2 and no file.

Usage: test_posterior.py --bin BUILD/sim --work DIR"""
import csv
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import work_args  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLOT = os.path.join(ROOT, "sim", "plots", "plot_posterior.py")
AT = (1.9, 2.0, 2.3)


def main():
    a = work_args.parse("bin")
    tool = os.path.join(a.bin, "br_mslip_plants")
    fails = []

    def check(cond, what):
        if not cond:
            fails.append(what)

    post, trace = os.path.join(a.work, "post.csv"), os.path.join(a.work, "trace.csv")
    r = subprocess.run([tool, "--hw", "--posterior", post, "--at", ",".join(map(str, AT)), "--pf-trace", trace],
                       capture_output=True, text=True)
    check(r.returncode == 0, f"the run exits 0 (got {r.returncode}: {r.stderr})")
    rows = list(csv.DictReader(open(post)))
    kinds = {}
    for row in rows:
        kinds.setdefault(row["kind"], []).append(row)
    # the UKF's run and the PF's each give a truth row per time
    check(len(kinds.get("truth", [])) == 2 * len(AT), f"truth rows: {len(kinds.get('truth', []))}")
    check(len(kinds.get("ukf_mean", [])) == len(AT) and len(kinds.get("ukf_sd", [])) == len(AT), "UKF rows per time")
    pf = kinds.get("pf", [])
    check(len(pf) == 1500 * len(AT), f"every particle at every time: {len(pf)} rows")
    for t in AT:  # the first period at or after each time
        ts = sorted({float(p["t_s"]) for p in pf if float(p["t_s"]) >= t - 1e-9 and float(p["t_s"]) < t + 0.0015})
        check(len(ts) == 1, f"one PF dump at {t} s, got {ts}")
    gp = [float(p["gp_N"]) for p in pf]
    check(min(gp) > 0.0 and max(gp) < 100.0, f"g_p of the particles in a physical range: {min(gp)}..{max(gp)}")
    check(all(float(row["gp_N"]) >= 0.0 for row in kinds.get("ukf_sd", [])), "UKF sigma >= 0")
    tr = list(csv.DictReader(open(trace)))
    n_steps = round(8.0 / 0.0015) + 1
    check(len(tr) == 2 * n_steps, f"a trace row per PF step and axis: {len(tr)} against {2 * n_steps}")
    check(all(0.0 <= float(x["ess"]) <= 1500.0 for x in tr), "ESS in [0, m]")
    check(all(float(x["gate_counts"]) > 0.0 for x in tr), "the gate in counts > 0")
    png = os.path.join(a.work, "fig.png")
    r = subprocess.run([sys.executable, PLOT, post, png], capture_output=True, text=True)
    check(r.returncode == 0 and os.path.getsize(png) > 1000, f"the plot script draws the figure: {r.stderr}")
    for bad in (["--posterior", os.path.join(a.work, "x.csv")], ["--posterior", os.path.join(a.work, "x.csv"),
                "--at", "2,1"], ["--posterior", os.path.join(a.work, "x.csv"), "--at", "2,"]):
        r = subprocess.run([tool, "--hw"] + bad, capture_output=True, text=True)
        check(r.returncode == 2 and not os.path.exists(os.path.join(a.work, "x.csv")), f"refused: {bad}")
    for f in fails:
        print("FAIL:", f)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
