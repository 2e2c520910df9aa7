# SPDX-License-Identifier: Apache-2.0
"""PF variants on the robustness set (docs/robustness.md, "PF variants"): the
PF re-run on the first K plants of a robustness study with a configuration
change that needs no change inside the filter (a shorter period, more
particles), each plant with its drift and noise; paired Wilcoxon signed-rank
against the baseline PF (1.5 ms, 1500 particles) and the UKF of the study.

Usage: pf_variants.py --bin BUILD/sim --study out/robustness [--k 40] [--jobs J] [--md OUT.md] [--variants 0,1,2]
"""
import argparse
import json
import os
import subprocess
import sys
from multiprocessing import Pool

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from robustness import completed, lost, wilcoxon  # noqa: E402

VARIANTS = (("1 ms, 1500 particles", ["--pf-dt", "0.001"]),
            ("1.5 ms, 2048 particles", ["--pf-n", "2048"]),
            ("1 ms, 2048 particles", ["--pf-dt", "0.001", "--pf-n", "2048"]))


def one(job):
    binp, study, p, opts, tag = job
    r = p["real"]
    d = os.path.join(study, "plants", f"{p['i']:04d}")
    cmd = [os.path.join(binp, "br_robust_run"), "--plant", os.path.join(d, "plant.json"), "--drift",
           f"{r['drift']:.6g}", "--force-noise", f"{r['force_noise_N']:.6g}", "--enc-noise", f"{r['enc_noise_p']:.6g}",
           "--seed", str(p["seed"]), "--only", "hinf_pf", *opts, "--json", os.path.join(d, f"pf_variant_{tag}.json")]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        return p["i"], {"error": out.stderr}
    with open(os.path.join(d, f"pf_variant_{tag}.json")) as f:
        return p["i"], json.load(f)["controllers"]["hinf_pf"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--study", required=True)
    ap.add_argument("--k", type=int, default=40)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--md")
    ap.add_argument("--variants", default="0,1,2", help="which of VARIANTS (indices)")
    a = ap.parse_args()
    pick = [int(v) for v in a.variants.split(",")]
    with open(os.path.join(a.study, "summary.json")) as f:
        plants = json.load(f)["plants"][:a.k]
    L = ["| PF variant | plants | median contour RMS | p90 | lost | vs baseline PF: median ratio, better, p | "
         "vs UKF: median ratio, better, p |", "|---|---|---|---|---|---|---|"]
    # the plants where the baseline PF, the UKF and H-inf only went to the end: a faulted run has no
    # RMS to pair (docs/tools.md); the others are counted as lost below
    plants = [p for p in plants if all(completed(p["runs"][k]) for k in ("hinf_only", "hinf_pf", "hinf_ukf"))]
    base = [p["runs"]["hinf_pf"]["contour_rms_m"] for p in plants]
    ukf = [p["runs"]["hinf_ukf"]["contour_rms_m"] for p in plants]
    import numpy as np

    def row(name, vals, n_lost, vs_base):
        v = np.array(vals)
        t2 = wilcoxon(vals, ukf)
        c1 = "—" if vs_base is None else f"{vs_base['median_ratio']:.3f}, {vs_base['first_better']}/{vs_base['n']}, " \
            f"{vs_base['p_value']:.2g}"
        return (f"| {name} | {len(v)} | {np.median(v):.3e} m | {np.percentile(v, 90):.3e} m | {n_lost} | {c1} | "
                f"{t2['median_ratio']:.3f}, {t2['first_better']}/{t2['n']}, {t2['p_value']:.2g} |")
    L.append(row("baseline: 1.5 ms, 1500 particles (the study's)", base,
                 sum(1 for p in plants if lost(p["runs"]["hinf_pf"], p["runs"]["hinf_only"]["contour_rms_m"])), None))
    res = {}
    with Pool(a.jobs) as pool:
        for tag, (name, opts) in enumerate(VARIANTS):
            if tag not in pick:
                continue
            got = dict(pool.map(one, [(a.bin, a.study, p, opts, tag) for p in plants]))
            bad = [i for i, g in got.items() if "error" in g]
            if bad:
                print(f"{name}: failed on plants {bad}", file=sys.stderr)
                return 1
            # a faulted variant run: no RMS, its worst case stands in for the paired test and it counts as lost
            vals = [got[p["i"]]["contour_rms_m"] if completed(got[p["i"]]) else float("inf") for p in plants]
            nl = sum(1 for p in plants if lost(got[p["i"]], p["runs"]["hinf_only"]["contour_rms_m"]))
            L.append(row(name, vals, nl, wilcoxon(vals, base)))
            res[name] = got
            print(L[-1], flush=True)
    print("\n".join(L))
    if a.md:
        with open(a.md, "w") as f:
            f.write("\n".join(L) + "\n")
    with open(os.path.join(a.study, "pf_variants.json"), "w") as f:
        json.dump(res, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
