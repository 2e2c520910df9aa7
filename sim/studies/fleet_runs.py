# SPDX-License-Identifier: Apache-2.0
"""One axis of the fleet study through the chain a user runs (docs/fleet.md,
docs/configure.md): the identification log simulated on its plant -> the
diagnosis with the user's machine file given -> machine.json -> the host tools
built for machine.json -> every controller on each trajectory of its set, on
the axis's true plant. The chain's steps are machine_chain.py's (host_build,
truth_model, run); a step that fails ends the axis with its stage and message
(a finding, listed), an exception here is an internal error.

Runs one controller per tool call, so that a run that goes non-finite (the
tool's exit 1) is that run's failure, not its neighbours'."""
import contextlib
import json
import os
import resource
import shutil
import subprocess
import sys
import time
import traceback
import types

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import fleet_axis  # noqa: E402
import machine_chain  # noqa: E402
from robustness import LOST_OUTLIER_FRAC  # noqa: E402
from runs import REFUSED_AT_INIT, faulted  # noqa: E402

# br_robust_run, the machine file's model; the estimators with its causes (--machine-causes), as the
# image built for machine.json has them (docs/fleet.md, "The estimators as the image has them")
CIRCLE_CTRLS = ("hinf_only", "hinf_ff", "hinf_ukf", "hinf_pf")
# br_track (not its _ff controllers: their feedforward is the plant's, an oracle; the estimators with the
# machine file's causes, --machine-causes); each also with the
# inertia feedforward of the axis's machine file (its mass times the reference acceleration: what the
# firmware knows), as a motion controller runs a track (docs/fleet.md, "The tracks")
TRACK_CTRLS = ("hinf_only", "hinf_ukf", "hinf_pf", "hinf_inertia", "hinf_ukf_inertia", "hinf_pf_inertia")
ESTIMATORS = ("hinf_ff", "hinf_ukf", "hinf_pf")
IDENT_REVERSALS = 1  # the identification log's reversal segment: the log docs/diagnose.md asks for presliding


class ChainError(Exception):
    """a step of the user's chain failed: the axis's finding, not the study's error"""

    def __init__(self, stage, msg):
        super().__init__("%s: %s" % (stage, msg))
        self.stage, self.msg = stage, msg


def step(stage, fn, *args, **kw):
    """machine_chain's steps end with sys.exit(message) on a failure: that is the stage's failure"""
    try:
        return fn(*args, **kw)
    except SystemExit as e:
        raise ChainError(stage, str(e.code)) from None


