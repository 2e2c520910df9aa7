# SPDX-License-Identifier: Apache-2.0
"""The reference queue against a host's gap (docs/modules/refq.md, "Depth
and the host's gaps"): bristle-link streams a 3 s move (10 mm/s after a
raised-cosine start) as cubic segments of SEG periods to br_link_sim (the
production service and queue at real time, --hold-periods HOLD), and the
test stops the streaming process (SIGSTOP, SIGCONT: a descheduled host) for
a gap one second into the stream. With the queue's 60 items in flight
(64 less bristle-link's margin of 4) the queue holds about 56 x SEG periods
ahead; the fault follows fault_periods = HOLD + the braking from the
machine's top speed + 1 periods of underrun (the machine file's limits and
period: 50 periods on the reference machine).

1. a gap well below the queue's reach: the stream ends, exit 0, no fault;
2. a gap between the queue's reach and the fault: the queue underruns, the
   stream's later items arrive late and bristle-link fails (exit 1,
   "the target refused items"), never a silent stop;
3. a gap beyond both: the target latches ref_underrun and bristle-link
   fails ("faulted").

Usage: test_refq_gap.py --sim BR_LINK_SIM --machine M.json --work DIR"""
import json
import math
import os
import re
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import work_args  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))

SEG = 4          # periods per segment
HOLD = 200       # br_link_sim --hold-periods: a wide window between the underrun and the fault


def cases(machine):
    """(gap ms, what must happen): below the queue's reach, between it and the fault, beyond the fault"""
    dt = machine["control"]["period_s"]
    lim = machine["limits"]
    brake = math.ceil(lim["max_speed_mps"] / (lim["max_accel_mps2"] * dt))  # br_refq_fault_periods_min
    reach_ms = 56 * SEG * dt * 1e3
    fault_ms = reach_ms + (HOLD + brake + 1) * dt * 1e3
    return [(60, "clean"), (round((reach_ms + fault_ms) / 2), "underrun"), (round(fault_ms + 400), "fault")]


def write_move(path):
    with open(path, "w") as f:
        f.write("t,pos\n")
        p = 0.0
        for k in range(3001):
            t = k * 1e-3
            v = 0.01 * (1.0 - math.cos(math.pi * min(t / 0.2, 1.0))) / 2.0
            f.write("%.4f,%.9e\n" % (t, p))
            p += v * 1e-3


def one(args, move, gap_ms):
    """(bristle-link's exit status and output, br_link_sim's end line) for one stream with a gap"""
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
        st = subprocess.Popen(link + ["stream", move, "--segments", str(SEG)], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, env=env)
        time.sleep(1.5)  # the stream begins 0.2 s after its start (--start-after): 1 s or more into it
        st.send_signal(signal.SIGSTOP)
        time.sleep(gap_ms / 1000.0)
        st.send_signal(signal.SIGCONT)
        out = st.communicate(timeout=60)[0]
    finally:
        sim.send_signal(signal.SIGTERM)
        err = sim.communicate(timeout=20)[1]
    print("gap %d ms: bristle-link stream -> %d\n%s%s" % (gap_ms, st.returncode, out, err), flush=True)
    return st.returncode, out, err.strip().splitlines()[-1]


def main():
    args = work_args.parse("sim", "machine")
    move = os.path.join(args.work, "move.csv")
    write_move(move)
    with open(args.machine) as f:
        machine = json.load(f)
    fails = []
    for gap_ms, want in cases(machine):
        rc, out, end = one(args, move, gap_ms)
        fault = re.search(r"last fault latched: (\w+)", end)
        fault = fault.group(1) if fault else "?"
        if want == "clean":
            ok = rc == 0 and fault == "none" and "streamed" in out
        elif want == "underrun":
            ok = rc == 1 and "the target refused items" in out and "late" in out
        else:
            ok = rc == 1 and "faulted" in out and fault == "ref_underrun"
        print("%s: gap %d ms, expected %s: exit %d, target's last fault %s" % ("ok" if ok else "FAIL", gap_ms, want,
                                                                               rc, fault), flush=True)
        if not ok:
            fails.append(gap_ms)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
