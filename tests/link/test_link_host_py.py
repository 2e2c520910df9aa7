# SPDX-License-Identifier: Apache-2.0
"""bristle-link's parts (docs/link.md, "The host tool"), without a target:
trajectories as setpoints and segments (the segments' cubics through the
file's positions and speeds, continuous from one to the next) and the file's
refusals; the session's decoding of a report stream cut into random pieces
with garbage between the frames (a property over 300 seeded streams); the
session's start against a target whose last accepted seq is any value; the
live plot's series; the command line's bounds and its atomic outputs."""
import io
import json
import math
import os
import random
import sys
import tempfile
import tomllib
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "python"))

from bristle.link import cli, messages, params  # noqa: E402
from bristle.link.frame import VERSION, Decoder, encode_frame  # noqa: E402
from bristle.link.session import LinkError, Session  # noqa: E402
from bristle.link.trajectory import (FLAG_LAST, TrajectoryError, check_limits, counts_per_m,  # noqa: E402
                                     read_trajectory, segments, setpoints)

with open(os.path.join(ROOT, "machines", "reference.json")) as _f:
    MACHINE = json.load(_f)
PERIOD = MACHINE["control"]["period_s"]


def write(text):
    fd, path = tempfile.mkstemp(suffix=".csv")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    return path


def move_file(n=501, dist=0.003, dur=0.5):
    rows = ["t,pos"] + ["%.6f,%.12e" % (k * dur / (n - 1), 0.5 * dist * (1 - math.cos(math.pi * k / (n - 1))))
                        for k in range(n)]
    return write("\n".join(rows) + "\n")


class Trajectory(unittest.TestCase):
    def test_segments_through_the_file(self):
        t, p = read_trajectory(move_file())
        cpm = counts_per_m(MACHINE)
        segs = segments(t, p, MACHINE, PERIOD, 100, 40, offset_m=0.01)
        self.assertEqual(segs[0]["tick"], 100)
        self.assertEqual(segs[-1]["flags"], FLAG_LAST)
        self.assertTrue(all(s["flags"] == 0 for s in segs[:-1]))
        for a, b in zip(segs, segs[1:]):
            self.assertEqual(a["tick"] + a["periods"], b["tick"])  # no gap, no overlap (refq's order rule)
            T = a["periods"] * PERIOD
            # refq-2 at the segment's end: the next one's start, and the file there
            end = a["counts"] + a["frac"] + T * (a["v_cps"] + T * (a["a_cps2"] / 2 + T * a["j_cps3"] / 6))
            v_end = a["v_cps"] + T * (a["a_cps2"] + T * a["j_cps3"] / 2)
            self.assertAlmostEqual(end, b["counts"] + b["frac"], delta=1e-3)
            want = (np.interp((b["tick"] - 100) * PERIOD, t, p) + 0.01) * cpm
            self.assertAlmostEqual(end, want, delta=1e-3)
            self.assertAlmostEqual(v_end, b["v_cps"], delta=1e-6 * cpm + 1e-3 * abs(b["v_cps"]))
        self.assertEqual(sum(s["periods"] for s in segs), 500)
        for s in segs:
            messages.pack("segment", **s)  # every field in its type's range

    def test_setpoints(self):
        t, p = read_trajectory(move_file())
        sp = setpoints(t, p, MACHINE, PERIOD, 7)
        self.assertEqual(len(sp), 501)
        self.assertEqual([s["tick"] for s in sp[:3]], [7, 8, 9])
        self.assertEqual(sp[-1]["flags"], FLAG_LAST)
        cpm = counts_per_m(MACHINE)
        for s, pk in zip(sp, p):
            self.assertTrue(0.0 <= s["frac"] < 1.0)
            self.assertAlmostEqual(s["counts"] + s["frac"], pk * cpm, delta=1e-3)
            messages.pack("setpoint", **s)
        self.assertEqual(setpoints(t, p, MACHINE, PERIOD, 7, last=False)[-1]["flags"], 0)

    def test_refusals(self):
        for text, what in [("", "empty"), ("x,pos\n0,0\n1,0\n", "header"), ("t,pos\n0,0\n", "two rows"),
                           ("t,pos\n0,0\n0,1e-3\n", "not after"), ("t,pos\n0,0\n1,nan\n", "not finite"),
                           ("t,pos\n0,0\n1,abc\n", "not a number"), ("t,pos\n0,0\n1\n", "fields"),
                           ("t,pos\n0,0\n4000,0\n", "long")]:
            with self.subTest(what=what), self.assertRaisesRegex(TrajectoryError, what):
                read_trajectory(write(text))
        vmax, amax = MACHINE["limits"]["max_speed_mps"], MACHINE["limits"]["max_accel_mps2"]
        t = np.array([0.0, 1.0])
        with self.assertRaisesRegex(TrajectoryError, "speed"):
            check_limits(t, np.array([0.0, 1.1 * vmax]), MACHINE)
        check_limits(t, np.array([0.0, vmax]), MACHINE)
        t3 = np.array([0.0, 0.01, 0.02])  # a = p2 / 0.01^2, at a speed below the limit
        with self.assertRaisesRegex(TrajectoryError, "acceleration"):
            check_limits(t3, np.array([0.0, 0.0, 1.1 * amax * 1e-4]), MACHINE)
        check_limits(t3, np.array([0.0, 0.0, 0.9 * amax * 1e-4]), MACHINE)