def tool(stage, cmd, log):
    r = subprocess.run(cmd, stdout=log, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise ChainError(stage, (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1])


def speed_cap(exe, log):
    """(lo, hi) -> the largest reference speed the drive exe is built for passes untouched in [lo, hi]
    (br_track --speed-cap: the firmware limiter's caps, their one home)"""
    def cap(lo, hi):
        r = subprocess.run([exe, "--speed-cap", "%.9g,%.9g" % (lo, hi)], capture_output=True, text=True)
        log.write(r.stderr)
        if r.returncode != 0:
            raise ChainError("br_track --speed-cap", (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1])
        return float(r.stdout)
    return cap


def run_seed(study_seed, i, k):
    """the noise seed of the axis's k-th run (independent of scheduling)"""
    return int(np.random.default_rng(fleet_axis.axis_seed(study_seed, i) + [2, k]).integers(1, 2 ** 31))


def result(raw, rms_key, max_key):
    """one run's record: its figures, or its fault (then no figures)"""
    if faulted(raw):
        # a run refused at init keeps its status (the firmware's BR_E_*): fleet.py counts it apart
        return {"faulted": True, "fault_t_s": raw["fault_t_s"], "fault_cause": raw.get("fault_cause", "unknown"),
                **({"init_status": raw["fault_status"]} if raw.get("fault_cause") == REFUSED_AT_INIT else {})}
    r = {"faulted": False, "rms_m": raw[rms_key], "max_m": raw[max_key]}
    if "ref_limited_periods" in raw:
        # br_track: the periods whose reference the drive's limiter changed (docs/tools.md)
        r["ref_limited_periods"] = raw["ref_limited_periods"]
    if "outlier_steps" in raw:
        r["outlier_steps"] = raw["outlier_steps"]
        r["persistent_outliers"] = raw["outlier_steps"] > LOST_OUTLIER_FRAC * 2 * raw["n_samples"]
    return r


def tool_record(js, ctrl):
    """result() of controller ctrl in a tool's JSON js: br_robust_run nests its controllers and names
    the contour RMS, br_track does neither"""
    if "controllers" in js:
        return result(js["controllers"][ctrl], "contour_rms_m", "max_err_m")
    return result(js[ctrl], "rms_m", "max_m")


def circle_runs(d, exe, truth, gms, tr, seed, noise, log, extra=()):
    """each circle controller on br_robust_run (extra: more of its options, a study's: fleet_rerun.py)"""
    out = {}
    for k, ctrl in enumerate(CIRCLE_CTRLS):
        js = os.path.join(d, "%s_%s.json" % (tr["name"], ctrl))
        cmd = [exe, "--plant", truth, *gms, "--only", ctrl, "--force-noise", "%.6g" % noise, "--seed", str(seed),
               "--json", js, "--machine-causes", *extra]
        if tr["kind"] == "circle":
            cmd += ["--radius-m", "%.6g" % tr["radius_m"], "--feed-mm-min", "%.6g" % tr["feed_mm_min"],
                    "--direction", tr["direction"]]
        try:
            tool("br_robust_run", cmd, log)
        except ChainError as e:
            out[ctrl] = {"faulted": True, "fault_t_s": None, "fault_cause": "tool failed: " + e.msg}
            continue
        with open(js, encoding="utf-8") as f:
            out[ctrl] = result(json.load(f)["controllers"][ctrl], "contour_rms_m", "max_err_m")
    return out


def track_runs(d, exe, truth, gms, ref, name, log):
    out = {}
    for ctrl in TRACK_CTRLS:
        js = os.path.join(d, "%s_%s.json" % (name, ctrl))
        try:
            tool("br_track", [exe, "--ref", ref, "--model", truth, *gms, "--ctrl", ctrl, "--json", js,
                              "--machine-causes"], log)
        except ChainError as e:
            out[ctrl] = {"faulted": True, "fault_t_s": None, "fault_cause": "tool failed: " + e.msg}
            continue
        with open(js, encoding="utf-8") as f:
            out[ctrl] = result(json.load(f)[ctrl], "rms_m", "max_m")
    return out


class Stopwatch:
    """wall and CPU seconds per stage of one axis, added up by stage (timing.json, never summary.json)"""

    def __init__(self):
        self.t, self.w, self.c = {}, time.time(), cpu_s()

    def lap(self, stage):
        w, c = time.time(), cpu_s()
        for key, v in (("wall_s", w - self.w), ("cpu_s", c - self.c)):
            self.t.setdefault(key, {})
            self.t[key][stage] = self.t[key].get(stage, 0.0) + v
        self.w, self.c = w, c


def chain(a, ax, d, log, sw):
    """the user's chain: the paths of the truth model and the two tools built for machine.json"""
    given, truth = os.path.join(d, "given.json"), os.path.join(d, "truth.json")
    g = fleet_axis.given_file(ax, "fleet-%04d" % ax["i"])
    why = fleet_axis.use_hinf_rule(g, a.hinf_rule)
    if a.load_q == "scaled":
        fleet_axis.scale_load_q(g, fleet_axis.reference_file())
    for path, m in ((given, g), (truth, fleet_axis.truth_file(ax, g))):
        with open(path, "w", encoding="utf-8") as f:
            json.dump(m, f, indent=1)
    truth_model = os.path.join(d, "truth-model.json")
    machine_chain.truth_model(truth, truth_model, a.src)
    simlog = step("build for the truth", machine_chain.host_build, a, truth, os.path.join(d, "host-truth"),
                  "br_simlog")
    sw.lap("builds")
    ident = os.path.join(d, "ident.csv")
    tool("identification log", [simlog, "--out", ident, "--traj", "ident", "--model", truth_model,
                                "--force-noise", "%.6g" % ax["force_noise_N"], "--seed", str(run_seed(a.seed, ax["i"], 0)),
                                "--reversals", str(IDENT_REVERSALS), *fleet_axis.gms_options(ax),
                                "--machine-out", os.path.join(d, "ident.machine.json")], log)
    sw.lap("identification_log")
    diag = os.path.join(d, "diagnose")
    env = dict(os.environ, PYTHONPATH=os.path.join(a.src, "python"), MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", ident, "--out", diag,
                        "--machine", given, "--no-plots", "--quiet"], stdout=log, stderr=subprocess.PIPE, text=True,
                       env=env)
    if r.returncode != 0:
        raise ChainError("diagnosis", (r.stderr.strip().splitlines() or ["exit %d" % r.returncode])[-1])
    sw.lap("diagnosis")
    machine_json = os.path.join(diag, "machine.json")
    bdir = os.path.join(d, "host-machine")
    robust = step("build for machine.json", machine_chain.host_build, a, machine_json, bdir, "br_robust_run")
    track = step("build for machine.json", machine_chain.host_build, a, machine_json, bdir, "br_track")
    sw.lap("builds")
    with open(machine_json, encoding="utf-8") as f:
        mj = json.load(f)
    return truth_model, robust, track, {"hinf_weights": why or "the reference's",
                                        **{sec: mj[sec] for sec in ("mechanics", "friction", "causes", "control",
                                                                    "friction_model") if sec in mj}}


