# SPDX-License-Identifier: Apache-2.0
"""sim/studies/robustness_pair.py on two made-up runs of the same plants whose
answer is known: B halves one controller's error on the quiet plants and
doubles it on the noisy ones, leaves another unchanged; runs of other plants
are refused with exit 1 and a message, never a comparison.
Usage: test_robustness_pair.py WORK"""
import copy
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "..", "sim", "studies", "robustness_pair.py")
sys.path.insert(0, os.path.dirname(SCRIPT))
from robustness_pair import SPLIT_N  # noqa: E402


def run_of(n_quiet, n_noisy):
    plants = []
    for i in range(n_quiet + n_noisy):
        noise = 0.5 * SPLIT_N if i < n_quiet else 2.0 * SPLIT_N
        plants.append({"i": i, "seed": 1000 + i, "real": {"force_noise_N": noise},
                       "runs": {"hinf_only": {"contour_rms_m": 2.0e-6 + 1e-8 * i},
                                "hinf_ukf": {"contour_rms_m": 4.0e-8 + 1e-9 * i}}})
    return {"plants": plants}


def main():
    work = sys.argv[1]
    os.makedirs(work, exist_ok=True)
    a = run_of(7, 5)
    b = copy.deepcopy(a)
    for p in b["plants"]:
        p["runs"]["hinf_ukf"]["contour_rms_m"] *= 0.5 if p["real"]["force_noise_N"] < SPLIT_N else 2.0
    pa, pb, out = (os.path.join(work, n) for n in ("a.json", "b.json", "pair.json"))
    for path, obj in ((pa, a), (pb, b)):
        with open(path, "w") as f:
            json.dump(obj, f)
    r = subprocess.run([sys.executable, SCRIPT, pa, pb, "--json", out], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with open(out) as f:
        res = json.load(f)
    u, h = res["hinf_ukf"], res["hinf_only"]
    lo, hi = u[f"noise_below_{SPLIT_N:g}N"], u[f"noise_above_{SPLIT_N:g}N"]
    assert (u["n"], u["b_better"]) == (12, 7), u
    assert (lo["n"], lo["median_ratio"], hi["n"], hi["median_ratio"]) == (7, 0.5, 5, 2.0), u
    assert abs(u["median_ratio_b_over_a"] - 0.5) < 1e-12, u  # 7 of 12 at 0.5
    assert u["wilcoxon_p"] is not None and 0.0 < u["wilcoxon_p"] < 1.0, u
    assert h["b_better"] == 0 and h["median_ratio_b_over_a"] == 1.0 and h["wilcoxon_p"] is None, h
    # other plants: refused
    c = copy.deepcopy(b)
    c["plants"][3]["seed"] += 1
    with open(pb, "w") as f:
        json.dump(c, f)
    r = subprocess.run([sys.executable, SCRIPT, pa, pb], capture_output=True, text=True)
    assert r.returncode == 1 and "same plants" in r.stderr and "Traceback" not in r.stderr, (r.returncode, r.stderr)
    print("robustness_pair: known halving/doubling recovered; other plants refused")


if __name__ == "__main__":
    main()
