# SPDX-License-Identifier: Apache-2.0
"""The reference queue against a host's gaps (docs/modules/refq.md, "Depth
and the host's gaps"): bristle-link streams a 3 s move (10 mm/s after a
raised-cosine start) to br_link_sim (the production service and queue at
real time, --hold-periods HOLD), and the test stops the streaming process
(SIGSTOP, SIGCONT: a descheduled host) for its gaps, the first one second
into the stream. With the queue's 60 items in flight (64 less
bristle-link's margin of 4) the queue holds about 56 items ahead: 56 x SEG
periods of segments of SEG periods, 56 periods of setpoints; the fault
follows fault_periods = HOLD + the braking from the machine's top speed + 1
periods of underrun (the machine file's limits and period: 50 periods on
the reference machine).

Segments of SEG periods:
1. a gap well below the queue's reach: the stream ends, exit 0, no fault;
2. a gap between the queue's reach and the fault: the queue underruns, the
   stream's later items arrive late and bristle-link fails (exit 1,
   "the target refused items"), never a silent stop;
3. a gap beyond both: the target latches ref_underrun and bristle-link
   fails ("faulted").
Setpoints (one period each):
4. three gaps of SP_GAP_PERIODS each, 0.5 s apart, each within the
   queue's reach, the host's loop itself asleep (bristle-link's own
   streaming loop run here, sim/studies/refq_gap.py): no underrun, nothing
   refused, at least one gap taking a third of its periods from the queue,
   and after each gap the queue refills by at least half of what it took
   (the service takes two setpoints a period; with one, the level stayed at
   its lowest, the rest of the items waiting in the byte channel);
5. one gap beyond the fault: ref_underrun latched, bristle-link fails.

Usage: test_refq_gap.py --sim BR_LINK_SIM --machine M.json --work DIR"""
import argparse
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
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.path.join(ROOT, "sim", "studies"))
sys.path.insert(0, os.path.join(ROOT, "python"))
import work_args  # noqa: E402
import refq_gap  # noqa: E402

SEG = 4          # periods per segment
HOLD = 200       # br_link_sim --hold-periods: a wide window between the underrun and the fault
REACH = 56       # items the queue holds ahead of the target's tick (60 in flight, the host's view lags)
SP_GAP_PERIODS = 30  # a setpoint stream's gaps: below the queue's level under load (40 or more measured, refq.md)
GAP_EVERY_S = 0.5


def cases(machine):
    """(SEG or 0 for setpoints, the gaps in ms, what must happen): segments below the queue's reach,
    between it and the fault, beyond the fault; setpoints: three gaps within the reach, one beyond the fault"""
    dt = machine["control"]["period_s"]
    lim = machine["limits"]
    brake = math.ceil(lim["max_speed_mps"] / (lim["max_accel_mps2"] * dt))  # br_refq_fault_periods_min
    fault_after_ms = (HOLD + brake + 1) * dt * 1e3
    reach_ms = REACH * SEG * dt * 1e3
    fault_ms = reach_ms + fault_after_ms
    sp_gap_ms = round(SP_GAP_PERIODS * dt * 1e3)
    sp_fault_ms = REACH * dt * 1e3 + fault_after_ms
    return [(SEG, [60], "clean"), (SEG, [round((reach_ms + fault_ms) / 2)], "underrun"),
            (SEG, [round(fault_ms + 400)], "fault"), (0, [sp_gap_ms] * 3, "refill"),
            (0, [round(sp_fault_ms + 400)], "fault")]


def refills(args, machine, gaps_ms):
    """case 4: bristle-link's streaming loop with its gaps (refq_gap.one_run); 1 when it held"""
    a = argparse.Namespace(bin=os.path.dirname(os.path.abspath(args.sim)), est="none", duration=3.0, segments=0)
    at_s = [1.0 + k * GAP_EVERY_S for k in range(len(gaps_ms))]
    r = refq_gap.one_run(a, machine, gaps_ms[0], at_s)
    per_gap = refq_gap.refill(r)
    print("setpoints, gaps %s ms: underruns %d, fault %s, refused %s; queued before -> lowest -> refilled: %s\n%s"
          % (gaps_ms, r["underruns"], r["fault"], r["refused"], per_gap, r["sim_end"]), flush=True)
    # each gap's loss at least half made good; the gaps took items (a simulated axis late against the
    # wall clock takes fewer than the gap's periods), else the run shows nothing
    return (r["underruns"] == 0 and r["fault"] is None and r["refused"] is None and len(per_gap) == len(gaps_ms)
            and all(low >= 0 and 2 * (up - low) >= before - low for before, low, up in per_gap)
            and max(before - low for before, low, _ in per_gap) >= SP_GAP_PERIODS / 3)


