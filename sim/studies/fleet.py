# SPDX-License-Identifier: Apache-2.0
"""The fleet study (docs/fleet.md, issue 28 item 2): N axes drawn across the
range of machine files a user may bring, each through the user's chain
(fleet_runs.py), every controller on its trajectory set; the independent axes
run on Dask's local cluster, or on an existing one (--scheduler).

Usage:
  fleet.py --out DIR [--n N] [--seed S] [--workers W | --scheduler ADDRESS]
           [--kinds thesis_circle,circle,p2p,emps] [--md DOC] [--command CMD] [--keep-builds]
           [--hinf-weights reference|rule] [--load-q reference|scaled] [--axes I,J --merge BASE]

Writes DIR/summary.json (the same for the same N, seed and kinds, whatever the
workers: no time in it), DIR/timing.json (wall times), DIR/cdf.png, DIR/axes/NNNN/.
"controllers": per controller median_m, p90_m, max_m of the RMS (contour RMS on
the circles, tracking RMS on the tracks) over the runs that went to the end,
and "lost": every run that faulted, lost lock (persistent outliers) or ended
worse than H-inf only, with its axis, trajectory, time and cause. "kinds": the
same per trajectory kind. Every lost run and every axis whose chain failed is
printed; the exit status is 0 then, 1 only on the study's own error.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fleet_axis  # noqa: E402
import fleet_runs  # noqa: E402
from runs import refused  # noqa: E402

REPO = fleet_axis.REPO
KINDS = ("thesis_circle", "circle", "p2p", "emps")
# the tracks also run each with the inertia feedforward of the axis's machine file (fleet_runs.TRACK_CTRLS)
CONTROLLERS = ("hinf_only", "hinf_ff", "hinf_ukf", "hinf_pf", "hinf_inertia", "hinf_ukf_inertia", "hinf_pf_inertia")
FULL_N = 200  # the study's size (make fleet's default N)


# the causes of loss that are not faults (the run went to the end)
NOT_FAULTS = ("persistent_outliers", "worse_than_hinf_only")


def why_lost(run_, hinf):
    """a run's cause of loss, or None: a fault, persistent outliers, worse than H-inf only (hinf: its RMS)"""
    if run_["faulted"]:
        return run_["fault_cause"]
    if run_.get("persistent_outliers"):
        return NOT_FAULTS[0]
    if hinf is not None and run_["rms_m"] > hinf:
        return NOT_FAULTS[1]
    return None


def stats(vals):
    if not vals:
        return {"median_m": None, "p90_m": None, "max_m": None}
    v = np.array(vals)
    return {"median_m": float(np.median(v)), "p90_m": float(np.percentile(v, 90)), "max_m": float(v.max())}


def summarise(recs, kinds=None):
    """per controller: the RMS statistics of the completed runs, the ratio to H-inf only, the lost runs,
    and the runs the firmware refused at init (never run: neither a figure nor lost)"""
    out = {}
    for ctrl in CONTROLLERS:
        vals, ratios, lost, refusals, n = [], [], [], [], 0
        for r in recs:
            for name, runs in r["runs"].items():
                kind = r["traj"][name]["kind"]
                if ctrl not in runs or (kinds and kind not in kinds):
                    continue
                n += 1
                run_, h = runs[ctrl], runs.get("hinf_only")
                if refused(run_):
                    refusals.append({"axis": r["i"], "trajectory": name, "kind": kind,
                                     "status": run_.get("init_status")})
                    continue
                hinf = None if ctrl == "hinf_only" or h is None or h["faulted"] else h["rms_m"]
                if not run_["faulted"]:
                    vals.append(run_["rms_m"])
                    if hinf:
                        ratios.append(run_["rms_m"] / hinf)
                cause = why_lost(run_, hinf)
                if cause:
                    lost.append({"axis": r["i"], "trajectory": name, "kind": kind, "t_s": run_.get("fault_t_s"),
                                 "cause": cause})
        if n:
            out[ctrl] = {"n": n, "n_completed": len(vals), **stats(vals),
                         "median_ratio_to_hinf_only": float(np.median(ratios)) if ratios else None,
                         "n_lost": len(lost), "lost": lost,
                         "n_refused_at_init": len(refusals), "refused_at_init": refusals}
    return out


