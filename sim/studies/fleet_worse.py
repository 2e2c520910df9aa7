# SPDX-License-Identifier: Apache-2.0
"""Why the fleet's estimator runs end worse than H-inf only (docs/fleet.md,
"Why runs end worse than H-inf only"): reads a fleet study's out folder and
prints markdown tables of the UKF's and the PF's lost runs (faulted, or
ended worse than H-inf only on the same trajectory):

  by how much worse (a tracking RMS 0.3 % above H-inf only's is a loss as
  much as one ten times it: the tables say which);
  with --oracle DIR (fleet_rerun.py --machine truth --tracks: the same
  runs with the tools built for the axis's truth.json, its own friction and
  delay): how many of the study's losses the diagnosis's model made (gone
  with the truth's) and how many are the estimator's (they stay);
  by the machine file's Stribeck ratio Fs/Fc over the truth's.

    python sim/studies/fleet_worse.py out/fleet [--oracle OUT]"""
import argparse
import glob
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fleet_runs import tool_record  # noqa: E402
from runs import refused  # noqa: E402

CTRLS = ("hinf_ukf", "hinf_pf")
NAMES = ("thesis_circle", "circle0", "circle1", "p2p", "emps")
BANDS = ((1.0, 1.01, "up to 1 % worse"), (1.01, 1.1, "1-10 % worse"), (1.1, 2.0, "10-100 % worse"),
         (2.0, float("inf"), "over twice"))


def run(d, name, ctrl):
    """one run's figure from its JSON in d: its RMS, "faulted", or None (not run, or refused at
    init: fleet.py counts those apart, neither lost nor a figure)"""
    path = os.path.join(d, "%s_%s.json" % (name, ctrl))
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as f:
        js = json.load(f)
    r = tool_record(js, ctrl)
    if refused(r):
        return None
    return "faulted" if r["faulted"] else r["rms_m"]


def verdicts(d):
    """{(name, ctrl): "faulted" | ratio to H-inf only} of the runs in d whose H-inf only went to the end"""
    out = {}
    for name in NAMES:
        h = run(d, name, "hinf_only")
        if h is None or h == "faulted":
            continue
        for ctrl in CTRLS:
            e = run(d, name, ctrl)
            if e is not None:
                out[(name, ctrl)] = e if e == "faulted" else e / h
    return out


def lost(v):
    return v == "faulted" or v > 1.0


def stribeck_ratio(ax):
    """the machine file's Fs/Fc over the truth's"""
    with open(os.path.join(ax, "truth.json"), encoding="utf-8") as f:
        t = json.load(f)["friction"]
    with open(os.path.join(ax, "diagnose", "machine.json"), encoding="utf-8") as f:
        m = json.load(f)["friction"]
    return (m["Fs_N"] / m["Fc_N"]) / (t["Fs_N"] / t["Fc_N"])


def table(title, head, rows):
    print("\n%s\n\n| %s |\n|%s" % (title, " | ".join(head), "---|" * len(head)))
    for r in rows:
        print("| " + " | ".join(str(x) for x in r) + " |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", help="a fleet study's out folder")
    ap.add_argument("--oracle", help="fleet_rerun.py --machine truth --tracks's out folder for the same axes")
    a = ap.parse_args()
    axes = sorted(p for p in glob.glob(os.path.join(a.study, "axes", "*"))
                  if os.path.exists(os.path.join(p, "diagnose", "machine.json")))
    if not axes:
        sys.exit("fleet_worse.py: %s: no axis with a machine.json" % a.study)
    recs = []  # (axis, name, ctrl, the study's verdict, the oracle's or None, Fs/Fc ratio)
    for ax in axes:
        i = os.path.basename(ax)
        orc = verdicts(os.path.join(a.oracle, i)) if a.oracle else {}
        sr = stribeck_ratio(ax)
        for key, v in verdicts(ax).items():
            recs.append((i,) + key + (v, orc.get(key), sr))
    rows = []
    for ctrl in CTRLS:
        for kinds, label in ((("thesis_circle", "circle0", "circle1"), "circles"), (("p2p", "emps"), "tracks")):
            rs = [r for r in recs if r[2] == ctrl and r[1] in kinds]
            nf = sum(1 for r in rs if r[3] == "faulted")
            band = [sum(1 for r in rs if r[3] != "faulted" and lo < r[3] <= hi) for lo, hi, _ in BANDS]
            rows.append([ctrl, label, len(rs), nf] + band)
    table("Lost runs by how much worse than H-inf only (%d axes)" % len(axes),
          ["estimator", "trajectories", "runs", "faulted"] + [b[2] for b in BANDS], rows)
    if a.oracle:
        rows = []
        for ctrl in CTRLS:
            rs = [r for r in recs if r[2] == ctrl and r[4] is not None]
            was = [r for r in rs if lost(r[3])]
            rows.append([ctrl, len(rs), len(was), sum(1 for r in was if not lost(r[4])),
                         sum(1 for r in was if lost(r[4])), sum(1 for r in rs if not lost(r[3]) and lost(r[4])),
                         sum(1 for r in rs if lost(r[4]))])
        table("With the truth's machine file (--oracle %s)" % a.oracle,
              ["estimator", "runs", "lost with machine.json", "of these not lost with truth.json",
               "lost with both", "lost only with truth.json", "lost with truth.json"], rows)
    rows = []
    for lo, hi in ((0.0, 1.5), (1.5, 3.0), (3.0, 10.0), (10.0, float("inf"))):
        for ctrl in CTRLS:
            rs = [r for r in recs if r[2] == ctrl and lo <= r[5] < hi]
            n = sum(1 for r in rs if lost(r[3]))
            rows.append(["%g-%g" % (lo, hi), ctrl, len({r[0] for r in rs}), len(rs), n,
                         "%.0f %%" % (100.0 * n / len(rs)) if rs else "-"])
    table("Lost runs by the machine file's Fs/Fc over the truth's",
          ["(Fs/Fc) / truth's", "estimator", "axes", "runs", "lost", "share"], rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
