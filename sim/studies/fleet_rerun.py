# SPDX-License-Identifier: Apache-2.0
"""The circles of a fleet study's axes again, with br_robust_run built from
this tree for each axis's machine.json as the diagnosis wrote it
(docs/fleet.md, "Holding on the fleet's axes"): the same truth, trajectories,
force noise and seeds as the study's runs (fleet_runs.circle_runs), so that
a change of the settings machine.py derives is compared on the same axes
without the chain's identification and diagnosis. Prints, per estimator,
the runs that faulted before (the study's JSON) and now, and the median of
RMS / H-inf only over the runs that went to the end. --pf-adapt-max S runs
the PF with that largest noise-variance factor of cfg.adapt instead of the
machine file's (docs/fleet.md, "The PF's start on the fleet's axes").
--machine truth builds it for the axis's truth.json instead (the plant's own
friction and delay, the given file's settings): a diagnosis without error, so
that a loss that stays is the estimator's, one that goes the diagnosis's
(docs/fleet.md, "Why runs end worse than H-inf only"). The
rerun's estimators carry machine.json's causes (fleet_runs.circle_runs); a
study whose runs did not (before that change) is named as such per axis.

    python sim/studies/fleet_rerun.py out/fleet OUT [--axes 63,67] [--pf-adapt-max S] [--machine truth]"""
import argparse
import glob
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fleet_axis  # noqa: E402
import fleet_runs  # noqa: E402
import machine_chain  # noqa: E402

CTRLS = ("hinf_only", "hinf_ukf", "hinf_pf")


def records(d, names):
    """({(traj, ctrl): the run's record} from the circle JSONs in d, the causes their UKF and PF runs
    carried: "thesis" where the JSON predates the key)"""
    out, causes = {}, set()
    for name in names:
        for ctrl in CTRLS:
            path = os.path.join(d, "%s_%s.json" % (name, ctrl))
            if os.path.exists(path):
                with open(path, encoding="utf-8") as f:
                    js = json.load(f)
                out[(name, ctrl)] = fleet_runs.tool_record(js, ctrl)
                if ctrl != "hinf_only":
                    causes.add(js.get("estimator_causes", "thesis"))
    return out, causes


