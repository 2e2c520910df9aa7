# SPDX-License-Identifier: Apache-2.0
"""bristle-link: the host's tool for an axis running bristle's firmware over
the link (docs/link.md, "The host tool"), on a serial port or the
simulator's pseudo-terminal (br_link_sim).

  bristle-link --port P --machine M.json status                 the state and the reference queue
  bristle-link --port P --machine M.json arm | disarm | reset   arm, disarm, reset a latched fault
  bristle-link --port P --machine M.json param [NAME [VALUE]]   read (every one without NAME) or write a parameter
  bristle-link --port P --machine M.json stream TRAJ.csv [--segments N] [--relative] [--record LOG.csv] [--plot]
  bristle-link --port P --machine M.json record LOG.csv --seconds S [--plot]
  bristle-link --port P --machine M.json dump CAPTURE.csv [--rearm]
  bristle-link --port P --machine M.json rec-arm                drop the recorder's capture, record again

Exit status: 0, 1 (no answer, a refusal, a fault during a stream, a file
that cannot be read or written), 2 (usage). Outputs are written to a
temporary file beside the destination and renamed onto it at the end
(docs/tools.md); the destination is checked before the run."""
import argparse
import csv
import json
import math
import os
import sys
import tempfile
import time

from . import messages, params
from .record import SAMPLE_NAMES, DumpError, dump_rows, write_measured_log
from .session import LinkError, Session, open_port
from .trajectory import TrajectoryError, check_limits, counts_per_m, item_end, read_trajectory, segments, setpoints

TOOL = "bristle-link"
# a stream keeps this many places of the target's queue free (the items in flight)
QUEUE_MARGIN = 4
# the tool's work between two redraws of the live plot
STEP_S = 0.02


class ToolError(RuntimeError):
    pass


def bounded(lo, hi, kind=float):
    def conv(s):
        try:
            v = kind(s)
        except ValueError:
            raise argparse.ArgumentTypeError("%r: not a number" % s) from None
        if not (math.isfinite(v) and lo <= v <= hi):
            raise argparse.ArgumentTypeError("%s: must be a number in %g .. %g" % (s, lo, hi))
        return v
    return conv


def parser():
    ap = argparse.ArgumentParser(prog=TOOL, description="Talk to an axis over bristle's link (docs/link.md).")
    ap.add_argument("--port", required=True, help="serial port or the simulator's pty (br_link_sim prints it)")
    ap.add_argument("--baud", type=bounded(1200, 4_000_000, int), default=115200, help="1200 .. 4000000 (default 115200)")
    ap.add_argument("--timeout", type=bounded(0.1, 60.0), default=2.0, help="seconds for an answer, 0.1 .. 60 (default 2)")
    ap.add_argument("--machine", required=True, help="the axis's machine file (machines/*.json; the period, units, limits)")
    ap.add_argument("--period", type=bounded(1e-4, 0.01), help="the target's control period, s (default: the machine file's)")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("status", help="the state and the reference queue")
    sub.add_parser("arm", help="arm the axis")
    sub.add_parser("disarm", help="disarm: duty 0, outputs off")
    sub.add_parser("reset", help="reset a latched fault (the axis stays disarmed)")
    p = sub.add_parser("param", help="read or write a run-time parameter")
    p.add_argument("name", nargs="?", choices=[q.name for q in params.PARAMS], metavar="NAME")
    p.add_argument("value", nargs="?", type=bounded(-3.4e38, 3.4e38))
    s = sub.add_parser("stream", help="stream a trajectory file (CSV of t, position m)")
    s.add_argument("traj")
    s.add_argument("--segments", type=bounded(1, 100_000, int), metavar="N",
                   help="cubic segments of N periods (default: one setpoint per period)")
    s.add_argument("--relative", action="store_true", help="positions from where the axis stands")
    s.add_argument("--start-after", type=bounded(0.01, 10.0), default=0.2, help="s after now, 0.01 .. 10 (default 0.2)")
    s.add_argument("--tail", type=bounded(0.0, 60.0), default=0.3, help="s recorded after the end (default 0.3)")
    s.add_argument("--no-last", action="store_true",
                   help="leave the stream open: the target underruns and faults (tests the fault path); "
                        "then the fault is the expected end")
    s.add_argument("--record", metavar="LOG.csv", help="telemetry of the move as the measured-log CSV")
    s.add_argument("--plot", action="store_true", help="show the run live")
    r = sub.add_parser("record", help="record telemetry into the measured-log CSV")
    r.add_argument("out")
    r.add_argument("--seconds", type=bounded(0.01, 3600.0), required=True)
    r.add_argument("--plot", action="store_true", help="show the run live")
    d = sub.add_parser("dump", help="dump the recorder's capture to CSV")
    d.add_argument("out")
    d.add_argument("--rearm", action="store_true", help="re-arm the recorder after a complete dump")
    sub.add_parser("rec-arm", help="drop the recorder's capture and record again")
    return ap


