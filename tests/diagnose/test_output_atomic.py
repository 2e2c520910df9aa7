# SPDX-License-Identifier: Apache-2.0
"""The outputs of a diagnosis are all or nothing, OUT replaced as a whole
(python/bristle/diagnose/output.py, Staging): a run into an OUT that holds a
previous result, on another log (so that any file it wrote would differ),
fails half-way (an exception while its first figure is written) or is killed
(SIGKILL) there, just before the folder exchange, just after it, or between
the two renames of the fallback where no exchange exists: OUT is all old or
all new (the fallback's missing OUT is put back by the next run). Stale
staging folders are removed by the next run, a run without figures leaves
none of the previous run's, and an OUT holding other files, or the current
directory, is refused.

Usage: test_output_atomic.py --simlog BIN --work DIR"""
import os
import shutil
import subprocess
import sys
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import output  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import work_args  # noqa: E402

ARGS = None

# runs the diagnosis with a failure injected (argv[1] says where)
HOOK = r"""
import os, signal, sys
from bristle.diagnose import __main__ as m, output, plots
how = sys.argv[1]
kill = lambda: os.kill(os.getpid(), signal.SIGKILL)
def broken_save(fig, path):
    with open(path, "wb") as f:
        f.write(b"\x89PNG half a figure")
    if how == "kill":
        kill()
    raise RuntimeError("injected failure while writing " + os.path.basename(path))
if how in ("fail", "kill"):
    plots.save = broken_save
real_exchange, real_rename = output._exchange, os.rename
def exchange(a, b):
    if how == "kill-before-exchange":
        kill()
    if how == "kill-between-renames":
        raise NotImplementedError("no exchange here")
    real_exchange(a, b)
    if how == "kill-after-exchange":
        kill()
renames = []
def rename(a, b):
    real_rename(a, b)
    renames.append(a)
    if how == "kill-between-renames" and len(renames) == 1:
        kill()
output._exchange = exchange
output.os.rename = rename
sys.exit(m.main(sys.argv[2:]))
"""


def env():
    return dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")


def diagnose(*a):
    return subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", *a], env=env(),
                          capture_output=True, text=True)


def snapshot(d):
    out = {}
    for n in sorted(os.listdir(d)):
        if not n.startswith("."):
            with open(os.path.join(d, n), "rb") as f:
                out[n] = f.read()
    return out


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

        # the previous result every test starts from (copied into its OUT)
        cls.first = os.path.join(cls.w, "first")
        r = diagnose("--log", cls.logs[0], "--out", cls.first, "--quiet")
        assert r.returncode == 0, r.stderr

    def setUp(self):
        self.out = os.path.join(self.w, "out_" + self._testMethodName)
        shutil.rmtree(self.out, ignore_errors=True)
        shutil.copytree(self.first, self.out)
        self.before = snapshot(self.out)
        self.assertIn("report.json", self.before)
        self.assertIn("force_fit.png", self.before)

    def disturbed(self, how, *extra):
        return subprocess.run([sys.executable, "-c", HOOK, how, "diagnose", "--log", self.logs[1], "--out", self.out,
                               "--quiet", *extra], env=env(), capture_output=True, text=True)

    def staged(self):
        """The staging and aside folders of OUT in its parent."""
        name = "." + os.path.basename(self.out) + "."
        return sorted(n for n in os.listdir(self.w) if n.startswith(name))

    def new_files(self):
        """What an undisturbed run on the second log writes (JSON and text; the
        figures are compared by name)."""
        ref = os.path.join(self.w, "ref_second")
        if not os.path.isdir(ref):
            r = diagnose("--log", self.logs[1], "--out", ref, "--quiet")
            self.assertEqual(r.returncode, 0, r.stderr)
        return snapshot(ref)

    def assert_new(self):
        after, new = snapshot(self.out), self.new_files()
        self.assertEqual(sorted(after), sorted(new))
        for n in ("report.json", "model.json", "machine.json"):
            self.assertEqual(after[n], new[n], n)
            self.assertNotEqual(after[n], self.before[n], n)

    def test_failed_run_keeps_previous(self):
        r = self.disturbed("fail")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("injected failure", r.stderr)
        self.assertEqual(snapshot(self.out), self.before)
        self.assertEqual(self.staged(), [])

    def test_killed_run_keeps_previous(self):
        r = self.disturbed("kill")
        self.assertEqual(r.returncode, -9)
        self.assertEqual(snapshot(self.out), self.before)
        self.assertEqual(len(self.staged()), 1)
        # the undisturbed run on the other log replaces every file and removes the stale staging folder
        r = diagnose("--log", self.logs[1], "--out", self.out, "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assert_new()
        self.assertEqual(self.staged(), [])

    def test_kill_before_exchange_keeps_old(self):
        self.assertEqual(self.disturbed("kill-before-exchange").returncode, -9)
        self.assertEqual(snapshot(self.out), self.before)

    def test_kill_after_exchange_is_all_new(self):
        self.assertEqual(self.disturbed("kill-after-exchange").returncode, -9)
        self.assert_new()
        stale = self.staged()
        self.assertEqual(len(stale), 1)  # the old folder, now stale: the next run removes it
        output.clean_stale(self.out)
        self.assertEqual(self.staged(), [])
        self.assert_new()

    def test_fallback_killed_between_renames(self):
        self.assertEqual(self.disturbed("kill-between-renames").returncode, -9)
        self.assertFalse(os.path.exists(self.out))  # never a mix: OUT aside, whole
        aside = [n for n in self.staged() if ".old-" in n]
        self.assertEqual(len(aside), 1)
        self.assertEqual(snapshot(os.path.join(self.w, aside[0])), self.before)
        output.clean_stale(self.out)  # what the next run does first
        self.assertEqual(snapshot(self.out), self.before)
        self.assertEqual(self.staged(), [])

    def test_no_plots_leaves_no_old_figures(self):
        r = diagnose("--log", self.logs[1], "--out", self.out, "--quiet", "--no-plots")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(snapshot(self.out)), ["machine.json", "model.json", "report.json", "report.md"])

    def test_foreign_out_refused(self):
        with open(os.path.join(self.out, "notes.txt"), "w") as f:
            f.write("mine\n")
        r = diagnose("--log", self.logs[1], "--out", self.out, "--quiet")
        self.assertEqual(r.returncode, 1)
        self.assertIn("--out holds files no diagnosis writes (notes.txt)", r.stderr)
        self.assertEqual(snapshot(self.out), dict(self.before, **{"notes.txt": b"mine\n"}))
        r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", self.logs[1], "--out", ".",
                            "--quiet"], env=env(), capture_output=True, text=True, cwd=self.out)
        self.assertEqual(r.returncode, 1)
        self.assertIn("--out holds the current directory", r.stderr)

    def test_stale_of_live_run_kept(self):
        base = "." + os.path.basename(self.out)
        live = os.path.join(self.w, f"{base}.partial-{os.getpid()}-x")
        os.makedirs(live)
        dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
        gone = os.path.join(self.w, f"{base}.partial-{int(dead.stdout)}-y")
        os.makedirs(gone)
        output.clean_stale(self.out)
        self.assertTrue(os.path.isdir(live))
        self.assertFalse(os.path.exists(gone))
        os.rmdir(live)


if __name__ == "__main__":
    work_args.main(sys.modules[__name__])
