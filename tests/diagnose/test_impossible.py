# SPDX-License-Identifier: Apache-2.0
"""Samples no axis could produce (python/bristle/diagnose/plausible.py,
docs/diagnose.md "Impossible samples"):

- the audit's case end to end: one force cell of 1e4 N in a br_simlog log
  (the reference axis exerts 502 N) leaves the verdict and the nominal
  parameters of the clean log, and the report names the line;
- on constructed logs: a position spike (also on the first sample) repaired,
  a force beyond the limit of the given machine file but not of another,
  a permanent position jump, a long run and too many impossible rows refused
  with the line named.

Usage: test_impossible.py --simlog BIN --work DIR"""
import json
import math
import os
import subprocess
import sys
import unittest

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import work_args  # noqa: E402
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import logreader, machinejson, plausible  # noqa: E402

mach = machinejson._loader()

ARGS = None
BAD_LINE = 5001


def env():
    return dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")


def diagnose(log, out, *extra):
    r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", log, "--out", out,
                        "--no-plots", "--quiet", *extra], env=env(), capture_output=True, text=True)
    return r


def write_csv(path, t, ref, pos, force):
    with open(path, "w") as f:
        f.write("t,ref,pos,force\n")
        for row in zip(t, ref, pos, force):
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def force_limit(path):
    m = mach.load(path)
    return 2 * math.pi * m["control"]["torque_limit_Nm"] / m["mechanics"]["lead_m_per_rev"]


class Constructed(unittest.TestCase):
    """plausible.check on small logs written here (a slow sine move)."""

    def make(self, name, edit=None):
        n, dt = 3000, 1e-3
        t = np.arange(n) * dt
        pos = 0.01 * np.sin(2 * np.pi * 0.5 * t)
        force = 20.0 * np.cos(2 * np.pi * 0.5 * t) + 1.0
        if edit:
            edit(pos, force)
        path = os.path.join(ARGS.work, name + ".csv")
        write_csv(path, t, pos, pos, force)
        return path

    def test_clean_log_untouched(self):
        lg = logreader.read_log(self.make("clean"))
        before = lg.pos.copy(), lg.force.copy()
        self.assertIsNone(plausible.check(lg))
        self.assertTrue(np.array_equal(lg.pos, before[0]) and np.array_equal(lg.force, before[1]))

    def test_fast_motion_kept(self):
        """2.5 times max_speed_mps (what the reference plant reached with a dead
        time in the hidden-cause suite) is a possible motion"""
        v = 2.5 * mach.load(mach.REFERENCE_MACHINE)["limits"]["max_speed_mps"]

        def fast(pos, force):
            pos[:] = v / np.pi * np.sin(np.pi * np.arange(len(pos)) * 1e-3)
        self.assertIsNone(plausible.check(logreader.read_log(self.make("fast", fast))))

    def test_position_spike_repaired(self):
        def spike(pos, force):
            pos[1200] += 0.05
            pos[0] -= 0.02  # the first sample: only the backward walk can tell
        lg = logreader.read_log(self.make("spike", spike))
        imp = plausible.check(lg)
        self.assertEqual(imp["pos"]["count"], 2)
        self.assertEqual([r["line"] for r in imp["pos"]["rows"]], [2, 1202])
        t = lg.t[[0, 1200]]
        self.assertTrue(np.allclose(lg.pos[[0, 1200]], 0.01 * np.sin(np.pi * t), atol=4e-5))  # sample 0: its neighbour
        self.assertNotIn("force", imp)

    def test_force_limit_from_machine_file(self):
        fine = os.path.join(REPO, "machines", "fine.json")
        ref_lim, fine_lim = (plausible.MARGIN * force_limit(p) for p in (mach.REFERENCE_MACHINE, fine))
        self.assertLess(ref_lim, fine_lim)
        value = 0.5 * (ref_lim + fine_lim)

        def cell(pos, force):
            force[700] = -value
        path = self.make("cell", cell)
        lg = logreader.read_log(path)
        imp = plausible.check(lg)
        self.assertEqual(imp["force"]["rows"], [{"line": 702, "t_s": lg.t[700], "value": -value}])
        self.assertLess(abs(lg.force[700] - (20 * math.cos(np.pi * lg.t[700]) + 1)), 0.1)
        self.assertIn("reference.json", imp["limits"]["source"])
        self.assertIsNone(plausible.check(logreader.read_log(path), fine))

    def refused(self, name, edit, pattern):
        lg = logreader.read_log(self.make(name, edit))
        with self.assertRaises(logreader.LogError) as cm:
            plausible.check(lg)
        self.assertRegex(str(cm.exception), pattern)
        return cm.exception

    def test_permanent_jump_refused(self):
        def jump(pos, force):
            pos[1500:] += 0.05
        e = self.refused("jump", jump, r"jump\.csv:1502: the position jumps by 0\.05 m")
        self.assertEqual(e.line, 1502)

    def test_long_run_refused(self):
        def run(pos, force):
            force[900:900 + plausible.MAX_RUN + 1] = 5e4
        self.refused("run", run, r"run\.csv:902: column 'force': 11 of 3000 samples .* longest run 11")

    def test_many_cells_refused(self):
        def many(pos, force):
            force[::50] = 5e4
        self.refused("many", many, r"many\.csv:2: column 'force': 60 of 3000 samples")


class Audit(unittest.TestCase):
    """One 1e4 N cell in a 9521-row br_simlog log."""

    @classmethod
    def setUpClass(cls):
        w = ARGS.work
        cls.clean = os.path.join(w, "clean.csv")
        cls.bad = os.path.join(w, "bad.csv")
        r = subprocess.run([ARGS.simlog, "--out", cls.clean, "--cycles", "1", "--force-noise", "0.05", "--seed", "7"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        with open(cls.clean) as f:
            lines = f.readlines()
        cells = lines[BAD_LINE - 1].rstrip("\n").split(",")
        cls.clean_cell = float(cells[3])
        lines[BAD_LINE - 1] = ",".join(cells[:3] + ["1e4"]) + "\n"
        with open(cls.bad, "w") as f:
            f.writelines(lines)

    def test_verdict_unchanged(self):
        reps = {}
        for name, log in (("clean", self.clean), ("bad", self.bad)):
            out = os.path.join(ARGS.work, "out_" + name)
            r = diagnose(log, out)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(os.path.join(out, "report.json")) as f:
                reps[name] = json.load(f)
            if name == "bad":
                self.assertIn(f"line {BAD_LINE} (10000)", r.stderr)
                with open(os.path.join(out, "report.md")) as f:
                    self.assertIn(f"line {BAD_LINE} (10000)", f.read())
        self.assertNotIn("impossible_samples", reps["clean"])
        imp = reps["bad"]["impossible_samples"]
        self.assertEqual(imp["force"]["count"], 1)
        self.assertEqual(imp["force"]["rows"][0]["line"], BAD_LINE)
        self.assertEqual(reps["bad"]["verdict"], reps["clean"]["verdict"])
        self.assertEqual(reps["bad"]["extended"]["causes"], reps["clean"]["extended"]["causes"])
        for k in ("Fc_N", "sigma2_Nspm", "Meff_kg"):
            a, b = reps["clean"]["nominal"]["params"][k], reps["bad"]["nominal"]["params"][k]
            self.assertLess(abs(a - b), 0.02 * abs(a), k)


if __name__ == "__main__":
    work_args.main(sys.modules[__name__])
