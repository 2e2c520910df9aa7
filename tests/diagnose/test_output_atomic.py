# SPDX-License-Identifier: Apache-2.0
"""The outputs of a diagnosis are all or nothing (python/bristle/diagnose/output.py,
Staging): a run into an OUT that holds a previous result, on another log (so
that any file it wrote would differ), fails half-way (an exception while its
first figure is written) or is killed there (SIGKILL): OUT keeps the
previous run's files byte for byte and gets no new file; a failed run leaves
no staging folder, a killed one only its hidden .partial-* folder. Then the
same run, undisturbed, replaces every file.

Usage: test_output_atomic.py --simlog BIN --work DIR"""
import argparse
import os
import shutil
import subprocess
import sys
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ARGS = None

# runs the diagnosis with plots.save replaced: half a file, then the failure
HOOK = r"""
import os, signal, sys
from bristle.diagnose import __main__ as m, plots
how = sys.argv[1]
def broken_save(fig, path):
    with open(path, "wb") as f:
        f.write(b"\x89PNG half a figure")
    if how == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    raise RuntimeError("injected failure while writing " + os.path.basename(path))
plots.save = broken_save
sys.exit(m.main(sys.argv[2:]))
"""


def env():
    return dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")


def diagnose(*a):
    return subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", *a], env=env(),
                          capture_output=True, text=True)


def snapshot(d):
    return {n: open(os.path.join(d, n), "rb").read() for n in sorted(os.listdir(d)) if not n.startswith(".")}


class AtomicOutputTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.w = ARGS.work
        shutil.rmtree(cls.w, ignore_errors=True)
        os.makedirs(cls.w)
        cls.logs = []
        for seed in ("21", "22"):
            log = os.path.join(cls.w, f"log{seed}.csv")
            r = subprocess.run([ARGS.simlog, "--out", log, "--offset", "1.2", "--force-noise", "0.05", "--seed", seed,
                                "--cycles", "2"], capture_output=True, text=True)
            assert r.returncode == 0, r.stderr
            cls.logs.append(log)

    def setUp(self):
        self.out = os.path.join(self.w, "out_" + self._testMethodName)
        shutil.rmtree(self.out, ignore_errors=True)
        r = diagnose("--log", self.logs[0], "--out", self.out, "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.before = snapshot(self.out)
        self.assertIn("report.json", self.before)
        self.assertIn("force_fit.png", self.before)

    def disturbed(self, how):
        return subprocess.run([sys.executable, "-c", HOOK, how, "diagnose", "--log", self.logs[1], "--out", self.out,
                               "--quiet"], env=env(), capture_output=True, text=True)

    def test_failed_run_keeps_previous(self):
        r = self.disturbed("fail")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("injected failure", r.stderr)
        self.assertEqual(snapshot(self.out), self.before)
        self.assertEqual([n for n in os.listdir(self.out) if n.startswith(".")], [])

    def test_killed_run_keeps_previous(self):
        r = self.disturbed("kill")
        self.assertEqual(r.returncode, -9)
        self.assertEqual(snapshot(self.out), self.before)
        hidden = [n for n in os.listdir(self.out) if n.startswith(".")]
        self.assertEqual(len(hidden), 1)
        self.assertTrue(hidden[0].startswith(".partial-"))
        # the undisturbed run on the other log replaces every file
        r = diagnose("--log", self.logs[1], "--out", self.out, "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        after = snapshot(self.out)
        self.assertEqual(sorted(after), sorted(self.before))
        self.assertNotEqual(after["report.json"], self.before["report.json"])
        self.assertNotEqual(after["model.json"], self.before["model.json"])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