def tally(recs):
    """per estimator: faulted runs (cause list) and the medians of RMS / H-inf only"""
    out = {}
    for ctrl in CTRLS[1:]:
        faults, ratios = [], []
        for (i, name, c), r in recs.items():
            if c != ctrl:
                continue
            if r["faulted"]:
                faults.append("%d %s %s" % (i, name, r["fault_cause"]))
                continue
            h = recs.get((i, name, "hinf_only"))
            if h and not h["faulted"]:
                ratios.append(r["rms_m"] / h["rms_m"])
        out[ctrl] = {"runs": sum(1 for k in recs if k[2] == ctrl), "faulted": faults,
                     "median_ratio": float(np.median(ratios)) if ratios else None,
                     "worse": sum(1 for x in ratios if x > 1.0)}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", help="a fleet study's out folder (its axes/<i>/ with diagnose/machine.json)")
    ap.add_argument("out", help="where the builds and runs go")
    ap.add_argument("--seed", type=int, default=20261201, help="the study's seed")
    ap.add_argument("--axes", help="comma-separated axis indices (default: every axis the chain finished)")
    ap.add_argument("--pf-adapt-max", type=float,
                    help="br_robust_run --pf-adapt-max (1: no inflation); the circles only")
    ap.add_argument("--tracks", action="store_true",
                    help="also the point-to-point and EMPS tracks (br_track, on the study's references)")
    ap.add_argument("--machine", choices=("diagnosed", "truth"), default="diagnosed",
                    help="the machine file the tool is built for: diagnose/machine.json (default) or truth.json")
    a = ap.parse_args()
    extra = () if a.pf_adapt_max is None else ("--pf-adapt-max", repr(a.pf_adapt_max))
    src = os.path.dirname(os.path.dirname(HERE))
    dirs = sorted(glob.glob(os.path.join(a.study, "axes", "*", "diagnose", "machine.json")))
    idx = [int(p.split(os.sep)[-3]) for p in dirs]
    if a.axes:
        want = {int(x) for x in a.axes.split(",") if x}
        idx = [i for i in idx if i in want]
    before, now = {}, {}
    os.environ["CMAKE_BUILD_PARALLEL_LEVEL"] = "1"
    build = argparse.Namespace(src=src)
    for i in idx:
        d, od = os.path.join(a.study, "axes", "%04d" % i), os.path.join(a.out, "%04d" % i)
        os.makedirs(od, exist_ok=True)
        ax = fleet_axis.draw(a.seed, i)
        circles = [(k, t) for k, t in enumerate(ax["traj"]) if t["kind"] in ("thesis_circle", "circle")]
        tracks = [t for t in ax["traj"] if a.tracks and t["kind"] in ("p2p", "emps")
                  and os.path.exists(os.path.join(d, "%s.ref.csv" % t["name"]))]
        names = [t["name"] for _, t in circles if os.path.exists(os.path.join(d, "%s_hinf_only.json" % t["name"]))]
        names += [t["name"] for t in tracks]
        mfile = os.path.join(d, *(("diagnose", "machine.json") if a.machine == "diagnosed" else ("truth.json",)))
        # one build folder per machine file kind: host_build configures a folder once
        exe = machine_chain.host_build(build, mfile, os.path.join(od, "host-" + a.machine), "br_robust_run")
        with open(os.path.join(od, "runs.log"), "w", encoding="utf-8") as log:
            for k, tr in circles:
                if tr["name"] in names:
                    fleet_runs.circle_runs(od, exe, os.path.join(d, "truth-model.json"), fleet_axis.gms_options(ax), tr,
                                           fleet_runs.run_seed(a.seed, i, k + 1), ax["force_noise_N"], log, extra)
            if tracks:
                trk = machine_chain.host_build(build, mfile, os.path.join(od, "host-" + a.machine), "br_track")
            for tr in tracks:
                fleet_runs.track_runs(od, trk, os.path.join(d, "truth-model.json"), fleet_axis.gms_options(ax),
                                      os.path.join(d, "%s.ref.csv" % tr["name"]), tr["name"], log)
        recs_before, causes_before = records(d, names)
        if causes_before - {"machine"}:
            # the rerun's estimators carry machine.json's causes (fleet_runs.circle_runs): a change of its own
            print("axis %d: the study's estimators ran on the %s model, the rerun's carry machine.json's causes"
                  % (i, "/".join(sorted(causes_before - {"machine"}))))
        for key, r in recs_before.items():
            before[(i,) + key] = r
        for key, r in records(od, names)[0].items():
            now[(i,) + key] = r
        for name in names:
            print("axis %d %s: %s" % (i, name, "  ".join(
                "%s %s -> %s" % (c, fmt(before.get((i, name, c))), fmt(now.get((i, name, c)))) for c in CTRLS)))
    for label, recs in (("before", before), ("now", now)):
        for group, names in (("", None), (" circles", ("thesis_circle", "circle")), (" tracks", ("p2p", "emps"))):
            sel = recs if names is None else {k: r for k, r in recs.items() if k[1].rstrip("0123456789") in names}
            if names is not None and not (a.tracks and sel):
                continue
            for ctrl, t in tally(sel).items():
                print("%s%s %s: %d runs, %d faulted, median RMS / H-inf only %s, %d worse than H-inf only" % (
                    label, group, ctrl, t["runs"], len(t["faulted"]),
                    "%.3g" % t["median_ratio"] if t["median_ratio"] is not None else "-", t["worse"]))
    return 0


def fmt(r):
    if r is None:
        return "-"
    return "%s@%.4gs" % (r["fault_cause"], r["fault_t_s"] or 0.0) if r["faulted"] else "%.3g" % r["rms_m"]


if __name__ == "__main__":
    sys.exit(main())
