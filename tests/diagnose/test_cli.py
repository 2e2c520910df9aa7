# SPDX-License-Identifier: Apache-2.0
"""End to end through the command lines: br_simlog writes a log with a
hidden offset; `python -m bristle.diagnose diagnose` writes every output; `validate`
applies the saved model to another log of the same machine; br_simlog loads
the saved model and its log is explained by it; the Python closed loop
agrees with the C plant; bad inputs give "file:line: problem".

Usage: test_cli.py --simlog BIN --work DIR"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import unittest

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ARGS = None


def py(*a):
    env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "bristle.diagnose", *a], env=env, capture_output=True, text=True)


def simlog(*a):
    return subprocess.run([ARGS.simlog, *a], capture_output=True, text=True)


class CliTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.w = ARGS.work
        shutil.rmtree(cls.w, ignore_errors=True)
        os.makedirs(cls.w)
        cls.log_a = os.path.join(cls.w, "a.csv")
        r = simlog("--out", cls.log_a, "--offset", "1.2", "--force-noise", "0.05", "--seed", "11", "--cycles", "2",
                   "--machine-out", os.path.join(cls.w, "a.machine.json"), "--truth")
        assert r.returncode == 0, r.stderr
        cls.out = os.path.join(cls.w, "out_a")
        cls.diag = py("diagnose", "--log", cls.log_a, "--out", cls.out)

    def test_diagnose_writes_everything(self):
        self.assertEqual(self.diag.returncode, 0, self.diag.stderr)
        for f in ("report.json", "model.json", "report.md", "force_fit.png", "residuals.png", "residual_spectrum.png",
                  "closed_loop.png", "friction_map.png", "unexplained.png"):
            self.assertTrue(os.path.getsize(os.path.join(self.out, f)) > 0, f)
        with open(os.path.join(self.out, "report.json")) as f:
            rep = json.load(f)
        for k in ("log", "nominal", "findings", "verdict", "extended", "noise_floor_percent", "unexplained"):
            self.assertIn(k, rep)
        self.assertEqual(rep["verdict"], "offset")
        self.assertAlmostEqual(rep["findings"][0]["params"]["force_N"], 1.2, delta=0.05)
        self.assertIn("evidence", rep["findings"][0])
        self.assertIn("last 30 %", rep["method"]["held_out"])
        self.assertLess(rep["extended"]["relerr_percent"], rep["nominal"]["relerr_percent"])
        # the machine file beside the log was found: the closed loop was re-simulated
        cl = rep["closed_loop"]
        self.assertLess(cl["extended"]["relerr_force_percent"], cl["nominal"]["relerr_force_percent"])
        self.assertLess(cl["extended"]["relerr_position_percent"], 0.01)
        with open(os.path.join(self.out, "report.md")) as f:
            md = f.read()
        self.assertTrue(md.startswith("<!-- python/bristle/diagnose"))
        self.assertIn("**Verdict: offset**", md)
        self.assertNotRegex(md, r"20\d\d-\d\d-\d\d")  # no timestamp
        # a rerun writes the same report (deterministic, no timestamp)
        out2 = os.path.join(self.w, "out_a2")
        r = py("diagnose", "--log", self.log_a, "--out", out2, "--no-plots", "--quiet")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out2, "report.json")) as f:
            self.assertEqual(json.load(f), rep)

    def test_validate_on_another_log_of_the_machine(self):
        self.assertEqual(self.diag.returncode, 0, self.diag.stderr)
        log_b = os.path.join(self.w, "b.csv")
        r = simlog("--out", log_b, "--offset", "1.2", "--force-noise", "0.05", "--seed", "12", "--cycles", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = py("validate", "--model", os.path.join(self.out, "model.json"), "--log", log_b)
        self.assertEqual(r.returncode, 0, r.stderr)
        m = re.search(r"relerr ([0-9.e+-]+) % over (\d+) samples .*nominal model ([0-9.e+-]+) %", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        ext, nom = float(m.group(1)), float(m.group(3))
        print(r.stdout.strip())
        self.assertLess(ext, 1.0)
        self.assertLess(ext, 0.2 * nom)

    def test_simulator_loads_the_saved_model(self):
        """br_simlog --model: the identified extended model as the plant; the
        model explains that log as well as the truth explains its own."""
        self.assertEqual(self.diag.returncode, 0, self.diag.stderr)
        log_c = os.path.join(self.w, "c.csv")
        r = simlog("--out", log_c, "--model", os.path.join(self.out, "model.json"), "--cycles", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        r = py("validate", "--model", os.path.join(self.out, "model.json"), "--log", log_c)
        self.assertEqual(r.returncode, 0, r.stderr)
        ext = float(re.search(r"relerr ([0-9.e+-]+) %", r.stdout).group(1))
        print(r.stdout.strip())
        self.assertLess(ext, 0.3)

    def test_python_closed_loop_agrees_with_the_c_plant(self):
        """The diagnosis's closed-loop simulator with the true parameters
        against br_simlog's true position (same controller, same reference)."""
        sys.path.insert(0, os.path.join(REPO, "python"))
        from bristle.diagnose import closedloop

        d = np.loadtxt(self.log_a, delimiter=",", skiprows=1)
        t, ref, pos, pos_true = d[:, 0], d[:, 1], d[:, 2], d[:, 4]
        with open(os.path.join(self.w, "a.machine.json")) as f:
            ctrl = dict(json.load(f)["controller"])
        ctrl["_quantum"] = closedloop.position_quantum(pos)
        L = 0.008 / (2 * np.pi)
        truth = {"Meff_kg": (4.0e-5 + L * L * 10.0) / (L * L), "sigma2_Nspm": 50.0, "Fc_N": 7.0, "Fs_N": 18.0,
                 "vs_mps": 2e-5, "sigma0_Npm": 4e6, "sigma1_Nspm": 2000.0, "offset_N": 1.2}
        n = 6000
        q, _, x = closedloop.simulate(truth, ctrl, ref[:n], 0.0, 0.0)
        err = np.max(np.abs(x - pos_true[:n]))
        print(f"closed loop, Python against C over {n} periods: max |dx| = {err:.3g} m")
        self.assertLess(err, 2e-6)  # well under the 0.3 mm following error, a few encoder counts

    def test_bad_inputs_name_the_line(self):
        bad = os.path.join(self.w, "bad.csv")
        with open(self.log_a) as f, open(bad, "w") as g:
            for k, line in enumerate(f):
                g.write(line if k != 1500 else "1.500000,0,nan,0,0,0,0\n")
        r = py("diagnose", "--log", bad, "--out", os.path.join(self.w, "out_bad"))
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"{bad}:1501: column 'pos' is NaN", r.stderr)
        model = os.path.join(self.w, "bad_model.json")
        with open(model, "w") as f:
            f.write('{"format": "bristle-model/2",\n "params": {"Meff_kg": 1}}\n')
        r = py("validate", "--model", model, "--log", self.log_a)
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"{model}:2: \"params\" lacks sigma2_Nspm", r.stderr)
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--model", model)
        self.assertEqual(r.returncode, 1)
        self.assertIn(f"{model}: \"params\".\"sigma2_Nspm\": required, missing", r.stderr)  # cJSON: no lines
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--delay", "-1")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("delay_s", r.stderr)
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--ripple", "1")
        self.assertEqual(r.returncode, 2)
        # the options set the parameters of sim/lib/plant/br_model_params.h, by their names and bounds
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--asym", "1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("dFc_neg_N,dsigma2_neg_Nspm", r.stderr)
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--delay", "0.5")
        self.assertEqual(r.returncode, 2)
        self.assertIn("delay_s must be in 0 .. 0.1", r.stderr)
        r = simlog("--out", os.path.join(self.w, "x.csv"), "--ripple", "1,0")
        self.assertIn("ripple_period_m must be > 0", r.stderr)

    def test_unusable_inputs_fail_before_the_fit(self):
        """Exit 1, "file:line: problem", no traceback, nothing written, and
        before the fit (no progress line)."""
        def refused(r, fragment):
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn(fragment, r.stderr)
            self.assertNotIn("Traceback", r.stderr)
            self.assertNotIn("nominal:", r.stderr)  # progress is logged to stderr

        with open(self.log_a) as f:
            lines = f.read().splitlines()
        a_file = os.path.join(self.w, "a_file")
        with open(a_file, "w") as f:
            f.write("keep\n")
        refused(py("diagnose", "--log", self.log_a, "--out", a_file), "--out names an existing file")
        refused(py("diagnose", "--log", self.log_a, "--out", os.path.join(a_file, "sub")), "is not a directory")
        with open(a_file) as f:
            self.assertEqual(f.read(), "keep\n")
        refused(py("diagnose", "--log", self.log_a, "--out", os.path.join(self.w, "o"), "--fc", "nan"),
                "--fc:0: parameter fc_hz = nan must be > 0")

        def log_with(name, edit):
            p = os.path.join(self.w, name)
            with open(p, "w") as f:
                f.write("\n".join(edit(k, x) for k, x in enumerate(lines)) + "\n")
            return p

        out = os.path.join(self.w, "out_never")
        zero = log_with("zero.csv", lambda k, x: x if k == 0 else ",".join(x.split(",")[:3] + ["0"] + x.split(",")[4:]))
        refused(py("diagnose", "--log", zero, "--out", out), f"{zero}:2: column 'force' is 0 on every row")
        huge = log_with("huge.csv", lambda k, x: x if k != 700 else ",".join(x.split(",")[:3] + ["1e308"] +
                                                                            x.split(",")[4:]))
        refused(py("diagnose", "--log", huge, "--out", out), f"{huge}:701: column 'force': 1e308 is beyond")
        self.assertFalse(os.path.exists(out))

        machine = os.path.join(self.w, "m.json")
        for key, value, fragment in (("gain_N", "1e308", "parameter gain_N = 1e+308 must be > 0 and <= 100000"),
                                     ("kv", "-3", "parameter kv = -3 must be > 0"),
                                     ("dt_s", "0.002", "controller period 0.002 s differs from the log's 0.001 s")):
            with open(os.path.join(self.w, "a.machine.json")) as f:
                text = re.sub(f'"{key}": [^,}}]+', f'"{key}": {value}', f.read())
            with open(machine, "w") as f:
                f.write(text)
            refused(py("diagnose", "--log", self.log_a, "--out", out, "--machine", machine), f"{machine}:")
            self.assertIn(fragment, py("diagnose", "--log", self.log_a, "--out", out, "--machine", machine).stderr)

        with open(os.path.join(self.out, "model.json")) as f:
            good = f.read()
        model = os.path.join(self.w, "m_model.json")
        for key, value, fragment in (("Fc_N", "0", "parameter Fc_N = 0 must be > 0"),
                                     ("Meff_kg", "-30", "parameter Meff_kg = -30 must be > 0"),
                                     ("sigma1_Nspm", "1e308", "parameter sigma1_Nspm = 1e+308 must be in 0 .. 1e+08")):
            with open(model, "w") as f:
                f.write(re.sub(f'"{key}": [^,}}\n]+', f'"{key}": {value}', good, count=1))
            r = py("validate", "--model", model, "--log", self.log_a)
            refused(r, f"{model}:")
            self.assertIn(fragment, r.stderr)
            self.assertNotIn("relerr", r.stdout)


def main():
    global ARGS
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0], "-v"] + rest)


if __name__ == "__main__":
    main()
