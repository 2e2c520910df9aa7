#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A machine through the whole chain (docs/configure.md): a log (measured, or
simulated on the given machine's plant) -> the diagnosis -> OUT/machine.json
-> the STM32H743 image built for it -> the simulator with the firmware built
for it: the log's own reference trajectory (br_track) and/or the thesis
circle (br_circle_ext), H-infinity only against H-infinity + PF.

  machine_chain.py --src REPO --work DIR --given MACHINE.json
                   [--log CSV | --simulate] [--controller FILE]
                   [--diagnose] [--cross] [--track] [--circle]
                   [--md DOC] [--check-ratio R]

--simulate   the identification log of br_simlog (docs/simlog.md) built for
             the given machine (-DBR_MACHINE=given: its plant), with the
             position loop it writes beside the log
--diagnose   python -m bristle.diagnose on the log with --machine given -> WORK/diagnose/
--cross      the image for WORK/diagnose/machine.json in WORK/cm7 (or --cross-dir):
             flash and RAM against the part's, the PF's entry points linked
--track      br_track on the log's reference (the identified plant of model.json);
             --track-ctrl LIST: its controllers (br_track --ctrl)
--circle     br_circle_ext --est pf with the firmware of machine.json on the
             plant of the given machine (the truth of a simulated log), or of
             the diagnosis's model.json (a measured log)
--md DOC     the track table into DOC between "<!-- chain:begin -->" and "<!-- chain:end -->"
--check-ratio R  exit 1 unless H-inf + PF (nominal model) / H-inf only < R on the circle,
             and the image links the PF within the part's memory
--expect-fault NAMES  runs (track or circle names, comma-separated) allowed to fault
Prints each figure; WORK/summary.json holds them. A run the firmware stopped
(a fault) is shown as a fault with its time and cause, never as an RMS; any
other faulted run makes the script exit 1 (after writing the page, which shows it)."""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from runs import fault_text, faulted, run_or_exit  # noqa: E402

BEGIN, END = "<!-- chain:begin -->", "<!-- chain:end -->"
TRACK = (("pd", "the log's PD controller"), ("hinf_only", "H-infinity only"),
         ("hinf_pf", "H-infinity + PF, nominal model"), ("hinf_pf_ext", "H-infinity + PF, extended model"),
         ("hinf_true", "H-infinity + the true friction (limit)"))


def run(cmd, **kw):
    return run_or_exit("machine_chain", cmd, **kw)


def host_build(a, machine, bdir, target):
    if not os.path.exists(os.path.join(bdir, "build.ninja")):
        run(["cmake", "-S", a.src, "-B", bdir, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
             "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG", "-DBR_MACHINE=" + os.path.abspath(machine),
             "-DBR_PYTHON=" + sys.executable], stdout=subprocess.DEVNULL)
    run(["cmake", "--build", bdir, "--target", target], stdout=subprocess.DEVNULL)
    return os.path.join(bdir, "sim", target)


def cross_build(a, machine, bdir):
    """The image for machine (the cm7-release preset's settings, BR_MACHINE);
    its size against the part's (the board's info file), the PF linked."""
    r = subprocess.run(["cmake", "--preset", "cm7-release", "-B", bdir, "-DBR_MACHINE=" + os.path.abspath(machine),
                        "-DBR_PYTHON=" + sys.executable], cwd=a.src, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(r.stdout + r.stderr + "machine_chain: configuring %s failed" % bdir)
    run(["cmake", "--build", bdir], stdout=subprocess.DEVNULL)
    # the board's info file: image path, flash KiB, then one NAME:ORIGIN:KIB per RAM region
    with open(os.path.join(bdir, "board-stm32h7.txt"), encoding="utf-8") as f:
        img, fk, *regions = f.read().split()
    size = subprocess.run(["arm-none-eabi-size", img], capture_output=True, text=True, check=True).stdout
    text, data, _ = (int(x) for x in size.splitlines()[1].split()[:3])
    sections = subprocess.run(["arm-none-eabi-size", "-A", img], capture_output=True, text=True,
                              check=True).stdout.splitlines()
    ram = []
    for r in regions:
        name, org, kib = r.split(":")
        lo, hi = int(org, 0), int(org, 0) + 1024 * int(kib)
        used = sum(int(ln.split()[1]) for ln in sections
                   if len(ln.split()) == 3 and ln.split()[2].isdigit() and lo <= int(ln.split()[2]) < hi)
        ram.append({"name": name, "bytes": used, "kib": int(kib)})
    syms = subprocess.run(["arm-none-eabi-nm", img], capture_output=True, text=True, check=True).stdout
    linked = sorted({ln.split()[-1] for ln in syms.splitlines()
                     if ln.split()[-1] in ("br_pf_init", "br_pf_est_step", "br_ukf_init", "br_ukf_est_step")})
    out = {"image": os.path.relpath(img, a.src), "flash_bytes": text + data, "flash_kib": int(fk), "ram": ram,
           "estimator_symbols": linked}
    print("image %s: flash %d B (%.2f %% of %s KiB), RAM %s; linked: %s"
          % (out["image"], out["flash_bytes"], 100.0 * out["flash_bytes"] / (1024 * int(fk)), fk,
             ", ".join("%s %d B (%.2f %% of %d KiB)" % (r["name"], r["bytes"], 100.0 * r["bytes"] / (1024 * r["kib"]),
                                                       r["kib"]) for r in ram),
             ", ".join(linked) or "no estimator"))
    return out


def truth_model(given, path, src):
    """The given machine as a model.json (its plant: the truth of a simulated log)."""
    sys.path.insert(0, os.path.join(src, "firmware", "design"))
    import machine
    m = machine.load(given)
    p = machine.params(m)
    params = {"Meff_kg": p["Jeff_kgm2"] / p["L_mprad"] ** 2}
    params.update({k: m["friction"][k] for k in m["friction"]})
    for c in m["causes"].values():
        params.update(c)
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"format": "bristle-model/2", "source": given, "params": params}, f, indent=2)


def plot_track(work, names, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    fig, ax = plt.subplots(3, 1, figsize=(10, 8), sharex=True)
    for name, label in names:
        f = os.path.join(work, "track", "track_%s.csv" % name)
        if not os.path.exists(f):
            continue
        d = np.loadtxt(f, delimiter=",", skiprows=1)
        if name == "hinf_only":
            ax[0].plot(d[:, 0], d[:, 1], "k", lw=0.8, label="reference")
        a = ax[1] if name == "pd" else ax[2]
        a.plot(d[:, 0], d[:, 3] * 1e6, lw=0.7, label=label)
    ax[0].set_ylabel("position, m")
    for a in ax:
        a.legend(loc="upper right", fontsize=8)
    ax[1].set_ylabel("tracking error, µm")
    ax[2].set_ylabel("tracking error, µm")
    ax[2].set_xlabel("t, s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def cells(r, rms_key, max_key, ref):
    """the row's figures, or the fault (time, cause) in their place"""
    if faulted(r):
        return fault_text(r) + " | — | —"
    ratio = "%.3f" % (r[rms_key] / ref) if ref else "—"
    return "%.3e m | %.3e m | %s" % (r[rms_key], r[max_key], ratio)