def load_machine(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise ToolError("--machine %s: %s" % (path, e)) from e


def check_out(path, opt):
    """the destination's folder exists and is writable, and the name is not a folder"""
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path) or not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise ToolError("%s %s: cannot write there" % (opt, path))


def write_atomic(path, write):
    """write(tmp_path) into a temporary file beside path, renamed onto it when it returned"""
    fd, tmp = tempfile.mkstemp(prefix="." + os.path.basename(path) + ".tmp-", dir=os.path.dirname(os.path.abspath(path)))
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def fmt_status(s, r):
    line = "tick %d armed %d fault %d fault_tick %d" % (s["tick"], s["armed"], s["fault"], s["fault_tick"])
    if r is not None:
        line += "; queue %d queued %d free state %d, dropped %d late %d underruns %d" % (
            r["queued"], r["free"], r["state"], r["dropped"], r["late"], r["underruns"])
    return line


def cmd_state(sess, args):
    """arm, disarm, reset: the request, then the status it must lead to"""
    want = {"arm": lambda s: s["armed"] == 1,
            "disarm": lambda s: s["armed"] == 0,
            "reset": lambda s: s["armed"] == 1 or s["fault"] <= 1}[args.cmd]
    sess.send({"arm": "arm", "disarm": "disarm", "reset": "fault_reset"}[args.cmd])
    try:
        s = sess.wait_status(args.timeout, want)
    except LinkError:
        s = sess.status
        raise ToolError("%s refused: %s" % (args.cmd, fmt_status(s, sess.ref_status) if s else "no status")) from None
    print(fmt_status(s, sess.ref_status))


def cmd_param(sess, args):
    if args.value is not None and args.name is None:
        raise ToolError("param: a value needs a name")
    names = [args.name] if args.name else [p.name for p in params.PARAMS]
    bad = 0
    for name in names:
        pv = sess.param(params.BY_NAME[name].id, args.value, args.timeout)
        if pv["status"] == 0:
            print("%s = %.9g" % (name, pv["value"]))
        else:
            bad = 1
            print("%s: refused, status %d (docs/link.md, \"Parameters\")" % (name, pv["status"]))
    if bad and args.value is not None:
        raise ToolError("param %s %g: refused" % (args.name, args.value))


def take_rows(sess, first, last):
    return [r for r in sess.tlm if first <= r["tick"] <= last]


def save_log(rows, machine, path):
    try:
        write_atomic(path, lambda tmp: write_measured_log(rows, machine, tmp))
    except DumpError as e:
        raise ToolError("%s: %s" % (path, e)) from e
    print("%s: %d rows" % (path, len(rows)))


def stream_steps(sess, items, kind, stop_tick, no_last, deadline):
    """The stream's work, one step per STEP_S: items sent as the target's
    queue (ref_status: queued + free) has room for them, the reports taken;
    ends at stop_tick, or at a fault (the tail of --no-last: timeout_s after it)."""
    i = j = 0  # the next item to send; the first not over at the target's tick
    base = None
    fault_end = None
    while True:
        end = time.monotonic() + STEP_S
        while time.monotonic() < end:
            sess.poll(0.0005)
            rs, now = sess.ref_status, sess.tick
            if base is None and rs is not None:
                base = (rs["dropped"], rs["late"])
            if rs is not None and base != (rs["dropped"], rs["late"]) and not sess.faults:
                raise ToolError("the target refused items: dropped %d, late %d (was %d, %d)"
                                % (rs["dropped"], rs["late"], *base))
            while j < i and item_end(items[j]) <= now:
                j += 1
            while rs is not None and not sess.faults and i < len(items) and i - j < rs["queued"] + rs["free"] - QUEUE_MARGIN:
                sess.send(kind, **items[i])
                i += 1
            if sess.faults and fault_end is None:
                fault_end = now + (stop_tick - item_end(items[-1]))
            if now is not None and (now >= stop_tick or (fault_end is not None and now >= fault_end)):
                return
        if no_last and time.monotonic() > deadline:
            raise ToolError("no fault came after the stream's end")
        yield


def run_steps(steps, plot):
    if plot is None:
        for _ in steps:
            pass
    else:
        plot.run(steps)


