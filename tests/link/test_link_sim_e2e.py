# SPDX-License-Identifier: Apache-2.0
"""The link end to end (docs/link.md, "The host tool"): bristle-link drives
the simulator's binding (br_link_sim: the production application on the
plant, behind br_svc, br_tlm and br_rec, on a pseudo-terminal, at wall-clock
pace), each step a separate invocation of the tool as a user would run it:

1. the axis starts disarmed (status armed 0, fault 1 DISARMED);
2. a parameter written while disarmed is taken; once armed, an at-the-arm
   parameter is refused (exit 1, status BR_E_STATE) and a live one taken;
3. a short move streamed as setpoints, its telemetry recorded into the
   measured-log CSV: the diagnosis's reader (bristle.diagnose.logreader)
   accepts it, the axis moved the move's distance and followed it within the
   machine file's max_following_error_m;
4. a stream of segments left open: the target underruns, brakes and faults;
   the tool reports the fault's tick; the recorder's dump holds that tick,
   the fault latched in it and not in the sample before;
5. reset and arm again are accepted.

Usage: test_link_sim_e2e.py --sim BR_LINK_SIM --machine machines/reference.json --work DIR"""
import csv
import json
import math
import os
import re
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "python"))

from bristle.diagnose.logreader import read_log  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import work_args  # noqa: E402

MOVE_M = 0.004   # the move: 4 mm in MOVE_S (a raised cosine), then held
MOVE_S = 0.6
HOLD_S = 0.6


def tool(args, *a, ok=True):
    """one bristle-link invocation: (exit status, stdout)"""
    # answers within 10 s: the simulated axis runs at a quarter of the wall-clock pace (main)
    cmd = [sys.executable, "-m", "bristle.link.cli", "--port", args.port, "--machine", args.machine,
           "--timeout", "10", *a]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=60,
                       env=dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python")))
    print("$ bristle-link", " ".join(a), "->", r.returncode, "\n" + r.stdout + r.stderr, flush=True)
    if ok is not None and (r.returncode == 0) != ok:
        raise AssertionError("bristle-link %s: exit %d, expected %s" % (" ".join(a), r.returncode, "0" if ok else "1"))
    return r.returncode, r.stdout


def write_move(path):
    with open(path, "w") as f:
        f.write("t,pos\n")
        for k in range(int((MOVE_S + HOLD_S) / 1e-3) + 1):
            t = k * 1e-3
            f.write("%.4f,%.9e\n" % (t, 0.5 * MOVE_M * (1.0 - math.cos(math.pi * min(t, MOVE_S) / MOVE_S))))


def check(cond, what):
    if not cond:
        raise AssertionError(what)
    print("ok:", what, flush=True)


def main():
    args = work_args.parse("sim", "machine", fresh=False)
    with open(args.machine) as f:
        machine = json.load(f)
    pty_file = os.path.join(args.work, "pty.txt")
    if os.path.exists(pty_file):
        os.remove(pty_file)
    # a quarter of the wall-clock pace: the host (Python, on a shared CI machine) keeps ahead of
    # the queue; the protocol, not the host's speed, is what this test checks
    sim = subprocess.Popen([args.sim, "--est", "ukf", "--speed", "0.25", "--duration", "60", "--pty-path", pty_file],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        end = time.monotonic() + 20
        while not os.path.exists(pty_file):
            if sim.poll() is not None or time.monotonic() > end:
                raise AssertionError("br_link_sim did not start: " + sim.stderr.read())
            time.sleep(0.05)
        with open(pty_file) as f:
            args.port = f.read().strip()
        run(args, machine)
    finally:
        sim.send_signal(signal.SIGTERM)
        err = sim.communicate(timeout=20)[1]
        print(err, flush=True)
    check(sim.returncode == 0, "br_link_sim ended cleanly on SIGTERM")
    check(re.search(r" 0 bad crc,", err) is not None, "the target saw no frame with a bad CRC")
    print("PASS")


def run(args, machine):
    _, out = tool(args, "status")
    check(re.search(r"armed 0 fault 1 ", out), "starts disarmed (fault 1: DISARMED)")
    _, out = tool(args, "param", "r_counts2", "2")
    check("r_counts2 = 2" in out, "an at-the-arm parameter written while disarmed")
    tool(args, "arm")
    _, out = tool(args, "param", "r_counts2", "3", ok=False)
    check("status -5" in out, "refused while armed (BR_E_STATE)")
    _, out = tool(args, "param", "r_counts2")
    check("r_counts2 = 2" in out, "the refused write changed nothing")
    _, out = tool(args, "param", "comp_ahead_periods", "1")
    check("comp_ahead_periods = 1" in out, "a live parameter written while armed")

    move, log = os.path.join(args.work, "move.csv"), os.path.join(args.work, "log.csv")
    write_move(move)
    if os.path.exists(log):
        os.remove(log)
    tool(args, "stream", move, "--relative", "--record", log)
    lg = read_log(log)
    check(len(lg.t) >= 1000 and abs(lg.dt - machine["control"]["period_s"]) < 1e-12,
          "the diagnosis's reader takes the log (%d rows at the machine's period)" % len(lg.t))
    moved = lg.pos[-1] - lg.pos[0]
    check(abs(moved - MOVE_M) < 0.01 * MOVE_M, "the axis moved %.6g m of %g" % (moved, MOVE_M))
    follow = float(max(abs(lg.ref - lg.pos)))
    check(follow < machine["limits"]["max_following_error_m"],
          "followed within %.3g m (machine limit %g)" % (follow, machine["limits"]["max_following_error_m"]))

    _, out = tool(args, "stream", move, "--relative", "--segments", "50", "--no-last")
    m = re.search(r"fault (\d+) at tick (\d+)", out)
    check(m is not None, "the open stream ended in a fault")
    fault_tick = int(m.group(2))
    cap = os.path.join(args.work, "capture.csv")
    # the capture is complete once the post-trigger samples are in
    end = time.monotonic() + 20
    while tool(args, "dump", cap, ok=None)[0] != 0:
        if time.monotonic() > end:
            raise AssertionError("no complete capture")
        time.sleep(0.3)
    with open(cap) as f:
        rows = list(csv.DictReader(f))
    at = [i for i, r in enumerate(rows) if int(r["tick"]) == fault_tick]
    check(len(at) == 1 and int(rows[at[0]]["fault"]) == int(m.group(1)) and int(rows[at[0] - 1]["fault"]) == 0,
          "the dump holds the fault's tick %d, latched there" % fault_tick)
    tool(args, "reset")
    tool(args, "arm")


if __name__ == "__main__":
    main()