def faults(s):
    """every tabulated run that faulted: (where, name, time, cause)"""
    out = []
    for where, key in (("track", "track"), ("circle", "circle")):
        for name, r in s.get(key, {}).items():
            if isinstance(r, dict) and faulted(r):
                out.append((where, name, r["fault_t_s"], r.get("fault_cause", "unknown")))
    return out


def unexpected_faults(s, expect=""):
    """a message per faulted run not named in expect (comma-separated run names)"""
    expected = {n for n in expect.split(",") if n}
    return ["%s run %s faulted at %.3f s (%s): not a result" % f for f in faults(s) if f[1] not in expected]


def write_md(doc, s):
    rows = ["The log's reference trajectory (24.8 s) on the identified plant (model.json):", "",
            "| controller | tracking RMS | max error | against H-inf only |", "|---|---|---|---|"]
    h = s["track"]["hinf_only"]
    ref = None if faulted(h) else h["rms_m"]
    for name, label in TRACK:
        r = s["track"].get(name)
        if r:
            rows.append("| %s | %s |" % (label, cells(r, "rms_m", "max_m", ref)))
    if "circle" in s:
        c = s["circle"]
        ref = None if faulted(c["hinf_only"]) else c["hinf_only"]["contour_rms_m"]
        rows += ["", "The thesis circle (radius 0.1 mm, 8 s) on the same plant, the firmware built for machine.json:", "",
                 "| controller | contour RMS | max error | against H-inf only |", "|---|---|---|---|"]
        for name, label in (("hinf_only", "H-infinity only"), ("est_nominal", "H-infinity + PF, nominal model"),
                            ("est_extended", "H-infinity + PF, extended model")):
            rows.append("| %s | %s |" % (label, cells(c[name], "contour_rms_m", "max_err_m", ref)))
    if "image" in s:
        im = s["image"]
        rows += ["", "Image (`make firmware MACHINE=out/emps-chain/diagnose/machine.json`): flash %d B of %d KiB, "
                 "RAM %s; estimator entry points linked: %s."
                 % (im["flash_bytes"], im["flash_kib"],
                    ", ".join("%s %d B of %d KiB" % (r["name"], r["bytes"], r["kib"]) for r in im["ram"]),
                    ", ".join(im["estimator_symbols"]) or "none")]
    with open(doc, encoding="utf-8") as f:
        text = f.read()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    with open(doc, "w", encoding="utf-8") as f:
        f.write(text[:i] + "\n" + "\n".join(rows) + "\n" + text[j:])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--src", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--given", required=True)
    ap.add_argument("--log")
    ap.add_argument("--simulate", action="store_true")
    ap.add_argument("--controller", help="JSON with the log's \"controller\" (emps_pd): the PD of br_track")
    ap.add_argument("--diagnose", action="store_true")
    ap.add_argument("--cross", action="store_true")
    ap.add_argument("--cross-dir")
    ap.add_argument("--track", action="store_true")
    ap.add_argument("--circle", action="store_true")
    ap.add_argument("--md")
    ap.add_argument("--check-ratio", type=float)
    ap.add_argument("--expect-fault", default="", help="run names allowed to fault, comma-separated")
    ap.add_argument("--track-ctrl", help="br_track's --ctrl list (default: its own; with --controller the log's PD first)")
    a = ap.parse_args()
    a.src = os.path.abspath(a.src)
    os.makedirs(a.work, exist_ok=True)
    s = {"given": a.given}
    log = a.log
    if a.simulate:
        simlog = host_build(a, a.given, os.path.join(a.work, "host-given"), "br_simlog")
        log = os.path.join(a.work, "ident.csv")
        run([simlog, "--out", log, "--traj", "ident", "--machine-out", os.path.join(a.work, "ident.machine.json")])
    diag = os.path.join(a.work, "diagnose")
    machine_json = os.path.join(diag, "machine.json")
    if a.diagnose:
        env = dict(os.environ, PYTHONPATH=os.path.join(a.src, "python"), MPLBACKEND="Agg")
        run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", log, "--out", diag, "--machine", a.given,
             "--no-plots"], env=env)
    with open(machine_json, encoding="utf-8") as f:
        mj = json.load(f)
    kinds = {}
    for k, v in mj.get("provenance", {}).items():
        kinds.setdefault(v, []).append(k)
    s["provenance"] = kinds
    s["machine"] = {sec: mj[sec] for sec in ("mechanics", "friction", "causes")}
    if a.cross:
        s["image"] = cross_build(a, machine_json, a.cross_dir or os.path.join(a.work, "cm7"))
    if a.track or a.circle:
        bdir = os.path.join(a.work, "host-machine")
    if a.track:
        track = host_build(a, machine_json, bdir, "br_track")
        cmd = [track, "--ref", log, "--model", os.path.join(diag, "model.json"),
               "--json", os.path.join(a.work, "track.json"), "--trace", os.path.join(a.work, "track")]
        os.makedirs(os.path.join(a.work, "track"), exist_ok=True)
        if a.controller:
            with open(a.controller, encoding="utf-8") as f:
                c = json.load(f)["controller"]
            cmd += ["--pd", "%r,%r,%r,%r" % (c["kp_1ps"], c["kv"], c["gain_N"], c["u_max"])]
        if a.track_ctrl:
            cmd += ["--ctrl", a.track_ctrl]
        run(cmd)
        with open(os.path.join(a.work, "track.json"), encoding="utf-8") as f:
            s["track"] = {k: v for k, v in json.load(f).items() if isinstance(v, dict)}
        plot_track(a.work, TRACK, os.path.join(a.work, "track.png"))
    if a.circle:
        ext = host_build(a, machine_json, bdir, "br_circle_ext")
        truth = os.path.join(diag, "model.json")  # a measured log: the identified plant
        if a.simulate:  # a simulated one: the plant it was simulated on
            truth = os.path.join(a.work, "truth-model.json")
            truth_model(a.given, truth, a.src)
        run([ext, "--model", truth, "--est", "pf", "--json", os.path.join(a.work, "circle.json")])
        with open(os.path.join(a.work, "circle.json"), encoding="utf-8") as f:
            s["circle"] = {k: v for k, v in json.load(f).items() if isinstance(v, dict)}
        c = s["circle"]
        s["circle_ratio_pf_nominal"] = (None if faulted(c["est_nominal"]) or faulted(c["hinf_only"])
                                        else c["est_nominal"]["contour_rms_m"] / c["hinf_only"]["contour_rms_m"])
        for name in ("hinf_only", "est_nominal", "est_extended"):
            print("circle %s: %s" % (name, cells(c[name], "contour_rms_m", "max_err_m", None).split(" | ")[0]))
    if a.md:
        write_md(a.md, s)
    with open(os.path.join(a.work, "summary.json"), "w", encoding="utf-8") as f:
        json.dump(s, f, indent=2)
        f.write("\n")
    unexpected = unexpected_faults(s, a.expect_fault)
    for msg in unexpected:
        print("machine_chain: %s%s" % (msg, "; the page shows the fault" if a.md else ""), file=sys.stderr)
    if unexpected:
        return 1
    if a.check_ratio is not None:
        bad = []
        ratio = s.get("circle_ratio_pf_nominal")
        if ratio is None or not ratio < a.check_ratio:
            bad.append("circle contour RMS H-inf + PF / H-inf only = %s, not below %g"
                       % ("%.4g" % ratio if ratio is not None else "none (a run faulted)", a.check_ratio))
        im = s.get("image")
        if im is not None:
            if "br_pf_est_step" not in im["estimator_symbols"]:
                bad.append("the image does not link the PF (br_pf_est_step)")
            if im["flash_bytes"] > 1024 * im["flash_kib"] or any(r["bytes"] > 1024 * r["kib"] for r in im["ram"]):
                bad.append("the image does not fit the part's flash / RAM")
        for b in bad:
            print("machine_chain: " + b, file=sys.stderr)
        return 1 if bad else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
