# SPDX-License-Identifier: Apache-2.0
"""A run the firmware stopped is never a result (docs/tools.md, "A faulted run
is not a result"): br_circle_ext and br_track print it as a fault with its time
and cause and write null figures; machine_chain.py and robustness.py show it as
a fault, keep it out of every RMS statistic, and exit 1 on one they did not
expect. The faults are real: a plant whose actuator delay (6 ms, 20 ms) is
beyond every candidate of the delay identification. An estimator the firmware
refuses at init is such a record too (refused_at_init), never a failed tool.

Usage: test_fault_report.py --bin BUILD/sim --work DIR"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "sim", "studies"))
sys.path.insert(0, os.path.join(REPO, "firmware", "design"))
import machine  # noqa: E402
import machine_chain  # noqa: E402
import robustness  # noqa: E402

ARGS = None


def run(tool, *a):
    return subprocess.run([os.path.join(ARGS.bin, tool), *a], capture_output=True, text=True, timeout=600)


def reference_model(path, delay_s, **friction):
    """the reference machine's plant (machines/reference.json) with an actuator delay (and the friction
    terms given), as a model.json"""
    m = machine.load(os.path.join(REPO, "machines", "reference.json"))
    p = machine.params(m)
    params = {"Meff_kg": p["Jeff_kgm2"] / p["L_mprad"] ** 2, **m["friction"], **friction, "delay_s": delay_s}
    with open(path, "w", encoding="utf-8") as f:
        json.dump({"format": "bristle-model/2", "params": params}, f)


class FaultReport(unittest.TestCase):
    def setUp(self):
        self.w = os.path.join(ARGS.work, self.id().rsplit(".", 1)[-1])
        shutil.rmtree(self.w, ignore_errors=True)
        os.makedirs(self.w)

    def assert_fault_line(self, out, name):
        line = [ln for ln in out.splitlines() if ln.split() and ln.split()[0] == name]
        self.assertEqual(len(line), 1, out)
        self.assertIn("FAULT at", line[0])
        self.assertNotIn("RMS", line[0])

    def test_circle_ext(self):
        js = os.path.join(self.w, "c.json")
        r = run("br_circle_ext", "--est", "pf", "--delay", "0.02", "--json", js)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(js) as f:
            c = json.load(f)
        self.assertFalse(c["hinf_only"]["faulted"])
        self.assertGreater(c["hinf_only"]["contour_rms_m"], 0.0)
        e = c["est_nominal"]
        self.assertTrue(e["faulted"])
        self.assertIsNone(e["contour_rms_m"])
        self.assertIsNone(e["max_err_m"])
        # a 20 ms delay the nominal model does not know: the PF loses lock, or (with its shared
        # external force, machines/reference.json) takes the misfit for a load until a motion
        # guard latches (docs/modules/pf.md, "On in the reference machine")
        self.assertIn(e["fault_cause"], ("lost_lock", "speed", "following"))
        self.assertGreater(e["fault_t_s"], 0.0)
        self.assert_fault_line(r.stdout, "est_nominal")

    def test_track(self):
        ref = os.path.join(self.w, "ref.csv")
        with open(ref, "w") as f:
            f.write("t,ref\n" + "".join("%.6f,%.9e\n" % (k * 1e-3, 1e-3 * min(k / 500.0, 1.0)) for k in range(1000)))
        model = os.path.join(self.w, "model.json")
        reference_model(model, 0.006)
        js = os.path.join(self.w, "t.json")
        r = run("br_track", "--ref", ref, "--model", model, "--ctrl", "hinf_only,hinf_pf", "--json", js)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(js) as f:
            t = json.load(f)
        self.assertFalse(t["hinf_only"]["faulted"])
        self.assertGreater(t["hinf_only"]["rms_m"], 0.0)
        self.assertTrue(t["hinf_pf"]["faulted"])
        self.assertIsNone(t["hinf_pf"]["rms_m"])
        self.assertNotEqual(t["hinf_pf"]["fault_cause"], "none")
        self.assert_fault_line(r.stdout, "hinf_pf")

    def assert_refused(self, out, rec, name, rms_key):
        """a run the firmware refused at init: a fault at 0 s with its BR_E_* and the cause
        refused_at_init, null figures, one REFUSED line (br_run_report.h)"""
        self.assertTrue(rec["faulted"])
        self.assertEqual((rec["fault_cause"], rec["fault_status"], rec["fault_t_s"]), ("refused_at_init", -2, 0))
        self.assertIsNone(rec[rms_key])
        line = [ln for ln in out.splitlines() if ln.split() and ln.split()[0] == name]
        self.assertEqual(line, ["%-14s REFUSED at init (status -2): no result" % name])

    def test_refused_at_init(self):
        """an estimator the firmware refuses at init is a record, not a failed tool (exit 0): br_robust_run's
        identified model with a bristle damping beyond the model's sub-step bound (docs/modules/model.md),
        br_track's extended model with a delay beyond the estimators' bound"""
        model = os.path.join(self.w, "model.json")
        reference_model(model, 0.0, sigma1_Nspm=1e7)
        js = os.path.join(self.w, "r.json")
        r = run("br_robust_run", "--model", model, "--only", "hinf_only,hinf_pf_id,hinf_ukf_id", "--json", js)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(js) as f:
            c = json.load(f)["controllers"]
        self.assertFalse(c["hinf_only"]["faulted"])
        for name in ("hinf_pf_id", "hinf_ukf_id"):
            self.assert_refused(r.stdout, c[name], name, "contour_rms_m")
        ref = os.path.join(self.w, "ref.csv")
        with open(ref, "w") as f:
            f.write("t,ref\n" + "".join("%.6f,%.9e\n" % (k * 1e-3, 1e-3 * min(k / 500.0, 1.0)) for k in range(1000)))
        reference_model(model, 0.1)
        r = run("br_track", "--ref", ref, "--model", model, "--ctrl", "hinf_pf_ext", "--json", js)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(js) as f:
            self.assert_refused(r.stdout, json.load(f)["hinf_pf_ext"], "hinf_pf_ext", "rms_m")

    def test_machine_chain_page(self):
        s = {"track": {"hinf_only": {"rms_m": 4e-5, "max_m": 1e-4, "fault_status": 0},
                       "hinf_pf": {"rms_m": None, "max_m": None, "fault_status": -6, "fault_cause": "lost_lock",
                                   "fault_t_s": 3.156}}}
        doc = os.path.join(self.w, "page.md")
        with open(doc, "w") as f:
            f.write("head\n%s\nold\n%s\ntail\n" % (machine_chain.BEGIN, machine_chain.END))
        machine_chain.write_md(doc, s)
        with open(doc) as f:
            page = f.read()
        row = [ln for ln in page.splitlines() if ln.startswith("| H-infinity + PF, nominal")][0]
        self.assertIn("fault at 3.156 s (lost_lock)", row)
        self.assertNotIn("e-0", row)
        self.assertEqual(len(machine_chain.unexpected_faults(s)), 1)
        self.assertEqual(machine_chain.unexpected_faults(s, "hinf_pf"), [])

    def test_robustness_statistics(self):
        def run_(rms, fault=0):
            return {"contour_rms_m": None if fault else rms, "fault_status": fault, "fault_cause": "lost_lock",
                    "fault_t_s": 0.5 if fault else 0.0, "outlier_steps": 0, "n_samples": 8001}
        recs = [{"i": i, "runs": {"hinf_only": run_(2e-6), "hinf_pf": run_(1e-8 * (i + 1), -6 if i == 2 else 0)}}
                for i in range(3)]
        ctl, _ = robustness.summarise(recs)
        pf = ctl["hinf_pf"]
        self.assertEqual(pf["n"], 3)
        self.assertEqual(pf["n_completed"], 2)
        self.assertEqual(pf["max_m"], 2e-8)  # the faulted run's partial figure is in no statistic
        self.assertEqual(pf["faults"], [{"plant": 2, "t_s": 0.5, "cause": "lost_lock"}])
        self.assertEqual(pf["lost_reasons"], {"fault": 1})


def main():
    global ARGS
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)


if __name__ == "__main__":
    main()