def cmd_stream(sess, args, machine, period_s):
    if args.record:
        check_out(args.record, "--record")
    try:
        t, p = read_trajectory(args.traj)
        check_limits(t, p, machine, args.traj)
    except (OSError, TrajectoryError) as e:
        raise ToolError(str(e)) from e
    sess.collect_tlm = True
    sess.wait("telemetry", lambda: sess.tlm and sess.ref_status, args.timeout)
    s = sess.wait_status(args.timeout)
    if not s["armed"]:
        raise ToolError("the axis is not armed (%s; bristle-link arm)" % fmt_status(s, sess.ref_status))
    last = sess.tlm[-1]
    offset = ((last["ref_counts"] + last["ref_frac"]) / counts_per_m(machine) - p[0]) if args.relative else 0.0
    tick0 = sess.tick + max(1, round(args.start_after / period_s))
    if args.segments:
        kind, items = "segment", segments(t, p, machine, period_s, tick0, args.segments, offset, not args.no_last)
    else:
        kind, items = "setpoint", setpoints(t, p, machine, period_s, tick0, offset, not args.no_last)
    tail = round(args.tail / period_s)
    stop_tick = item_end(items[-1]) + tail
    deadline = time.monotonic() + (stop_tick - sess.tick) * period_s + args.timeout
    plot = None
    if args.plot:
        from .liveplot import LivePlot
        plot = LivePlot(sess, machine)
    run_steps(stream_steps(sess, items, kind, stop_tick, args.no_last, deadline), plot)
    print("streamed %d %ss from tick %d to %d" % (len(items), kind, tick0, item_end(items[-1])))
    if sess.faults:
        f = sess.faults[0]
        print("fault %d at tick %d" % (f["cause"], f["tick"]))
        if args.no_last:
            return
        raise ToolError("the axis faulted during the stream: the run is no result")
    if args.no_last:
        raise ToolError("the stream was left open but no fault came")
    if args.record:
        save_log(take_rows(sess, tick0, stop_tick), machine, args.record)


def cmd_record(sess, args, machine, period_s):
    check_out(args.out, "record")
    sess.collect_tlm = True
    sess.wait("telemetry", lambda: sess.tlm, args.timeout)
    first = sess.tlm[-1]["tick"]
    last = first + round(args.seconds / period_s)

    def steps():
        while sess.tick < last:
            end = time.monotonic() + STEP_S
            while time.monotonic() < end and sess.tick < last:
                sess.poll(0.0005)
            yield

    plot = None
    if args.plot:
        from .liveplot import LivePlot
        plot = LivePlot(sess, machine)
    run_steps(steps(), plot)
    if sess.faults:
        raise ToolError("fault %d at tick %d during the record: the run is no result"
                        % (sess.faults[0]["cause"], sess.faults[0]["tick"]))
    save_log(take_rows(sess, first, last), machine, args.out)


def cmd_dump(sess, args):
    check_out(args.out, "dump")
    sess.collect_dump = True
    sess.send("rec_dump", first=0)
    # the dump goes at the channel's pace: the deadline moves on with each frame
    deadline, n = time.monotonic() + args.timeout, 0
    rec_end = messages.BY_NAME["rec_end"].id
    while not any(fr.id == rec_end for fr in sess.dump[-1:]):
        sess.poll()
        if len(sess.dump) != n:
            n, deadline = len(sess.dump), time.monotonic() + args.timeout
        if time.monotonic() > deadline:
            raise ToolError("dump: no rec_end within %g s of the last frame (%d frames)" % (args.timeout, n))
    try:
        cap = dump_rows(sess.dump)
    except DumpError as e:
        raise ToolError("dump: %s" % e) from e

    def write(tmp):
        with open(tmp, "w", newline="", encoding="utf-8") as f:
            w = csv.writer(f, lineterminator="\n")
            w.writerow(["index", *SAMPLE_NAMES])
            for i, row in enumerate(cap.rows):
                w.writerow([i, *(repr(row[k]) for k in SAMPLE_NAMES)])

    write_atomic(args.out, write)
    print("%s: %d samples, trigger %s at index %d tick %d, missed faults %d"
          % (args.out, len(cap.rows), cap.cause, cap.trigger_index, cap.trigger_tick, cap.missed_faults))
    if args.rearm:
        sess.send("rec_arm")


def run(args):
    machine = load_machine(args.machine)
    period_s = args.period or machine["control"]["period_s"]
    sess = Session(open_port(args.port, args.baud))
    sess.start(args.timeout)
    if args.cmd == "status":
        sess.wait("ref_status", lambda: sess.ref_status, args.timeout)
        print(fmt_status(sess.wait_status(args.timeout), sess.ref_status))
    elif args.cmd in ("arm", "disarm", "reset"):
        cmd_state(sess, args)
    elif args.cmd == "param":
        cmd_param(sess, args)
    elif args.cmd == "stream":
        cmd_stream(sess, args, machine, period_s)
    elif args.cmd == "record":
        cmd_record(sess, args, machine, period_s)
    elif args.cmd == "dump":
        cmd_dump(sess, args)
    elif args.cmd == "rec-arm":
        sess.send("rec_arm")
    # what was sent leaves before the port closes
    sess.port.flush()


def main(argv=None):
    args = parser().parse_args(argv)
    try:
        run(args)
    except (ToolError, LinkError, OSError) as e:
        print("%s: %s" % (TOOL, e), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
