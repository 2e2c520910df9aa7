# SPDX-License-Identifier: Apache-2.0
"""Two fleet runs of the same axes side by side (docs/fleet.md, "The
bandwidth from the friction"): each run's controller table (fleet.py's), the
axes whose chain failed, and per axis and trajectory each controller's run
before and after: its RMS when it went to the end, else its fault (cause and
time), "refused at init", or the chain's failure. A faulted run never shows
an RMS.

Usage: fleet_pair.py BEFORE_DIR AFTER_DIR [--only hinf_only,hinf_ukf,...]"""
import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fleet  # noqa: E402
from runs import refused  # noqa: E402


def load(folder):
    with open(os.path.join(folder, "summary.json"), encoding="utf-8") as f:
        return json.load(f)


def cell(rec, traj, ctrl):
    """one run as the page shows it"""
    if rec is None:
        return "—"
    if "chain_failed" in rec:
        return "chain failed (%s)" % rec["chain_failed"]["stage"]
    run_ = rec["runs"].get(traj, {}).get(ctrl)
    if run_ is None:
        return "—"
    if refused(run_):
        return "refused at init"
    if run_["faulted"]:
        t = run_.get("fault_t_s")
        return "**%s**%s" % (run_["fault_cause"], "" if t is None else " at %.3g s" % t)
    h = rec["runs"][traj].get("hinf_only")
    cause = fleet.why_lost(run_, None if ctrl == "hinf_only" or h is None or h["faulted"] else h["rms_m"])
    return "%.3g m%s" % (run_["rms_m"], " (**%s**)" % cause if cause else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--only", default=",".join(fleet.CONTROLLERS), help="the controllers of the per-run table")
    a = ap.parse_args()
    pair = [load(a.before), load(a.after)]
    ctrls = [c for c in a.only.split(",") if c]
    for name, s in zip(("before", "after"), pair):
        print("%s (%s):\n" % (name, [a.before, a.after][name == "after"]))
        print("\n".join(fleet.table(s["controllers"])))
        for f in s["axes_chain_failed"]:
            print("\n- axis %d, chain failed at %s: %s" % (f["axis"], f["stage"], f["message"]))
        print()
    recs = [{r["i"]: r for r in s["axes"]} for s in pair]
    print("| axis | trajectory | " + " | ".join("%s before | after" % c for c in ctrls) + " |")
    print("|---|---|" + "---|---|" * len(ctrls))
    for i in sorted(set(recs[0]) | set(recs[1])):
        trajs = sorted({t for r in (recs[0].get(i), recs[1].get(i)) if r for t in r["runs"]})
        for t in trajs or ["—"]:
            print("| %d | %s | %s |" % (i, t, " | ".join(
                "%s | %s" % (cell(recs[0].get(i), t, c), cell(recs[1].get(i), t, c)) for c in ctrls)))


if __name__ == "__main__":
    main()
