# SPDX-License-Identifier: Apache-2.0
"""Two robustness runs of the same plants compared plant by plant
(docs/robustness.md; docs/modules/est.md uses it for the compensation lead).

Both summary.json files must hold the same plants (the same --seed and --n:
each plant's seed is compared). For each controller in both: the paired
Wilcoxon test of B against A (robustness.py's, on log contour-RMS ratios),
how many plants B is better on, and the median ratio B / A on the plants
below and above a force noise of SPLIT_N per period.

Usage: robustness_pair.py A/summary.json B/summary.json [--json OUT]"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from robustness import completed, wilcoxon  # noqa: E402

# the force noise that splits the plants (N per period): about the median of
# robustness.py's draw, and where docs/robustness.md finds the PF / UKF order turning
SPLIT_N = 0.1


def load(path):
    with open(path) as f:
        s = json.load(f)
    return {p["i"]: p for p in s["plants"]}


def pair(a, b):
    """Per controller in both runs: the paired statistics of B against A."""
    if sorted(a) != sorted(b) or any(a[i]["seed"] != b[i]["seed"] for i in a):
        raise ValueError("the two runs do not hold the same plants (the same --seed and --n)")
    names = sorted(set.intersection(*[set(p["runs"]) for p in list(a.values()) + list(b.values())]))
    out = {}
    for k in names:
        # the pairs where both runs went to the end (a faulted run has no RMS, docs/tools.md)
        ids = [i for i in sorted(a) if completed(a[i]["runs"][k]) and completed(b[i]["runs"][k])]
        ra = np.array([a[i]["runs"][k]["contour_rms_m"] for i in ids])
        rb = np.array([b[i]["runs"][k]["contour_rms_m"] for i in ids])
        noise = np.array([a[i]["real"]["force_noise_N"] for i in ids])
        t = None if np.all(rb == ra) else wilcoxon(rb, ra)  # identical runs: no test to make
        ratio = rb / ra
        row = {"n": len(ids), "n_faulted": len(a) - len(ids), "b_better": int(np.sum(rb < ra)), "median_ratio_b_over_a": float(np.median(ratio)),
               "wilcoxon_p": t["p_value"] if t else None}
        for tag, sel in (("below", noise < SPLIT_N), ("above", noise >= SPLIT_N)):
            row[f"noise_{tag}_{SPLIT_N:g}N"] = {"n": int(sel.sum()),
                                                "median_ratio": float(np.median(ratio[sel])) if sel.any() else None}
        out[k] = row
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--json")
    args = ap.parse_args()
    try:
        res = pair(load(args.a), load(args.b))
    except (OSError, ValueError, KeyError) as e:
        print(f"robustness_pair: {e}", file=sys.stderr)
        return 1
    for k, r in res.items():
        lo, hi = r[f"noise_below_{SPLIT_N:g}N"], r[f"noise_above_{SPLIT_N:g}N"]
        p = "—" if r["wilcoxon_p"] is None else f"{r['wilcoxon_p']:.2g}"
        fmt = (lambda v: "—" if v is None else f"{v:.3f}")
        print(f"{k:14s} B better on {r['b_better']}/{r['n']}, median B/A {r['median_ratio_b_over_a']:.3f}, "
              f"Wilcoxon p {p}; force noise < {SPLIT_N:g} N: {lo['n']} plants {fmt(lo['median_ratio'])}, "
              f">= {SPLIT_N:g} N: {hi['n']} plants {fmt(hi['median_ratio'])}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