FRICTIONS = (("lugre", "LuGre"), ("maxwell_slip", "Maxwell-slip presliding"))


def friction_of(r):
    return "maxwell_slip" if r["axis"].get("presliding") else "lugre"


def friction_split(recs):
    """per plant friction (fleet_axis.P_PRESLIDING): the axes, how many the diagnosis named
    presliding_hysteresis on, and the controllers' statistics over their runs"""
    out = {}
    for key, _ in FRICTIONS:
        sub = [r for r in recs if friction_of(r) == key]
        through = [r for r in sub if "chain_failed" not in r]
        # the machine file carries presliding_hysteresis as its Maxwell-slip friction_model (machine-file.md)
        named = [r["i"] for r in through
                 if (r.get("machine", {}).get("friction_model") or {}).get("model") == "maxwell_slip"]
        out[key] = {"n_axes": len(sub), "n_through_chain": len(through), "presliding_named": named,
                    "controllers": summarise(sub)}
    return out


def ref_limited(recs):
    """the track runs whose reference the drive's limiter changed (br_track's ref_limited_periods,
    docs/tools.md): another trajectory than the one drawn, listed with the periods"""
    return [{"axis": r["i"], "trajectory": name, "controller": ctrl, "periods": run_["ref_limited_periods"]}
            for r in recs for name, rr in r["runs"].items() for ctrl, run_ in rr.items()
            if run_.get("ref_limited_periods", 0) > 0]


def ref_limited_lines(summ):
    lim = summ.get("ref_limited", [])
    n = sum(1 for r in summ["axes"] for rr in r["runs"].values() for run_ in rr.values()
            if "ref_limited_periods" in run_)
    L = ["", "Track runs whose reference the drive's limiter changed (`ref_limited_periods` > 0, the run-in "
         "from rest included): %d of the %d track runs that went to the end%s" % (len(lim), n, ":" if lim else ".")]
    return L + ["- axis %d, %s, %s: %d periods" % (x["axis"], x["trajectory"], x["controller"], x["periods"])
                for x in lim]


def friction_lines(summ):
    L = []
    for key, title in FRICTIONS:
        f = summ.get("friction", {}).get(key)
        if not f or not f["n_axes"]:
            continue
        L += ["", "### %s plants (%d axes, %d through the chain; the diagnosis named presliding_hysteresis on %d)"
              % (title, f["n_axes"], f["n_through_chain"], len(f["presliding_named"])), ""] + table(f["controllers"])
    return L