def write_move(path):
    with open(path, "w") as f:
        f.write("t,pos\n")
        p = 0.0
        for k in range(3001):
            t = k * 1e-3
            v = 0.01 * (1.0 - math.cos(math.pi * min(t / 0.2, 1.0))) / 2.0
            f.write("%.4f,%.9e\n" % (t, p))
            p += v * 1e-3


def one(args, move, seg, gaps_ms):
    """(bristle-link's exit status and output, br_link_sim's end line) for one stream with its gaps"""
    pty_file = os.path.join(args.work, "pty.txt")
    if os.path.exists(pty_file):
        os.remove(pty_file)
    sim = subprocess.Popen([args.sim, "--est", "none", "--hold-periods", str(HOLD), "--duration", "60",
                            "--pty-path", pty_file], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    try:
        end = time.monotonic() + 20
        while not os.path.exists(pty_file):
            if sim.poll() is not None or time.monotonic() > end:
                raise AssertionError("br_link_sim did not start")
            time.sleep(0.05)
        link = [sys.executable, "-m", "bristle.link.cli", "--port", open(pty_file).read().strip(),
                "--machine", args.machine]
        r = subprocess.run(link + ["arm"], capture_output=True, text=True, env=env, timeout=60)
        if r.returncode != 0:
            raise AssertionError("arm: " + r.stdout + r.stderr)
        st = subprocess.Popen(link + ["stream", move] + (["--segments", str(seg)] if seg else []),
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
        time.sleep(1.5)  # the stream begins 0.2 s after its start (--start-after): 1 s or more into it
        for k, gap_ms in enumerate(gaps_ms):
            if k:
                time.sleep(GAP_EVERY_S)
            st.send_signal(signal.SIGSTOP)
            time.sleep(gap_ms / 1000.0)
            st.send_signal(signal.SIGCONT)
        out = st.communicate(timeout=60)[0]
    finally:
        sim.send_signal(signal.SIGTERM)
        err = sim.communicate(timeout=20)[1]
    what = "segments of %d" % seg if seg else "setpoints"
    print("%s, gaps %s ms: bristle-link stream -> %d\n%s%s" % (what, gaps_ms, st.returncode, out, err), flush=True)
    return st.returncode, out, err.strip().splitlines()[-1]


def main():
    args = work_args.parse("sim", "machine")
    move = os.path.join(args.work, "move.csv")
    write_move(move)
    with open(args.machine) as f:
        machine = json.load(f)
    fails = []
    for seg, gaps_ms, want in cases(machine):
        what = "segments of %d" % seg if seg else "setpoints"
        if want == "refill":
            ok = refills(args, machine, gaps_ms)
            print("%s: %s, gaps %s ms, expected refills" % ("ok" if ok else "FAIL", what, gaps_ms), flush=True)
            if not ok:
                fails.append((seg, gaps_ms))
            continue
        rc, out, end = one(args, move, seg, gaps_ms)
        fault = re.search(r"last fault latched: (\w+)", end)
        fault = fault.group(1) if fault else "?"
        if want == "clean":
            ok = rc == 0 and fault == "none" and "streamed" in out
        elif want == "underrun":
            ok = rc == 1 and "the target refused items" in out and "late" in out
        else:
            ok = rc == 1 and "faulted" in out and fault == "ref_underrun"
        print("%s: %s, gaps %s ms, expected %s: exit %d, target's last fault %s"
              % ("ok" if ok else "FAIL", what, gaps_ms, want, rc, fault), flush=True)
        if not ok:
            fails.append((seg, gaps_ms))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
