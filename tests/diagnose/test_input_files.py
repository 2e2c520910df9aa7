# SPDX-License-Identifier: Apache-2.0
"""What a diagnosis reads must be a regular file, and a model file must list
each cause and each field once (python/bristle/diagnose/logreader.py
open_regular, jsonfile.py, modelfile.py; firmware/design/machine.py load):

- LOG=/dev/zero, a FIFO and a folder, and the same as --machine, as a
  validate --model, and to the machine-file loader: exit 1 at once with the
  file named (before: /dev/zero and a FIFO hung the diagnosis);
- "causes": ["offset", "offset"] (applied the offset twice) and a field
  given twice in a model file: refused with the field named;
- the 1 MiB limit of a model file: exactly 1 MiB read, one byte more refused.

Each command runs under a timeout: a guard that is missing hangs, and the
timeout fails the test.

Usage: test_input_files.py --simlog BIN --work DIR"""
import json
import os
import subprocess
import sys
import unittest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import work_args  # noqa: E402

ARGS = None
TIMEOUT_S = 60


def run(*a, module="bristle.diagnose"):
    env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", module, *a], env=env, capture_output=True, text=True,
                          timeout=TIMEOUT_S)


class InputFiles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        w = ARGS.work
        cls.log = os.path.join(w, "log.csv")
        r = subprocess.run([ARGS.simlog, "--out", cls.log, "--cycles", "1", "--force-noise", "0.05"],
                           capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
        cls.fifo = os.path.join(w, "fifo")
        os.mkfifo(cls.fifo)
        cls.folder = os.path.join(w, "folder")
        os.makedirs(cls.folder)
        cls.out = os.path.join(w, "out")
        r = run("diagnose", "--log", cls.log, "--out", cls.out, "--no-plots", "--quiet")
        assert r.returncode == 0, r.stderr
        cls.model = os.path.join(cls.out, "model.json")

    def refused(self, r, path, kind):
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn(f"{path}:0: not a regular file ({kind})", r.stderr)
        self.assertNotIn("Traceback", r.stderr)

    def test_log_not_a_file(self):
        for path, kind in (("/dev/zero", "a character device"), (self.fifo, "a FIFO"), (self.folder, "a directory")):
            self.refused(run("diagnose", "--log", path, "--out", os.path.join(ARGS.work, "never")), path, kind)
            self.refused(run("validate", "--model", self.model, "--log", path), path, kind)
        self.assertFalse(os.path.exists(os.path.join(ARGS.work, "never")))

    def test_machine_and_model_not_a_file(self):
        for path, kind in (("/dev/zero", "a character device"), (self.fifo, "a FIFO")):
            self.refused(run("diagnose", "--log", self.log, "--out", os.path.join(ARGS.work, "never"),
                             "--machine", path), path, kind)
            self.refused(run("validate", "--model", path, "--log", self.log), path, kind)
            sys.path.insert(0, os.path.join(REPO, "firmware", "design"))
            import machine
            with self.assertRaises(machine.MachineError) as cm:
                machine.load(path)
            self.assertIn("not a regular file", cm.exception.lines[0])

    def model_with(self, name, edit):
        with open(self.model) as f:
            text = f.read()
        path = os.path.join(ARGS.work, name)
        with open(path, "w") as f:
            f.write(edit(text))
        return path

    def test_duplicate_cause_refused(self):
        with open(self.model) as f:
            m = json.load(f)
        m["causes"] = ["offset", "offset"]
        m["params"]["force_N"] = 1.0
        path = os.path.join(ARGS.work, "twice.json")
        with open(path, "w") as f:
            json.dump(m, f, indent=2)
        r = run("validate", "--model", path, "--log", self.log)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertIn("field causes lists offset twice", r.stderr)
        self.assertEqual(r.stdout, "")

    def test_duplicate_field_refused(self):
        path = self.model_with("dupkey.json", lambda t: t.replace('"Fc_N": ', '"Fc_N": 1e3, "Fc_N": ', 1))
        r = run("validate", "--model", path, "--log", self.log)
        self.assertEqual(r.returncode, 1, r.stdout)
        self.assertRegex(r.stderr, r"dupkey\.json:\d+: field \"Fc_N\" given twice")

    def test_size_limit(self):
        """jsonfile.MAX_BYTES (1 MiB, the C loader's): a model padded with spaces
        to exactly 1 MiB validates, one byte more is refused"""
        with open(self.model) as f:
            text = f.read().rstrip("\n")
        path = os.path.join(ARGS.work, "padded.json")
        for size, ok in ((1 << 20, True), ((1 << 20) + 1, False)):
            with open(path, "w") as f:
                f.write(text + " " * (size - len(text.encode())))
            self.assertEqual(os.path.getsize(path), size)
            r = run("validate", "--model", path, "--log", self.log)
            if ok:
                self.assertEqual(r.returncode, 0, r.stderr)
            else:
                self.assertEqual(r.returncode, 1, r.stdout)
                self.assertIn(f"{path}:0: larger than 1 MiB", r.stderr)


if __name__ == "__main__":
    work_args.main(sys.modules[__name__])