def cdf_plot(recs, path, n_axes):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker  # noqa: F401 - the minor tick labels off
    fig, axs = plt.subplots(1, len(KINDS), figsize=(15, 4.2), sharey=True)
    colours = {"hinf_only": "k", "hinf_ff": "tab:brown", "hinf_ukf": "tab:blue", "hinf_pf": "tab:red",
               "hinf_inertia": "tab:gray", "hinf_ukf_inertia": "tab:cyan", "hinf_pf_inertia": "tab:pink"}
    for ax, kind in zip(axs, KINDS):
        for ctrl in CONTROLLERS:
            runs = [rr[ctrl] for r in recs for name, rr in r["runs"].items()
                    if r["traj"][name]["kind"] == kind and ctrl in rr]
            v = np.sort([x["rms_m"] for x in runs if not x["faulted"]])
            if len(v):
                # faulted runs never reach the curve: it ends below 1 by their share
                ax.step(v, np.arange(1, len(v) + 1) / len(runs), where="post", color=colours[ctrl],
                        label="%s (%d of %d)" % (ctrl, len(v), len(runs)))
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title(kind)
        ax.set_xlabel("contour RMS [m]" if "circle" in kind else "tracking RMS [m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="lower right")
    axs[0].set_ylabel("fraction of runs")
    fig.suptitle("Fleet: %d axes" % n_axes)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fmt(v):
    return "—" if v is None else "%.3e" % v


def table(ctl):
    L = ["| controller | runs | went to the end | median RMS | p90 | max | median / H-inf only | lost "
         "| refused at init |",
         "|---|---|---|---|---|---|---|---|---|"]
    for k, v in ctl.items():
        ratio = "—" if v["median_ratio_to_hinf_only"] is None else "%.3f" % v["median_ratio_to_hinf_only"]
        L.append("| %s | %d | %d | %s m | %s m | %s m | %s | %d | %d |" % (
            k, v["n"], v["n_completed"], fmt(v["median_m"]), fmt(v["p90_m"]), fmt(v["max_m"]), ratio, v["n_lost"],
            v["n_refused_at_init"]))
    return L


def lost_lines(summ):
    out = []
    for k, v in summ["controllers"].items():
        for x in v["lost"]:
            when = " at %.4f s" % x["t_s"] if x["t_s"] is not None else ""
            out.append("%s: axis %d, %s, %s%s" % (k, x["axis"], x["trajectory"], x["cause"], when))
    return out


def refused_lines(summ):
    """the runs refused at init, by controller and axis"""
    out = []
    for k, v in summ["controllers"].items():
        by_axis = {}
        for x in v["refused_at_init"]:
            by_axis.setdefault((x["axis"], x["status"]), []).append(x["trajectory"])
        out += ["%s: axis %d, status %s: %s" % (k, ax, st, ", ".join(tr)) for (ax, st), tr in sorted(by_axis.items())]
    return out


def lost_causes(summ):
    """the lost runs counted by controller and cause (the list follows in full)"""
    causes = sorted({x["cause"] for v in summ["controllers"].values() for x in v["lost"]})
    if not causes:
        return []
    out = ["| controller | " + " | ".join(causes) + " |", "|---|" + "---|" * len(causes)]
    for k, v in summ["controllers"].items():
        n = [sum(1 for x in v["lost"] if x["cause"] == c) for c in causes]
        out.append("| %s | %s |" % (k, " | ".join(str(x) for x in n)))
    return out


def hinf_line(summ):
    """which axes' given files took the H-inf weights from the machine (fleet_axis.use_hinf_rule)"""
    ruled = [r["i"] for r in summ["axes"] if r.get("machine", {}).get("hinf_weights", "the reference's")
             != "the reference's"]
    if summ.get("hinf_weights") == "rule":
        return "H-inf weights: from the machine on every axis (`--hinf-weights rule`, firmware/design/hinf_weights.py)."
    return ("H-inf weights: the reference's, and from the machine (firmware/design/hinf_weights.py) where the "
            "reference's admit no acceptable design: %s." % (", ".join("axis %d" % i for i in ruled) or "no axis"))


def write_md(path, summ, command, out_dir=None, out_name=None):
    """the page's measured part; out_dir's absolute path in the messages is written as out_name
    (default out_dir as given: a page does not name one machine's folders)"""
    L = ["<!-- generated by sim/studies/fleet.py --md; do not edit below -->", "",
         "## Measured: %d axes" % summ["n_axes"], "",
         "Command: `%s` (seed %d, trajectory kinds %s; the axes, the chain and the definitions above)."
         % (command, summ["seed"], ", ".join(summ["kinds_run"])), ""]
    if "merged" in summ:
        L += ["Run again on this tree: axes %s; the other axes' records are those of `%s` (`--merge`)."
              % (", ".join(str(i) for i in summ["merged"]["axes_run_again"]), summ["merged"]["base"]), ""]
    if summ["n_axes"] < FULL_N:
        L += ["**Provisional**: %d axes, not the study's %d." % (summ["n_axes"], FULL_N), ""]
    fails = summ["axes_chain_failed"]
    L += ["Axes through the chain: %d of %d%s" % (summ["n_axes"] - len(fails), summ["n_axes"],
                                                  "; the chain failed on:" if fails else ".")]
    L += [""] + ["- axis %d, %s: %s" % (f["axis"], f["stage"], f["message"]) for f in fails] if fails else []
    L += ["", hinf_line(summ)]
    L += ["", "### All trajectories (the contour RMS of the circles and the tracking RMS of the tracks together)",
          ""] + table(summ["controllers"])
    for kind, ctl in summ["kinds"].items():
        L += ["", "### %s" % kind, ""] + table(ctl)
    L += friction_lines(summ)
    L += ref_limited_lines(summ)
    lines = lost_lines(summ)
    L += ["", "### Lost runs (%d)" % len(lines), "",
          "A run is lost when the firmware stopped it (its fault's cause and time), its filter re-anchored "
          "in more than 1 % of the axis-periods (persistent_outliers), or it ended worse than H-inf only on the "
          "same axis and trajectory. A lost run that faulted has no RMS in the tables above.", ""]
    L += lost_causes(summ)
    if lines:
        L += ["", "<details><summary>every lost run (%d)</summary>" % len(lines), ""]
        L += ["- " + x for x in lines] + ["", "</details>"]
    else:
        L += ["none"]
    ref = refused_lines(summ)
    L += ["", "### Refused at init (%d)" % len(ref), "",
          "Runs whose application the firmware refused at init (`br_app_init`'s BR_E_* status, e.g. the "
          "estimation model's sub-step bound): never run, so neither a figure nor lost; the \"runs\" column "
          "counts them.", ""]
    L += ["- " + x for x in ref] if ref else ["none"]
    L += ["", "CDF per trajectory kind: `out/fleet/cdf.png`.", ""]
    if out_dir:
        L = [x.replace(os.path.abspath(out_dir), (out_name or out_dir).rstrip("/")) for x in L]
    with open(path, encoding="utf-8") as f:
        text = f.read()
    head = text.split("<!-- fleet:begin -->")[0] if "<!-- fleet:begin -->" in text else text
    with open(path, "w", encoding="utf-8") as f:
        f.write(head.rstrip("\n") + "\n\n<!-- fleet:begin -->\n" + "\n".join(L) + "<!-- fleet:end -->\n")


def axis_timing(recs, f):
    """f (median, max) over the axes of each stage's wall and CPU seconds, and of their totals"""
    out = {}
    for key in ("wall_s", "cpu_s"):
        stages = sorted({k for r in recs for k in r["timing"][key]})
        out[key] = {k: float(f([r["timing"][key].get(k, 0.0) for r in recs])) for k in stages}
        out[key]["total"] = float(f([sum(r["timing"][key].values()) for r in recs]))
    return out


def _add_path(path):
    if path not in sys.path:
        sys.path.insert(0, path)


def distribute(a, args):
    """every axis as one task on a Dask cluster, with dask's progress bar; records in index order"""
    from distributed import Client, LocalCluster, progress
    if a.scheduler:
        client, cluster = Client(a.scheduler), None
    else:
        cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None)
        client = Client(cluster)
    try:
        # the workers import fleet_runs and its neighbours from this folder (the same path on every worker)
        client.run(_add_path, HERE)
        idx = a.axes if a.axes is not None else list(range(a.n))
        futures = client.map(fleet_runs.one_axis, [args] * len(idx), idx, pure=False)
        progress(futures)
        sys.stdout.write("\n")
        recs = client.gather(futures)
    finally:
        client.close()
        if cluster:
            cluster.close()
    return sorted(recs, key=lambda r: r["i"])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--seed", type=int, default=20261201)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="the local cluster's worker processes")
    ap.add_argument("--scheduler", help="an existing Dask scheduler's address (tcp://host:port) instead")
    ap.add_argument("--axes", help="run only these axis indices of the seed's draw, comma-separated "
                    "(a fleet's subset: its axes are the same as in the full run; --n is ignored)")
    ap.add_argument("--kinds", default=",".join(KINDS), help="the trajectory kinds, comma-separated")
    ap.add_argument("--md", help="docs page: its part after <!-- fleet:begin --> is rewritten")
    ap.add_argument("--command", default="make fleet")
    ap.add_argument("--keep-builds", action="store_true", help="keep each axis's two host builds")
    ap.add_argument("--hinf-weights", choices=("reference", "rule"), default="reference",
                    help="the given files' control.hinf: the reference's, replaced by the weights from the "
                         "machine (firmware/design/hinf_weights.py) where they admit no acceptable design "
                         "(default); or the weights from the machine on every axis")
    ap.add_argument("--load-q", choices=("reference", "scaled"), default="reference",
                    help="the given files' estimator.<est>.load: the reference's random walk in N^2/s "
                         "(default), or the same share of each axis's actuator force (q_Fact2_per_s)")
    ap.add_argument("--merge", metavar="BASE",
                    help="with --axes: a study of BASE's axes (BASE/summary.json, the same seed and kinds) with "
                         "these axes run again; the summary, table and plot over them all (a change that alters "
                         "the machine files of some axes only, measured without running the rest again)")
    ap.add_argument("--expect-faults", action="store_true",
                    help="with --md: the page may tabulate faulted runs (listed with time and cause); "
                         "without it a faulted run makes the study exit 1 after writing the page")
    ap.add_argument("--md-out-name", help="with --md-only: the out folder as the page names it (default --out)")
    ap.add_argument("--md-only", action="store_true",
                    help="run nothing: write --md from OUT/summary.json (a study run before)")
    a = ap.parse_args()
    if a.md_only:
        if not a.md:
            ap.error("--md-only needs --md")
        try:
            with open(os.path.join(a.out, "summary.json"), encoding="utf-8") as f:
                summ_md = json.load(f)
            write_md(a.md, summ_md, a.command, a.out, a.md_out_name)
        except (OSError, ValueError, KeyError) as e:
            sys.exit("fleet.py: %s/summary.json: %s" % (a.out, e))
        print("wrote %s from %s/summary.json" % (a.md, a.out))
        return unexpected_faults(summ_md, a)
    kinds = [k for k in a.kinds.split(",") if k]
    try:
        a.axes = sorted({int(x) for x in a.axes.split(",") if x}) if a.axes else None
    except ValueError:
        ap.error("--axes: comma-separated axis indices")
    if a.axes is not None:
        if not a.axes or a.axes[0] < 0:
            ap.error("--axes: indices >= 0")
        a.n = len(a.axes)
    if not (1 <= a.n <= 100000) or a.workers < 1 or not kinds or set(kinds) - set(KINDS):
        ap.error("--n in 1..100000, --workers >= 1, --kinds from %s" % ",".join(KINDS))
    base = None
    if a.merge:
        if a.axes is None:
            ap.error("--merge needs --axes")
        try:
            with open(os.path.join(a.merge, "summary.json"), encoding="utf-8") as f:
                base = json.load(f)
        except (OSError, ValueError) as e:
            sys.exit("fleet.py: --merge %s/summary.json: %s" % (a.merge, e))
        same = {"seed": a.seed, "kinds_run": sorted(kinds), "hinf_weights": a.hinf_weights, "load_q": a.load_q}
        # a base from before --load-q ran the reference's random walks
        theirs = {"seed": base.get("seed"), "kinds_run": sorted(base.get("kinds_run", [])),
                  "hinf_weights": base.get("hinf_weights"), "load_q": base.get("load_q", "reference")}
        if theirs != same:
            sys.exit("fleet.py: --merge %s: %s: not this study's (%s)" % (a.merge, theirs, same))
        if set(a.axes) - {r["i"] for r in base["axes"]}:
            sys.exit("fleet.py: --merge %s: axes %s are not in it" % (
                a.merge, sorted(set(a.axes) - {r["i"] for r in base["axes"]})))
    os.makedirs(a.out, exist_ok=True)
    args = {"src": REPO, "out": os.path.abspath(a.out), "seed": a.seed, "kinds": kinds, "keep": a.keep_builds,
            "hinf_rule": a.hinf_weights == "rule", "load_q": a.load_q}
    t0 = time.time()
    recs = distribute(a, args)
    wall = time.time() - t0
    errors = [r for r in recs if "error" in r]
    good = [r for r in recs if "error" not in r]
    n_run = a.n
    if base is not None:
        # the base's records of the axes not run again, this run's of the rest; the base's axis
        # folders linked beside this run's, so that the folder readers (fleet_why.py,
        # fleet_worse.py, fleet_rerun.py) see every axis
        kept = [r for r in base["axes"] if r["i"] not in set(a.axes)]
        os.makedirs(os.path.join(a.out, "axes"), exist_ok=True)
        for r in kept:
            src = os.path.abspath(os.path.join(a.merge, "axes", "%04d" % r["i"]))
            dst = os.path.join(a.out, "axes", "%04d" % r["i"])
            if os.path.isdir(src) and not os.path.lexists(dst):
                os.symlink(src, dst)
        good = sorted(kept + good, key=lambda r: r["i"])
        a.n = base["n_axes"]
    summ = {"generator": "sim/studies/fleet.py", "n_axes": a.n, "seed": a.seed, "kinds_run": kinds,
            "hinf_weights": a.hinf_weights, "load_q": a.load_q,
            **({"merged": {"base": a.merge, "axes_run_again": a.axes,
                           **({"base_merged": base["merged"]} if "merged" in base else {})},
                **({"axes_run": base["axes_run"]} if "axes_run" in base else {})} if base is not None else
               {"axes_run": a.axes} if a.axes is not None else {}),
            "axes_chain_failed": [{"axis": r["i"], **r["chain_failed"]} for r in good if "chain_failed" in r],
            "controllers": summarise(good),
            "kinds": {k: summarise(good, (k,)) for k in kinds},
            "friction": friction_split(good),
            "ref_limited": ref_limited(good),
            "axes": [{k: v for k, v in r.items() if k != "timing"} for r in good]}
    with open(os.path.join(a.out, "summary.json"), "w", encoding="utf-8") as f:
        json.dump(summ, f, indent=1, sort_keys=True)
        f.write("\n")
    timing = {"wall_s": wall, "workers": a.workers if not a.scheduler else None, "scheduler": a.scheduler,
              "axis_median": axis_timing(recs, np.median), "axis_max": axis_timing(recs, np.max)}
    with open(os.path.join(a.out, "timing.json"), "w", encoding="utf-8") as f:
        json.dump(timing, f, indent=1)
        f.write("\n")
    cdf_plot(good, os.path.join(a.out, "cdf.png"), a.n)
    if a.md:
        write_md(a.md, summ, a.command, a.out)
    print("%d axes in %.0f s (an axis: median %.1f s wall, %.1f s CPU); chain failed on %d"
          % (n_run, wall, timing["axis_median"]["wall_s"]["total"], timing["axis_median"]["cpu_s"]["total"],
             len(summ["axes_chain_failed"])))
    for line in table(summ["controllers"]):
        print(line)
    for f in summ["axes_chain_failed"]:
        print("chain failed: axis %d, %s: %s" % (f["axis"], f["stage"], f["message"]))
    for line in lost_lines(summ):
        print("lost: " + line)
    for line in refused_lines(summ):
        print("refused at init: " + line)
    print("wrote %s/summary.json, timing.json, cdf.png%s" % (a.out, ", " + a.md if a.md else ""))
    for r in errors:
        print("fleet: internal error on axis %d:\n%s" % (r["i"], r["error"]), file=sys.stderr)
    if errors:
        return 1
    return unexpected_faults(summ, a)


def unexpected_faults(summ, a):
    """1 when the page just written lists faulted runs nobody said to expect (docs/tools.md:
    a docs-writing target fails on a fault it did not expect), else 0"""
    n = sum(1 for v in summ["controllers"].values() for x in v["lost"] if x["cause"] not in NOT_FAULTS)
    if n and a.md and not a.expect_faults:
        print("fleet: %d runs faulted (listed in %s with time and cause); --expect-faults accepts them"
              % (n, a.md), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
