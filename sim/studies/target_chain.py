#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The chain on a running target (docs/link.md, "The chain on a running
target"; issue 32 item 6), the steps that talk to the axis:

  target_chain.py ident   --bin DIR --work DIR [--plant SPEC] [--cycles N] [--est E]
      the identification run: br_simlog's identification trajectory
      (docs/simlog.md) streamed over the link to br_link_sim (the production
      application on the host, behind br_svc, on a pseudo-terminal) with
      bristle-link, and its telemetry recorded into WORK/ident.csv, the
      measured-log CSV the diagnosis reads
  target_chain.py image   --src REPO --machine M.json --dir BUILD
      the image in the loop for machine M (what `make firmware MACHINE=`
      does, for the br_pil_mps2 target only): H-inf gains, configure, build
  target_chain.py circles --pil BR_PIL --before ELF --after ELF --work DIR
                          [--plant SPEC] [--est E] [--duration S] [--md DOC]
      the circle in the loop (br_pil, QEMU's Cortex-M7) on the same plant with
      the image of the nominal machine and the image of the diagnosed one:
      the before/after table in WORK/table.md and WORK/summary.json (the
      nominal image's run also compared with the simulator's bit for bit)

--plant SPEC: the cause planted in the axis's plant (the truth the firmware
does not know), items NAME=VALUES separated by spaces, each a cause option
of the simulator (docs/simlog.md): offset=F, asym=DFC,DFV, ripple=A,P[,PH],
gradient=S, delay=D, drift=R. A run the firmware stopped (a fault) is
printed as a fault and exits 1, never a figure (br_run_report.h)."""
import argparse
import json
import os
import re
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from runs import run_or_exit  # noqa: E402

CAUSES = ("offset", "asym", "ripple", "gradient", "delay", "drift")
SIM_START_S = 10.0  # the wait for br_link_sim's pty


def plant_args(spec):
    """The cause options of SPEC ("offset=2.5 asym=2,15"): a list of argv words."""
    out = []
    for item in spec.split():
        name, sep, val = item.partition("=")
        if not sep or name not in CAUSES or not val:
            sys.exit("target_chain: --plant %r: each item NAME=VALUES, NAME one of %s" % (item, ", ".join(CAUSES)))
        out += ["--" + name, val]
    return out


def run(cmd, **kw):
    return run_or_exit("target_chain", cmd, **kw)


def ident(a):
    os.makedirs(a.work, exist_ok=True)
    traj, log, pty = (os.path.join(a.work, f) for f in ("ident_traj.csv", "ident.csv", "pty.txt"))
    # the excitation: br_simlog's identification run (moves over 0.1 m at 15..50 mm/s, 0.5 m/s^2,
    # dwells), its reference column streamed as it is, from where the axis stands
    run([os.path.join(a.bin, "br_simlog"), "--traj", "ident", "--cycles", str(a.cycles), "--out", traj])
    if os.path.exists(pty):
        os.remove(pty)
    sim_log = open(os.path.join(a.work, "link_sim.txt"), "w")
    sim_cmd = ([os.path.join(a.bin, "br_link_sim"), "--est", a.est, "--speed", "%g" % a.speed, "--pty-path", pty]
               + plant_args(a.plant))
    print("$ " + " ".join(sim_cmd), flush=True)
    sim = subprocess.Popen(sim_cmd, stdout=sim_log, stderr=subprocess.STDOUT)
    try:
        t0 = time.monotonic()
        while not os.path.exists(pty):
            if sim.poll() is not None or time.monotonic() - t0 > SIM_START_S:
                sys.exit("target_chain: br_link_sim did not start (%s)" % sim_log.name)
            time.sleep(0.05)
        port = open(pty).read().strip()
        # an axis slower than real time (--speed < 1) needs its items sent earlier and the tool's
        # deadline, which counts the trajectory in real time, widened by what the pace adds
        slow = a.speed < 1.0
        link = ([sys.executable, "-m", "bristle.link.cli", "--port", port, "--machine", a.machine]
                + (["--timeout", "60"] if slow else []))
        run(link + ["arm"])
        run(link + ["stream", traj, "--relative", "--record", log] + (["--start-after", "1"] if slow else []))
        run(link + ["disarm"])
    finally:
        sim.send_signal(signal.SIGTERM)
        sim.wait(timeout=30)
        sim_log.close()
    end = open(sim_log.name).read().strip().splitlines()[-1]
    print(end)
    # br_link_sim's last line names the last fault latched ("none": the run ended by the disarm above)
    m = re.search(r"last fault latched: (\w+) \(tick (\d+)\)", end)
    if m is None or m.group(1) != "none":
        sys.exit("target_chain: the identification run faulted: " + end)


def image(a):
    abs_m = os.path.realpath(a.machine)
    gen = os.path.join(a.dir, "gen", "bristle_gen", "ctrl")
    os.makedirs(gen, exist_ok=True)
    run([sys.executable, os.path.join(a.src, "firmware/design/synth_hinf.py"), "--machine=" + abs_m,
         "--out=" + os.path.join(gen, "br_hinf_gains.h")], stdout=subprocess.DEVNULL)
    run(["cmake", "--preset", "cm7-release", "-B", a.dir, "-DBR_MACHINE=" + abs_m], cwd=a.src,
        stdout=subprocess.DEVNULL)
    run(["cmake", "--build", a.dir, "--target", "br_pil_mps2", "--", "--quiet"])


ROW = re.compile(r"^(H-inf[^0-9]*?)\s+([0-9.]+)\s+([0-9.e+-]+)\s+([0-9.e+-]+)\s+(\S+)\s+([0-9.]+)\s+(\S+)\s+([0-9.]+)$")


def pil_run(a, elf, tag, compare):
    """One circle in the loop: {rms, max, fhat_err, same, wall} or exit 1 on a fault."""
    cmd = [a.pil, "--image", elf, "--est", a.est, "--timeout", "120"] + plant_args(a.plant)
    if a.duration > 0:
        cmd += ["--duration", str(a.duration)]
    if compare:
        cmd.append("--compare")
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(r.stdout)
    sys.stderr.write(r.stderr)
    open(os.path.join(a.work, "pil_%s.txt" % tag), "w").write(r.stdout + r.stderr)
    if "FAULT" in r.stdout:
        sys.exit("target_chain: the %s image's circle faulted: no result" % tag)
    rows = [ROW.match(line.strip()) for line in r.stdout.splitlines()]
    rows = [m for m in rows if m]
    if r.returncode != 0 or len(rows) != 1:
        sys.exit("target_chain: br_pil failed (exit %d) for the %s image" % (r.returncode, tag))
    m = rows[0]
    return {"image": elf, "contour_rms_m": float(m.group(3)), "max_err_m": float(m.group(4)),
            "fhat_rms_err_N": float(m.group(6)), "same_as_sim": m.group(7), "wall_s": float(m.group(8))}


def circles(a):
    os.makedirs(a.work, exist_ok=True)
    before = pil_run(a, a.before, "before", True)
    after = pil_run(a, a.after, "after", False)
    if before["same_as_sim"] != "yes":
        sys.exit("target_chain: the nominal image's circle is not the simulator's bit for bit")
    change = after["contour_rms_m"] / before["contour_rms_m"] - 1.0
    label = {"none": "H-inf only", "ukf": "H-inf + UKF", "pf": "H-inf + PF"}[a.est]
    lines = ["| image (%s) | contour RMS | max error | F_hat RMS error | wall |" % label,
             "|---|---|---|---|---|"]
    for name, r in (("nominal machine (machines/reference.json)", before),
                    ("diagnosed machine (machine.json)", after)):
        lines.append("| %s | %.3e m | %.3e m | %.3f N | %.1f s |"
                     % (name, r["contour_rms_m"], r["max_err_m"], r["fhat_rms_err_N"], r["wall_s"]))
    lines.append("| change | %+.0f %% | %+.0f %% | | |" % (100 * change,
                                                       100 * (after["max_err_m"] / before["max_err_m"] - 1)))
    table = "\n".join(lines) + "\n"
    print(table)
    open(os.path.join(a.work, "table.md"), "w").write(table)
    summary = {"plant": a.plant, "est": a.est, "duration_s": a.duration, "before": before, "after": after,
               "contour_change": change}
    if a.diagnosis:
        summary["machine"] = json.load(open(a.diagnosis))
    with open(os.path.join(a.work, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    i = sub.add_parser("ident")
    i.add_argument("--bin", required=True, help="the host build's sim/ folder (br_link_sim, br_simlog)")
    i.add_argument("--work", required=True)
    i.add_argument("--machine", default="machines/reference.json", help="the axis's machine file as shipped")
    i.add_argument("--plant", default="offset=2.5")
    i.add_argument("--cycles", type=int, default=3, choices=range(1, 11), metavar="1..10")
    i.add_argument("--est", default="none", choices=("none", "ukf", "pf"))
    i.add_argument("--speed", type=float, default=1.0,
                   help="the simulated axis's periods per wall-clock period (br_link_sim --speed; default 1: real time)")
    g = sub.add_parser("image")
    g.add_argument("--src", default=".")
    g.add_argument("--machine", required=True)
    g.add_argument("--dir", required=True)
    c = sub.add_parser("circles")
    c.add_argument("--pil", required=True)
    c.add_argument("--before", required=True)
    c.add_argument("--after", required=True)
    c.add_argument("--work", required=True)
    c.add_argument("--plant", default="offset=2.5")
    c.add_argument("--est", default="ukf", choices=("none", "ukf", "pf"))
    c.add_argument("--duration", type=float, default=0.0, help="seconds of the circle (0: the thesis's 8 s)")
    c.add_argument("--diagnosis", help="the diagnosis's machine.json, copied into summary.json")
    a = p.parse_args()
    {"ident": ident, "image": image, "circles": circles}[a.cmd](a)


if __name__ == "__main__":
    main()