def trajectory_set(a, ax):
    return [t for t in ax["traj"] if t["kind"] in a.kinds]


def one_axis(a, i):
    """the record of axis i (a: src, out, seed, kinds, keep): never raises"""
    os.environ["CMAKE_BUILD_PARALLEL_LEVEL"] = "1"  # one compile per worker: the workers share the cores
    os.environ["OPENBLAS_NUM_THREADS"] = "1"
    a = types.SimpleNamespace(**a)
    sw = Stopwatch()
    ax = fleet_axis.draw(a.seed, i)
    d = os.path.join(a.out, "axes", "%04d" % i)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    rec = {"i": i, "axis": {k: v for k, v in ax.items() if k not in ("i", "traj")}, "runs": {}, "traj": {}}
    with open(os.path.join(d, "chain.log"), "w", encoding="utf-8") as log, contextlib.redirect_stdout(log):
        try:
            truth, robust, track, rec["machine"] = chain(a, ax, d, log, sw)
            # the tracked references within what the drive built for machine.json accepts
            with open(os.path.join(d, "diagnose", "machine.json"), encoding="utf-8") as f:
                lim = fleet_axis.track_limits(ax, json.load(f), speed_cap(track, log))
            gms = fleet_axis.gms_options(ax)  # the truth's Maxwell-slip friction, where it has one
            for k, tr in enumerate(trajectory_set(a, ax)):
                rec["traj"][tr["name"]] = tr
                if tr["kind"] in ("thesis_circle", "circle"):
                    rec["runs"][tr["name"]] = circle_runs(d, robust, truth, gms, tr, run_seed(a.seed, i, k + 1),
                                                          ax["force_noise_N"], log)
                    continue
                t, ref = (fleet_axis.p2p_reference(tr["moves"], ax["max_speed_mps"], lim["p2p_mps"], lim["acc_mps2"],
                                                   lim["dt_s"]) if tr["kind"] == "p2p"
                          else fleet_axis.emps_reference(lim["emps_mps"], lim["acc_mps2"], lim["dt_s"]))
                tr["duration_s"] = float(t[-1])
                path = os.path.join(d, tr["name"] + ".ref.csv")
                fleet_axis.write_reference(path, t, ref)
                rec["runs"][tr["name"]] = track_runs(d, track, truth, gms, path, tr["name"], log)
        except ChainError as e:
            rec["chain_failed"] = {"stage": e.stage, "message": e.msg}
        except Exception:  # noqa: BLE001 - the study's own error, reported and made its exit status
            rec["error"] = traceback.format_exc()
    if not a.keep:
        for b in ("host-truth", "host-machine"):
            shutil.rmtree(os.path.join(d, b), ignore_errors=True)
    sw.lap("runs")
    rec["timing"] = sw.t
    return rec


def cpu_s():
    """CPU seconds of this process and its finished children (the tools, the builds, the diagnosis)"""
    return sum(getattr(resource.getrusage(w), k) for w in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
               for k in ("ru_utime", "ru_stime"))