class Port:
    """A fake port: read() hands out the stream in the pieces given; write()
    decodes the host's frames as a target with last accepted seq `last`
    would, and answers an accepted param_read with a param_value and an
    accepted hello with its hello_reply (protocol `version`)."""

    def __init__(self, pieces=(), last=None, version=VERSION):
        self.pieces = list(pieces)
        self.version = version
        self.target = Decoder()
        self.target.last_seq = last
        self.accepted = []
        self.out_seq = 0

    @property
    def in_waiting(self):
        return len(self.pieces[0]) if self.pieces else 0

    def read(self, n):
        return self.pieces.pop(0) if self.pieces else b""

    def write(self, b):
        for fr in self.target.feed(b):
            self.accepted.append(fr)
            name, v = messages.unpack(fr.id, fr.payload)
            if name == "param_read":
                self.pieces.append(encode_frame(messages.BY_NAME["param_value"].id, self.out_seq,
                                                messages.pack("param_value", param=v["param"], value=0.0, status=0)))
                self.out_seq += 1
            elif name == "hello":
                self.pieces.append(encode_frame(messages.BY_NAME["hello_reply"].id, self.out_seq,
                                                messages.pack("hello_reply", session=v["session"], version=self.version,
                                                              fw_version=0x000102, machine=b"reference")))
                self.out_seq += 1

    def flush(self):
        pass


def report(name, seq, **v):
    return encode_frame(messages.BY_NAME[name].id, seq, messages.pack(name, **v))


def sample(tick, rng):
    return {"tick": tick, "counts": rng.randrange(-2 ** 31, 2 ** 31), "ref_counts": rng.randrange(-2 ** 31, 2 ** 31),
            "ref_frac": float(np.float32(rng.random())), "duty": float(np.float32(rng.uniform(-1, 1))),
            "F_hat_N": float(np.float32(rng.uniform(-50, 50))), "n_outliers": rng.randrange(65536),
            "status": rng.randrange(-128, 128), "fault": rng.randrange(256), "flags": rng.randrange(256)}


class SessionDecoding(unittest.TestCase):
    def test_random_pieces_and_garbage(self):
        """Property: whatever the pieces and the garbage between frames (never
        a 0x00 inside a frame), the session takes every report once, in order."""
        for seed in range(300):
            rng = random.Random(seed)
            stream, sent, seq = bytearray(), [], rng.randrange(65536)
            last_status, faults = None, []
            for k in range(rng.randrange(1, 40)):
                kind = rng.random()
                if kind < 0.6:
                    s = sample(1000 + k, rng)
                    sent.append(s)
                    stream += report("tlm_sample", seq, **s)
                elif kind < 0.8:
                    last_status = {"tick": 1000 + k, "fault_tick": rng.randrange(2 ** 32), "armed": rng.randrange(2),
                                   "fault": rng.randrange(256)}
                    stream += report("status", seq, **last_status)
                else:
                    faults.append({"cause": rng.randrange(256), "tick": rng.randrange(2 ** 32)})
                    stream += report("fault", seq, **faults[-1])
                seq = (seq + rng.randrange(1, 3)) & 0xFFFF  # a frame lost on the way: a gap in seq
                if rng.random() < 0.3:
                    stream += bytes(rng.randrange(1, 256) for _ in range(rng.randrange(1, 80)))
            cuts = sorted(rng.sample(range(1, len(stream)), min(len(stream) - 1, rng.randrange(0, 60))))
            pieces = [bytes(stream[a:b]) for a, b in zip([0] + cuts, cuts + [len(stream)])]
            sess = Session(Port(pieces))
            sess.collect_tlm = True
            while sess.port.pieces:
                sess.poll(0.0)
            self.assertEqual(sess.tlm, sent, "seed %d" % seed)
            self.assertEqual(sess.status, last_status, "seed %d" % seed)
            self.assertEqual(sess.faults, faults, "seed %d" % seed)
            self.assertEqual(sess.dec.counters["replayed"], 0)

    def test_start_whatever_the_targets_last_seq(self):
        """The hello opens the session whatever seq the target accepted last
        (the host starts from 0 again, as after a restart), and every frame
        after it is accepted; the reply is kept."""
        arm = messages.BY_NAME["arm"].id
        for last in list(range(0, 65536, 331)) + [None, 0xFFFF, 0x5555, 0xAAAA, 0x7FFF, 0x8000]:
            port = Port(last=last)
            sess = Session(port, start_seq=0)
            hello = sess.start(timeout_s=0.5, session=7)
            self.assertEqual((hello["session"], hello["machine"].rstrip(b"\0")), (7, b"reference"))
            sess.send("arm")
            self.assertEqual([f.id for f in port.accepted], [messages.BY_NAME["hello"].id, arm], "last seq %s" % last)

    def test_start_refuses_another_version(self):
        with self.assertRaises(LinkError):
            Session(Port(version=VERSION + 1)).start(timeout_s=0.5)

    def test_replay_within_a_session_dropped(self):
        """A frame repeated after the hello, or the hello itself repeated,
        does not pass: the session opens the window, it does not remove it."""
        port = Port(last=0x1234)
        sess = Session(port, start_seq=0)
        sess.start(timeout_s=0.5, session=9)
        hello_wire = encode_frame(messages.BY_NAME["hello"].id, 0, messages.pack("hello", session=9))
        arm_wire = encode_frame(messages.BY_NAME["arm"].id, 1, b"")
        port.write(arm_wire)
        port.write(arm_wire)
        port.write(hello_wire)
        self.assertEqual(len(port.accepted), 2)
        self.assertEqual(port.target.counters["replayed"], 2)


