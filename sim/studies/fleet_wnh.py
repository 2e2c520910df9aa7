# SPDX-License-Identifier: Apache-2.0
"""The fleet's estimator faults by the presliding mode's period ratio
(docs/fleet.md, "Holding on the fleet's axes"): for every run of the page's
200-axis table (its "Lost runs" list, docs/fleet.md, and the axes drawn
again with fleet_axis.draw), the faulted share of the PF's and the UKF's
runs by wn h = h sqrt(sigma0 / Meff) (the bristles' presliding mode against
the estimator's period h) and by d = Fc h^2 / (2 Meff). A fault is any
cause but worse_than_hinf_only and persistent_outliers.

    python sim/studies/fleet_wnh.py docs/fleet.md"""
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fleet_axis  # noqa: E402

SEED, N = 20261201, 200
TRAJ = ("thesis_circle", "circle0", "circle1", "p2p", "emps")
NOT_FAULT = ("ok", "worse_than_hinf_only", "persistent_outliers")
WNH_EDGES = (0.0, 0.5, 1.0, 2.0, 2.8, 1e9)
D_EDGES = (0.0, 1e-7, 1e-6, 1.0)


def rows(page):
    txt = open(page, encoding="utf-8").read().split("<!-- fleet:begin -->")[1]
    failed = {int(m) for m in re.findall(r"^- axis (\d+), ", txt, re.M)}
    lost = {}
    for ctl, ax, tr, cause in re.findall(r"^- (hinf_\w+): axis (\d+), (\w+), (\w+)", txt, re.M):
        lost.setdefault((ctl, int(ax)), {})[tr] = cause
    out = []
    for i in range(N):
        if i in failed:
            continue
        a = fleet_axis.draw(SEED, i)
        f, M = a["friction"], a["Meff_kg"]
        for ctl, h in (("hinf_pf", fleet_axis.PF_PERIOD_RATIO * a["period_s"]), ("hinf_ukf", a["period_s"])):
            for tr in TRAJ:
                c = lost.get((ctl, i), {}).get(tr, "ok")
                out.append((ctl, h * math.sqrt(f["sigma0_Npm"] / M), f["Fc_N"] * h * h / (2.0 * M),
                            c not in NOT_FAULT))
    return out


def main(page):
    R = rows(page)
    print("| estimator | class | faulted | runs | share |\n|---|---|---|---|---|")
    for ctl in ("hinf_pf", "hinf_ukf"):
        for name, k, edges in (("wn h", 1, WNH_EDGES), ("d (m)", 2, D_EDGES)):
            for lo, hi in zip(edges[:-1], edges[1:]):
                S = [r for r in R if r[0] == ctl and lo <= r[k] < hi]
                if S:
                    nf = sum(r[3] for r in S)
                    print("| %s | %s in [%g, %g) | %d | %d | %.0f %% |" % (ctl[5:].upper(), name, lo, hi, nf, len(S),
                                                                        100.0 * nf / len(S)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "docs/fleet.md"))
