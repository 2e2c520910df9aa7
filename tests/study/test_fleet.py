# SPDX-License-Identifier: Apache-2.0
"""The fleet study (docs/fleet.md), label `study`.

- A fleet of 2 axes (one with a LuGre plant, one with a Maxwell-slip plant) on the thesis circle and
  the point-to-point moves on Dask's local cluster of 2 workers: summary.json's structure; H-inf only's contour RMS finite and
  positive on every run that went to the end; every faulted run listed in
  "lost" with its cause and time and never carrying an RMS; a chain failure
  listed with its stage.
- Axis 0 alone on 1 worker, merged into the two-axis study (--merge): its
  record is the same (the axes do not depend on the scheduling, the worker
  count or N), and so is the merged summary.
- Every UKF and PF run's JSON says its estimators carried machine.json's causes.
- The statistics on records made here: a faulted run stays out of the RMS
  figures and is lost with its cause; a run worse than H-inf only is lost.

Usage: test_fleet.py --work DIR"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import unittest


HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "sim", "studies"))
import fleet  # noqa: E402
import fleet_axis  # noqa: E402
import fleet_why  # noqa: E402
import fleet_worse  # noqa: E402

ARGS = None
SEED = 7


# the two-axis fleet: axis 0 (LuGre) and the seed's first axis with a Maxwell-slip plant
TWO_AXES = (0, 7)


def study(out, axes, workers, merge=None):
    shutil.rmtree(out, ignore_errors=True)
    r = subprocess.run([sys.executable, os.path.join(REPO, "sim", "studies", "fleet.py"), "--out", out,
                        "--axes", ",".join(str(i) for i in axes),
                        "--seed", str(SEED), "--workers", str(workers), "--kinds", "thesis_circle,p2p",
                        *(("--merge", merge) if merge else ())],
                       capture_output=True, text=True, timeout=500)
    if r.returncode != 0:
        raise AssertionError("fleet.py exit %d\n%s\n%s" % (r.returncode, r.stdout[-3000:], r.stderr[-3000:]))
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
        return json.load(f), r.stdout


class Fleet(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.two, cls.out2 = study(os.path.join(ARGS.work, "two"), TWO_AXES, 2)
        # axis 0 again alone, on 1 worker, merged into the two-axis study (fleet.py --merge)
        cls.one, _ = study(os.path.join(ARGS.work, "one"), TWO_AXES[:1], 1, merge=os.path.join(ARGS.work, "two"))

    def test_structure(self):
        s = self.two
        self.assertEqual(s["n_axes"], 2)
        self.assertEqual([r["i"] for r in s["axes"]], list(TWO_AXES))
        # the plants by friction: one LuGre, one Maxwell-slip, each with its controllers' statistics
        self.assertEqual([s["friction"][k]["n_axes"] for k in ("lugre", "maxwell_slip")], [1, 1])
        self.assertEqual(s["friction"]["maxwell_slip"]["controllers"]["hinf_only"]["n"],
                         len(s["axes"][1]["runs"]))
        self.assertEqual(sorted(s["kinds"]), ["p2p", "thesis_circle"])
        # br_track runs the UKF too, and each with the machine file's inertia feedforward
        self.assertEqual(sorted(s["kinds"]["p2p"]), ["hinf_inertia", "hinf_only", "hinf_pf", "hinf_pf_inertia",
                                                     "hinf_ukf", "hinf_ukf_inertia"])
        for ctl in (s["controllers"], *s["kinds"].values()):
            for name, v in ctl.items():
                self.assertIn(name, fleet.CONTROLLERS)
                for k in ("median_m", "p90_m", "max_m", "lost", "n", "n_completed"):
                    self.assertIn(k, v)
        self.assertTrue(os.path.isfile(os.path.join(ARGS.work, "two", "cdf.png")))

    def test_estimators_carry_the_machine_causes(self):
        """every run's estimators as the image built for the axis's machine.json has them, with its
        causes (br_robust_run / br_track --machine-causes; docs/fleet.md, "The estimators as the image
        has them"), not the thesis model the tools run by default"""
        seen = 0
        for r in self.two["axes"]:
            for name in r.get("runs", {}):
                for ctrl in ("hinf_ukf", "hinf_pf"):
                    path = os.path.join(ARGS.work, "two", "axes", "%04d" % r["i"], "%s_%s.json" % (name, ctrl))
                    if not os.path.exists(path):
                        continue  # a run whose tool failed writes nothing (listed as lost)
                    with open(path, encoding="utf-8") as f:
                        self.assertEqual(json.load(f).get("estimator_causes"), "machine", path)
                    seen += 1
        self.assertGreater(seen, 0)

    def test_hinf_only_finite(self):
        """H-inf only went to the end on every axis whose chain went through, with a finite RMS"""
        for r in self.two["axes"]:
            if "chain_failed" in r:
                self.assertTrue(r["chain_failed"]["stage"] and r["chain_failed"]["message"])
                continue
            self.assertEqual(sorted(r["runs"]), ["p2p", "thesis_circle"])
            for name, runs in r["runs"].items():
                h = runs["hinf_only"]
                self.assertFalse(h["faulted"], "axis %d, %s: H-inf only faulted" % (r["i"], name))
                self.assertTrue(math.isfinite(h["rms_m"]) and h["rms_m"] > 0.0)

    def test_faulted_runs_listed_never_an_rms(self):
        s = self.two
        for r in s["axes"]:
            for name, runs in r["runs"].items():
                for ctrl, run_ in runs.items():
                    lost = [x for x in s["controllers"][ctrl]["lost"] if x["axis"] == r["i"] and x["trajectory"] == name]
                    if fleet.refused(run_):
                        # refused at init: counted apart, never lost, never a figure
                        self.assertNotIn("rms_m", run_)
                        self.assertEqual(lost, [])
                        self.assertIn({"axis": r["i"], "trajectory": name, "kind": r["traj"][name]["kind"],
                                       "status": run_["init_status"]}, s["controllers"][ctrl]["refused_at_init"])
                    elif run_["faulted"]:
                        self.assertNotIn("rms_m", run_)
                        self.assertEqual(len(lost), 1, (r["i"], name, ctrl))
                        self.assertEqual(lost[0]["cause"], run_["fault_cause"])
                        self.assertTrue(lost[0]["cause"])
                        self.assertIn("%s: axis %d, %s, %s" % (ctrl, r["i"], name, run_["fault_cause"]), self.out2)
                    else:
                        self.assertTrue(math.isfinite(run_["rms_m"]))

    def test_track_references_pass_the_drive(self):
        """the point-to-point moves built within the limiter's accepted speed (fleet_axis.track_limits)
        pass the drive's own reference limiter untouched on each axis's firmware: every track run
        that went to the end reports its ref_limited_periods (br_track), and none is > 0"""
        s = self.two
        n = 0
        for r in s["axes"]:
            for name, runs in r["runs"].items():
                if r["traj"][name]["kind"] != "p2p":
                    continue
                for ctrl, run_ in runs.items():
                    if not run_["faulted"]:
                        self.assertIn("ref_limited_periods", run_, (r["i"], name, ctrl))
                        n += 1
        self.assertGreater(n, 0)
        self.assertEqual(s["ref_limited"], [])

    def test_why_reads_every_estimator_run(self):
        """fleet_why.py (docs/fleet.md, "Why runs are lost") sees each estimator run of the summary, with its fault"""
        want = sorted((ctrl, run_["faulted"]) for r in self.two["axes"] for runs in r.get("runs", {}).values()
                      for ctrl, run_ in runs.items() if ctrl in fleet_why.CTRLS)
        got = sorted((r["ctrl"], r["faulted"]) for r in fleet_why.runs(os.path.join(ARGS.work, "two")))
        self.assertEqual(got, want)
        self.assertTrue(all(r["d_m"] > 0.0 and math.isfinite(r["d_m"]) for r in fleet_why.runs(os.path.join(ARGS.work, "two"))))

    def test_worse_reads_every_run(self):
        """fleet_worse.py (docs/fleet.md, "Why runs end worse than H-inf only") sees each estimator run
        whose H-inf only went to the end: faulted where the summary says so, else its RMS over H-inf only's"""
        n, seen = 0, 0
        for r in self.two["axes"]:
            got = fleet_worse.verdicts(os.path.join(ARGS.work, "two", "axes", "%04d" % r["i"]))
            seen += len(got)
            for name, runs in r["runs"].items():
                if runs["hinf_only"]["faulted"]:
                    continue
                for ctrl in fleet_worse.CTRLS:
                    run_ = runs[ctrl]
                    want = "faulted" if run_["faulted"] else run_["rms_m"] / runs["hinf_only"]["rms_m"]
                    if want == "faulted":
                        self.assertEqual(got[(name, ctrl)], want)
                    else:
                        self.assertAlmostEqual(got[(name, ctrl)] / want, 1.0, places=5)
                    n += 1
        self.assertEqual(seen, n)  # no run beside the summary's
        self.assertGreater(n, 0)

    def test_worse_leaves_refusals_out(self):
        """fleet_worse.py: a run the firmware refused at init is neither lost nor a figure (as fleet.py
        counts it); a faulted run is "faulted", never a ratio"""
        import tempfile
        d = tempfile.mkdtemp(dir=ARGS.work)
        runs = {"hinf_only": {"fault_status": 0, "contour_rms_m": 2e-6, "max_err_m": 4e-6},
                "hinf_ukf": {"fault_status": -6, "fault_t_s": 0.1, "fault_cause": "lost_lock"},
                "hinf_pf": {"fault_status": -2, "fault_t_s": 0.0, "fault_cause": "refused_at_init"}}
        for ctrl, r in runs.items():
            with open(os.path.join(d, "thesis_circle_%s.json" % ctrl), "w", encoding="utf-8") as f:
                json.dump({"controllers": {ctrl: r}}, f)
        self.assertEqual(fleet_worse.verdicts(d), {("thesis_circle", "hinf_ukf"): "faulted"})

    def test_independent_of_workers_and_n(self):
        self.assertEqual(self.two["axes"][0], self.one["axes"][0])

    def test_merge(self):
        """axis 0 run again and merged into the two-axis study: the same study, axis 7's record the
        base's, the statistics over both, and the merge named"""
        self.assertEqual(self.one["merged"], {"base": os.path.join(ARGS.work, "two"), "axes_run_again": [0]})
        self.assertEqual(self.one["axes"][1], self.two["axes"][1])
        self.assertEqual({k: v for k, v in self.one.items() if k != "merged"}, self.two)
        # axis 0 ran here (its folder written by this run), axis 7's folder is the base's, linked
        one, two = os.path.join(ARGS.work, "one", "axes"), os.path.join(ARGS.work, "two", "axes")
        self.assertFalse(os.path.islink(os.path.join(one, "0000")))
        self.assertTrue(os.path.isfile(os.path.join(one, "0000", "thesis_circle_hinf_pf.json")))
        self.assertEqual(os.path.realpath(os.path.join(one, "0007")), os.path.realpath(os.path.join(two, "0007")))
        # a base of another study is refused with the reason
        r = subprocess.run([sys.executable, os.path.join(REPO, "sim", "studies", "fleet.py"), "--out",
                            os.path.join(ARGS.work, "refused"), "--axes", "0", "--seed", str(SEED + 1),
                            "--kinds", "thesis_circle,p2p", "--merge", os.path.join(ARGS.work, "two")],
                           capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 1)
        self.assertIn("not this study's", r.stderr)

    def test_page_with_faults_fails_unless_expected(self):
        """--md with a faulted run: exit 1 unless --expect-faults; a run only worse than H-inf only is no fault"""
        import types
        fault = {"controllers": {"hinf_pf": {"lost": [{"cause": "lost_lock", "t_s": 0.1}]}}}
        worse = {"controllers": {"hinf_pf": {"lost": [{"cause": "worse_than_hinf_only", "t_s": None}]}}}
        page = types.SimpleNamespace(md="page.md", expect_faults=False)
        self.assertEqual(fleet.unexpected_faults(fault, page), 1)
        self.assertEqual(fleet.unexpected_faults(worse, page), 0)
        self.assertEqual(fleet.unexpected_faults(fault, types.SimpleNamespace(md="page.md", expect_faults=True)), 0)
        self.assertEqual(fleet.unexpected_faults(fault, types.SimpleNamespace(md=None, expect_faults=False)), 0)

    def test_statistics(self):
        """a faulted run: out of the figures, lost with its cause; worse than H-inf only: lost"""
        def rec(i, pf):
            return {"i": i, "traj": {"c": {"kind": "circle"}},
                    "runs": {"c": {"hinf_only": {"faulted": False, "rms_m": 1e-6, "max_m": 2e-6}, "hinf_pf": pf}}}
        recs = [rec(0, {"faulted": True, "fault_t_s": 0.05, "fault_cause": "lost_lock"}),
                rec(1, {"faulted": False, "rms_m": 2e-6, "max_m": 3e-6}),
                rec(2, {"faulted": False, "rms_m": 1e-8, "max_m": 3e-8}),
                rec(3, {"faulted": True, "fault_t_s": 0.0, "fault_cause": "refused_at_init", "init_status": -2})]
        pf = fleet.summarise(recs)["hinf_pf"]
        self.assertEqual((pf["n"], pf["n_completed"], pf["n_lost"]), (4, 2, 2))
        self.assertEqual(pf["max_m"], 2e-6)
        self.assertEqual([(x["axis"], x["cause"], x["t_s"]) for x in pf["lost"]],
                         [(0, "lost_lock", 0.05), (1, "worse_than_hinf_only", None)])
        # the run the firmware refused at init: counted per controller, neither lost nor a figure
        self.assertEqual((pf["n_refused_at_init"], pf["refused_at_init"]),
                         (1, [{"axis": 3, "trajectory": "c", "kind": "circle", "status": -2}]))
        row = [x for x in fleet.table({"hinf_pf": pf}) if x.startswith("| hinf_pf")][0]
        self.assertTrue(row.endswith("| 2 | 1 |"), row)
        summ = {"controllers": {"hinf_pf": pf}}
        self.assertEqual(fleet.refused_lines(summ), ["hinf_pf: axis 3, status -2: c"])
        self.assertEqual(fleet.unexpected_faults(summ, __import__("types").SimpleNamespace(
            md="page.md", expect_faults=False)), 1)  # the lost_lock, not the refusal

    def test_load_q_scaled(self):
        """--load-q scaled: the reference's external-force random walks as the same share of each axis's
        actuator force (q_Fact2_per_s): on the reference itself the same N^2/s, on an axis with a tenth
        of its actuator force a hundredth"""
        import copy
        sys.path.insert(0, os.path.join(REPO, "firmware", "design"))
        import machine
        ref = fleet_axis.reference_file()
        m = copy.deepcopy(ref)
        fleet_axis.scale_load_q(m, ref)
        for est in ("pf", "ukf"):
            self.assertEqual(list(m["estimator"][est]["load"]), ["q_Fact2_per_s"])
            self.assertAlmostEqual(machine.load_q_N2_per_s(m, est) / ref["estimator"][est]["load"]["q_N2_per_s"],
                                   1.0, places=12)
        m["control"]["torque_limit_Nm"] *= 0.1
        self.assertAlmostEqual(machine.load_q_N2_per_s(m, "pf") / ref["estimator"]["pf"]["load"]["q_N2_per_s"],
                               0.01, places=12)

    def test_friction_split(self):
        """the axes by their plant's friction; presliding named where the diagnosis wrote the
        Maxwell-slip friction_model into machine.json (where the machine file carries the cause)"""
        def rec(i, presliding, model):
            return {"i": i, "axis": {"presliding": presliding}, "traj": {}, "runs": {},
                    "machine": {"causes": {}, **({"friction_model": {"model": model}} if model else {})}}
        f = fleet.friction_split([rec(0, False, None), rec(1, True, "maxwell_slip"), rec(2, True, None),
                                  rec(3, False, "maxwell_slip")])
        self.assertEqual((f["lugre"]["n_axes"], f["maxwell_slip"]["n_axes"]), (2, 2))
        self.assertEqual((f["lugre"]["presliding_named"], f["maxwell_slip"]["presliding_named"]), ([3], [1]))

    def test_axis_draw_in_range(self):
        for i in range(50):
            ax = fleet_axis.draw(SEED, i)
            self.assertEqual(ax, fleet_axis.draw(SEED, i))
            self.assertTrue(2e-3 <= ax["lead_m_per_rev"] <= 40e-3 and 1.0 <= ax["Meff_kg"] <= 200.0)
            self.assertTrue(2 ** 12 <= ax["counts_per_rev"] <= 2 ** 26)
            # the travel fits a signed 32-bit count
            self.assertLess((fleet_axis.TRAVEL_M + 0.01 * ax["max_speed_mps"]) / ax["lead_m_per_rev"]
                            * ax["counts_per_rev"], 2 ** 31)
            self.assertTrue(0.25e-3 <= ax["period_s"] <= 2e-3 and 0.0 <= ax["delay_s"] <= 3e-3)
            # a Maxwell-slip plant's elements within issue 30's ranges, and none on a LuGre plant
            g = ax["gms"]
            self.assertEqual(g is not None, ax["presliding"])
            self.assertEqual(fleet_axis.gms_options(ax) != [], ax["presliding"])
            if g:
                self.assertTrue(fleet_axis.GMS_N[0] <= len(g["breakaway_m"]) <= fleet_axis.GMS_N[1])
                self.assertEqual(g["breakaway_m"], sorted(g["breakaway_m"]))
                self.assertTrue(all(fleet_axis.GMS_D_M[0] <= d <= fleet_axis.GMS_D_M[1] for d in g["breakaway_m"]))
                self.assertTrue(fleet_axis.GMS_ZETA[0] <= g["zeta"] <= fleet_axis.GMS_ZETA[1])
            # the machine file a user writes for it loads, and its soft travel limits (the drive's
            # protections) hold the working range every trajectory stays in
            path = os.path.join(ARGS.work, "given-%d.json" % i)
            with open(path, "w") as f:
                json.dump(fleet_axis.given_file(ax, "given-%d" % i), f)
            m = fleet_axis.machine.load(path)
            lo, hi = fleet_axis.machine.soft_limits_m(m)
            self.assertAlmostEqual(lo, -fleet_axis.WORK_BELOW_M, delta=1e-9)
            self.assertAlmostEqual(hi, fleet_axis.TRAVEL_M, delta=1e-9)


if __name__ == "__main__":
    args = sys.argv[1:]
    if "--work" not in args[:-1]:
        sys.exit("usage: test_fleet.py --work DIR [unittest's options]")
    k = args.index("--work")
    ARGS = argparse.Namespace(work=args[k + 1])
    os.makedirs(ARGS.work, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + args[:k] + args[k + 2:], verbosity=2)