class LivePlotSeries(unittest.TestCase):
    def test_series(self):
        import matplotlib
        matplotlib.use("Agg")
        from bristle.link.liveplot import LivePlot
        sess = Session(Port())
        rng = random.Random(1)
        sess.tlm = [dict(sample(k, rng), counts=1000, ref_counts=1002, ref_frac=0.5, duty=0.25)
                    for k in range(0, 8000)]
        lp = LivePlot(sess, MACHINE)
        lp.update()
        t, e, f = (lp.l_e.get_xdata(), lp.l_e.get_ydata(), lp.l_f.get_ydata())
        n_win = int(round(5.0 / PERIOD)) + 1  # the window, WINDOW_S
        self.assertEqual(len(t), n_win)
        m_per_count = MACHINE["mechanics"]["lead_m_per_rev"] / MACHINE["encoder"]["counts_per_rev"]
        self.assertAlmostEqual(e[0], 2.0 * m_per_count, delta=1e-15)
        L = MACHINE["mechanics"]["lead_m_per_rev"] / (2 * math.pi)
        self.assertAlmostEqual(f[0], 0.25 * MACHINE["amplifier"]["torque_per_duty_Nm"] / L)


class CommandLine(unittest.TestCase):
    def usage(self, *argv):
        err = io.StringIO()
        stderr, sys.stderr = sys.stderr, err
        try:
            with self.assertRaises(SystemExit) as cm:
                cli.parser().parse_args(list(argv))
        finally:
            sys.stderr = stderr
        self.assertEqual(cm.exception.code, 2)
        return err.getvalue()

    def test_bounds(self):
        base = ["--port", "/dev/null", "--machine", "m.json"]
        self.assertIn("--baud", self.usage(*base, "--baud", "5", "status"))
        self.assertIn("--timeout", self.usage(*base, "--timeout", "nan", "status"))
        self.assertIn("NAME", self.usage(*base, "param", "no_such"))
        self.assertIn("--seconds", self.usage(*base, "record", "x.csv"))
        self.assertIn("--segments", self.usage(*base, "stream", "x.csv", "--segments", "0"))
        self.assertIn("--machine", self.usage("--port", "/dev/null", "status"))
        names = {p.name for p in params.PARAMS}
        self.assertEqual(set(cli.parser()._subparsers._group_actions[0].choices["param"]
                             ._actions[1].choices), names)

    def test_outputs_atomic(self):
        d = tempfile.mkdtemp()
        path = os.path.join(d, "out.csv")
        with open(path, "w") as f:
            f.write("old")

        def fails(tmp):
            with open(tmp, "w") as f:
                f.write("partial")
            raise cli.ToolError("failed half way")

        with self.assertRaises(cli.ToolError):
            cli.write_atomic(path, fails)
        with open(path) as f:
            self.assertEqual(f.read(), "old")
        self.assertEqual(os.listdir(d), ["out.csv"])
        with self.assertRaises(cli.ToolError):
            cli.check_out(d, "dump")  # a folder
        with self.assertRaises(cli.ToolError):
            cli.check_out(os.path.join(d, "no", "x.csv"), "dump")

    def test_console_script(self):
        with open(os.path.join(ROOT, "pyproject.toml"), "rb") as f:
            proj = tomllib.load(f)
        self.assertEqual(proj["project"]["scripts"]["bristle-link"], "bristle.link.cli:main")
        self.assertTrue(any(d.startswith("pyserial") for d in proj["project"]["dependencies"]))


if __name__ == "__main__":
    unittest.main()
