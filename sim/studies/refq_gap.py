#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The reference queue against the host's gaps (docs/modules/refq.md, "Depth
and the host's gaps"; docs/link.md): br_link_sim (the production service and
queue, on a pseudo-terminal, at real time) armed and fed a setpoint stream by
bristle-link's own streaming loop (bristle.link.cli.stream_steps), whose
host stops for GAP ms (nothing sent, as a descheduled process) at each of
--at S seconds after the stream's start. Per run it prints the target's
queue level (ref_status.queued) before and after the gaps, per gap the
level before it, the lowest after it and the highest after that (the
refill: the service takes two setpoints a period), the underruns
and the fault the target reported, and the largest wall-clock gap between
two turns of the host's loop (its scheduling gaps on this machine).

  refq_gap.py --bin BUILD/sim [--gaps-ms 0,40,...] [--at 1.0[,2.0...]] [--segments N]
              [--machine machines/reference.json] [--duration S] [--est none|ukf|pf]

Exit 0; a run whose host or target failed otherwise is printed as such."""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from bristle.link import cli
from bristle.link.session import Session, open_port
from bristle.link.trajectory import item_end, segments, setpoints

SIM_START_S = 20.0


def trajectory(duration_s):
    """a constant-speed move of 10 mm/s (within every machine file's limits) after a raised-cosine start"""
    t = np.linspace(0.0, duration_s, int(duration_s * 1000) + 1)
    ramp = np.minimum(t / 0.2, 1.0)
    v = 0.01 * (1.0 - np.cos(np.pi * ramp)) / 2.0
    p = np.concatenate(([0.0], np.cumsum((v[1:] + v[:-1]) / 2.0 * np.diff(t))))
    return t, p


def one_run(a, machine, gap_ms, at_s):
    """{levels: [(tick, queued)], before/after, underruns, fault, host_gap_max_s, refused} of one stream"""
    work = tempfile.mkdtemp(prefix="refq_gap_")
    pty = os.path.join(work, "pty.txt")
    sim = subprocess.Popen([os.path.join(a.bin, "br_link_sim"), "--est", a.est, "--status-periods", "5",
                            "--tlm-every", "10", "--pty-path", pty], stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True)
    out = {"gap_ms": gap_ms, "levels": [], "refused": None, "gap_ticks": []}
    try:
        t0 = time.monotonic()
        while not os.path.exists(pty):
            if sim.poll() is not None or time.monotonic() - t0 > SIM_START_S:
                raise RuntimeError("br_link_sim did not start")
            time.sleep(0.02)
        sess = Session(open_port(open(pty).read().strip(), 921600))
        sess.send("arm")
        sess.wait_status(2.0, lambda s: s["armed"] == 1)
        sess.wait("ref_status", lambda: sess.ref_status, 2.0)
        period_s = machine["control"]["period_s"]
        t, p = trajectory(a.duration)
        tick0 = sess.tick + 200
        if a.segments:
            kind, items = "segment", segments(t, p, machine, period_s, tick0, a.segments, 0.0, True)
        else:
            kind, items = "setpoint", setpoints(t, p, machine, period_s, tick0, 0.0, True)
        stop_tick = item_end(items[-1]) + 50
        steps = cli.stream_steps(sess, items, kind, stop_tick, False, time.monotonic() + 3600)
        gaps = sorted(tick0 + round(s / period_s) for s in at_s)
        last, gap_max = time.monotonic(), 0.0
        try:
            for _ in steps:
                now = time.monotonic()
                gap_max, last = max(gap_max, now - last - cli.STEP_S), now
                rs = sess.ref_status
                out["levels"].append((sess.tick, rs["queued"], rs["underruns"], rs["state"]))
                if gaps and sess.tick >= gaps[0]:
                    gaps.pop(0)
                    out["gap_ticks"].append(sess.tick)
                    time.sleep(gap_ms / 1000.0)  # the host stopped: nothing read, nothing sent
                    sess.poll(0.0)  # the reports sent during the gap: the level at its end, before any refill
                    rs = sess.ref_status
                    out["levels"].append((sess.tick, rs["queued"], rs["underruns"], rs["state"]))
                    last = time.monotonic()
        except cli.ToolError as e:
            out["refused"] = str(e)
        rs = sess.ref_status
        out["underruns"] = rs["underruns"]
        out["fault"] = sess.faults[0] if sess.faults else None
        out["host_gap_max_s"] = gap_max
        out["tick0"] = tick0
        out["end_tick"] = item_end(items[-1])
        sess.send("disarm")
    finally:
        sim.terminate()
        _, err = sim.communicate(timeout=30)
        out["sim_end"] = err.strip().splitlines()[-1] if err.strip() else ""
    return out


def refill(r):
    """per gap (the host's tick at its start): the queue's level last reported before it, the lowest
    after it, and the highest after that lowest, until the next gap (or 100 periods before the
    stream's end, where the queue empties)"""
    out = []
    ends = r["gap_ticks"][1:] + [r["end_tick"] - 100]
    for g, e in zip(r["gap_ticks"], ends):
        before = [q for tk, q, _, _ in r["levels"] if tk < g]
        after = [(tk, q) for tk, q, _, _ in r["levels"] if g <= tk < e]
        if not before or not after:
            out.append((-1, -1, -1))
            continue
        low_tick, low = min(after, key=lambda x: x[1])
        out.append((before[-1], low, max(q for tk, q in after if tk >= low_tick)))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", required=True)
    ap.add_argument("--machine", default="machines/reference.json")
    ap.add_argument("--gaps-ms", default="0,40,80,120,160")
    ap.add_argument("--at", default="1.0", help="seconds after the stream's start of each gap, comma-separated")
    ap.add_argument("--segments", type=int, default=0, help="cubic segments of N periods (default setpoints)")
    ap.add_argument("--duration", type=float, default=3.0, help="the stream's length, s")
    ap.add_argument("--est", default="none")
    ap.add_argument("--trace", action="store_true", help="print each step's (tick - tick0):queued")
    a = ap.parse_args()
    with open(a.machine) as f:
        machine = json.load(f)
    at_s = [float(x) for x in a.at.split(",")]
    print("gap_ms  gaps  queued_min_before  queued_min_after  underruns  fault  host_gap_max_ms  refused")
    for g in (float(x) for x in a.gaps_ms.split(",")):
        r = one_run(a, machine, g, at_s)
        first = r["tick0"] + round(at_s[0] / machine["control"]["period_s"])
        before = min((q for tk, q, _, _ in r["levels"] if r["tick0"] <= tk < first), default=-1)
        # the levels until the stream's last items (the queue empties at its end)
        after = min((q for tk, q, _, _ in r["levels"] if first <= tk < r["end_tick"] - 100), default=-1)
        if a.trace:
            print("        " + " ".join("%d:%d" % (tk - r["tick0"], q) for tk, q, _, _ in r["levels"]))
        fault = "cause %d tick %d" % (r["fault"]["cause"], r["fault"]["tick"]) if r["fault"] else "none"
        print("%6.0f  %4d  %17d  %16d  %9d  %s  %15.1f  %s" % (g, len(at_s), before, after, r["underruns"], fault,
                                                               1e3 * r["host_gap_max_s"], r["refused"] or "-"))
        print("        queued before -> lowest -> refilled, per gap: "
              + ", ".join("%d -> %d -> %d" % x for x in refill(r)))
        print("        br_link_sim: " + r["sim_end"], flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
