# SPDX-License-Identifier: Apache-2.0
"""The host tools' command lines (docs/tools.md): every option checked
against its bound (sim/lib/tool/br_tool_limits.h) before a file is touched,
--help never taken as an option needing a value, an output that cannot be
written refused before the run, and a failed run leaving any existing file
byte for byte and no temporary file behind.

Usage: test_tools.py --bin DIR --work DIR"""
import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import unittest

ARGS = None
TOOLS = ("br_simlog", "br_demo_circle", "br_circle_ext", "br_pf_study", "br_dt_study", "br_tune_est", "br_track",
         "br_robust_run", "br_bench", "br_link_sim", "br_mslip_plants", "br_pil_tune")
VALUED = {"br_simlog": "--out", "br_demo_circle": "--out", "br_circle_ext": "--json", "br_pf_study": "--table",
          "br_dt_study": "--seeds", "br_tune_est": "--out", "br_track": "--json", "br_robust_run": "--json",
          "br_bench": "--json", "br_link_sim": "--pty-path", "br_mslip_plants": "--json",
          "br_pil_tune": "--out"}  # an option that takes a value
VERSION_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "VERSION")
OLD = b"an existing file\r\nwith two lines\n"


def run(tool, *a, cwd=None):
    return subprocess.run([os.path.join(ARGS.bin, tool), *a], capture_output=True, text=True, cwd=cwd, timeout=600)


class ToolsTest(unittest.TestCase):
    def setUp(self):
        self.w = os.path.join(ARGS.work, self.id().rsplit(".", 1)[-1])
        shutil.rmtree(self.w, ignore_errors=True)
        os.makedirs(self.w)

    def existing(self, name):
        p = os.path.join(self.w, name)
        with open(p, "wb") as f:
            f.write(OLD)
        return p

    def assert_untouched(self, *paths):
        for p in paths:
            with open(p, "rb") as f:
                self.assertEqual(f.read(), OLD, p)
        self.assertEqual(sorted(os.listdir(self.w)), sorted(os.path.basename(p) for p in paths),
                         "a temporary or partial file was left")

    def assert_refused(self, r, rc, *words):
        self.assertEqual(r.returncode, rc, r.stderr)
        for w in words:
            self.assertIn(w, r.stderr)

    def test_help_everywhere(self):
        for tool in TOOLS:
            for h in ("--help", "-h"):
                r = run(tool, h)
                self.assertEqual(r.returncode, 0, f"{tool} {h}: {r.stderr}")
                self.assertIn("usage:", r.stdout, tool)
            # where a value is expected, --help is still help, not the value (no file named --help)
            r = run(tool, VALUED[tool], "--help", cwd=self.w)
            self.assertEqual(r.returncode, 0, f"{tool}: {r.stderr}")
            self.assertIn("usage:", r.stdout, tool)
            self.assertEqual(os.listdir(self.w), [], tool)

    def test_version_everywhere(self):
        with open(VERSION_FILE) as f:
            version = f.read().strip()
        for tool in TOOLS:
            name = os.path.basename(tool)
            for a in (["--version"], [VALUED[tool], "--version"]):
                r = run(tool, *a, cwd=self.w)
                self.assertEqual(r.returncode, 0, f"{tool} {a}: {r.stderr}")
                self.assertEqual(r.stdout, f"{name} (bristle) {version}\n", tool)
            self.assertEqual(os.listdir(self.w), [], tool)

    def test_usage_errors_everywhere(self):
        for tool in TOOLS:
            for bad, word in ((["--bogus", "1"], "unknown option --bogus"), ([VALUED[tool]], "needs a value"),
                              (["stray"], "unexpected argument stray"), (["-x"], "unknown option -x")):
                r = run(tool, *bad, cwd=self.w)
                self.assert_refused(r, 2, word, "usage:")
            self.assertEqual(os.listdir(self.w), [], tool)
        # an unambiguous prefix of a long option is the option; an ambiguous one is refused
        r = run("br_dt_study", "--see", "1")
        self.assert_refused(r, 2, "--seeds 1: must be a whole number in 2 .. 16")  # named in full
        r = run("br_simlog", "--m", "x", cwd=self.w)
        self.assert_refused(r, 2, "ambiguous option --m")
        r = run("br_simlog", "--out", "x.csv", "--truth=1", cwd=self.w)
        self.assert_refused(r, 2, "--truth=1: the option takes no value")
        self.assertEqual(os.listdir(self.w), [])

    def test_pil_tune_refusals(self):
        # br_pil_tune (docs/link.md, "Tuning on the target"): each bad option refused before anything runs or is written
        out = os.path.join(self.w, "out")
        for bad, word in ((["--est", "kf"], "--est kf: ukf or pf"), (["--max-fev", "5"], "at least 6 evaluations"),
                          (["--est", "pf", "--max-fev", "4"], "at least 5 evaluations"),
                          (["--set", "q_bogus=1"], "no such parameter"), (["--set", "outlier_sigma=nan"], "finite"),
                          (["--set", "outlier_sigma"], "NAME=VALUE"),
                          (["--set", "outlier_sigma=1", "--set", "reanchor_after=2", "--set", "outlier_sigma=2"],
                           "at most 2"),
                          (["--duration", "0.05"], "--duration 0.05"), (["--timeout", "0"], "--timeout 0")):
            r = run("br_pil_tune", "--sim", "--out", out, *bad)
            self.assert_refused(r, 2, word)
        r = run("br_pil_tune", "--out", out)
        self.assert_refused(r, 2, "--image is required")
        r = run("br_pil_tune", "--image", os.path.join(self.w, "none.elf"), "--out", out)
        self.assert_refused(r, 1, "no image at")
        self.assertEqual(os.listdir(self.w), [])
        # a search where every evaluation faulted has no best: exit 1, nothing written (the folder stays empty)
        r = run("br_pil_tune", "--sim", "--max-fev", "6", "--duration", "0.1", "--set", "outlier_sigma=0.01",
                "--set", "outlier_transient_counts=0", "--out", out)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("no setting ran to the end", r.stdout)
        self.assertEqual(os.listdir(out), [])
        # --sim does not model a parameter it cannot set: refused, not ignored
        r = run("br_pil_tune", "--sim", "--max-fev", "6", "--set", "reanchor_after=2")
        self.assert_refused(r, 1, "--sim sets no parameter 0x0008")

    def test_simlog_bad_options_touch_nothing(self):
        out = self.existing("log.csv")
        for bad in (["--duration", "1e12"], ["--duration", "inf"], ["--duration", "nan"], ["--duration", "0"],
                    ["--duration", "3601"], ["--cycles", "0"], ["--cycles", "401"], ["--cycles", "2x"],
                    ["--force-noise", "-1"], ["--force-noise", "1e308"], ["--seed", "-1"], ["--traj", "square"],
                    ["--delay", "0.5"], ["--bogus", "1"], ["--cycles"]):
            r = run("br_simlog", "--out", out, "--traj", "circle", *bad)
            self.assert_refused(r, 2)
            self.assertIn("usage:", r.stderr)
            self.assert_untouched(out)
        r = run("br_simlog", "--out", out, "--machine-out", os.path.join(self.w, "m.json"), "--traj", "circle")
        self.assert_refused(r, 2, "does not apply to --traj circle")
        self.assert_untouched(out)
        # --reversals: 1..BR_IDENT_REV_MAX_PAIRS pairs, the identification run only
        for bad in ("0", "5", "1.5", "x"):
            r = run("br_simlog", "--out", out, "--reversals", bad)
            self.assert_refused(r, 2, "--reversals")
            self.assert_untouched(out)
        r = run("br_simlog", "--out", out, "--traj", "backforth", "--reversals", "1")
        self.assert_refused(r, 2, "--reversals applies to --traj ident only")
        self.assert_untouched(out)

    def test_gms_options_checked_in_every_tool(self):
        # --gms: 1..8 breakaway displacements, each in (0, 0.01] m; --gms-zeta: a damping ratio in
        # 0.001 .. 1, with --gms only (sim/lib/gms_args, the three tools that simulate an axis)
        for tool, head in (("br_simlog", ["--out", "{}", "--traj", "circle"]), ("br_robust_run", ["--json", "{}"]),
                           ("br_track", ["--json", "{}", "--ref", "{}"])):
            out = self.existing(tool + ".out")
            args = [out if a == "{}" else a for a in head]
            for bad in ("0", "-1e-6", "0.02", "nan", "1e-6,", "1e-6,2e-6,3e-6,4e-6,5e-6,6e-6,7e-6,8e-6,9e-6"):
                r = run(tool, *args, "--gms", bad)
                self.assert_refused(r, 2, "bad value for --gms")
            for bad in ("0", "-0.1", "1.5", "nan", "x"):
                r = run(tool, *args, "--gms", "2e-6", "--gms-zeta", bad)
                self.assert_refused(r, 2, "--gms-zeta")
            r = run(tool, *args, "--gms-zeta", "0.1")
            self.assert_refused(r, 2, "--gms-zeta applies with --gms only")
            with open(out, "rb") as f:
                self.assertEqual(f.read(), OLD, tool)

    def test_robust_run_gms_is_the_demos_hardware_like_plant(self):
        # br_robust_run --gms with the demo's elements (read from its summary.json) runs the demo's
        # hardware-like plant: the same H-inf only contour RMS to the digit; without --gms the LuGre one
        demo = os.path.join(self.w, "demo")
        r = run("br_demo_circle", "--out", demo, "--only", "hinf_only")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(demo, "summary.json")) as f:
            hw = json.load(f)["hardware_like"]
        d = ",".join(repr(e["breakaway_m"]) for e in hw["plant"]["elements"])
        rms = []
        for extra in (["--gms", d], []):
            js = os.path.join(self.w, "r%d.json" % len(rms))
            r = run("br_robust_run", "--only", "hinf_only", "--json", js, *extra)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(js) as f:
                rms.append(json.load(f)["controllers"]["hinf_only"]["contour_rms_m"])
        self.assertAlmostEqual(rms[0] / hw["hinf_only"]["contour_rms_m"], 1.0, places=6)
        self.assertGreater(abs(rms[1] / rms[0] - 1.0), 0.1)  # without --gms: the LuGre plant's figure
        # br_track: the same elements reach its plant (a short back-and-forth's reference)
        ref = os.path.join(self.w, "ref.csv")
        r = run("br_simlog", "--out", ref, "--traj", "backforth", "--duration", "1")
        self.assertEqual(r.returncode, 0, r.stderr)
        track = []
        for extra in (["--gms", d], []):
            js = os.path.join(self.w, "t%d.json" % len(track))
            r = run("br_track", "--ref", ref, "--ctrl", "hinf_only", "--json", js, *extra)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(js) as f:
                run_js = json.load(f)["hinf_only"]
            track.append(run_js["rms_m"])
            self.assertEqual(run_js["ref_limited_periods"], 0)  # within the drive's limits
        self.assertGreater(abs(track[1] / track[0] - 1.0), 0.01)

    def test_track_reports_a_limited_reference(self):
        """br_track says how many periods the drive's reference limiter changed (docs/tools.md): a
        5 mm step of the reference is limited (the run tracks the limiter's ramp, not the log's
        step), and the count is in the JSON and on stdout"""
        ref = os.path.join(self.w, "step.csv")
        with open(ref, "w") as f:
            f.write("t,ref,pos,force\n")
            for k in range(500):
                x = 0.005 if k >= 100 else 0.0
                f.write("%.3f,%.9g,%.9g,0\n" % (k * 1e-3, x, x))
        js = os.path.join(self.w, "step.json")
        r = run("br_track", "--ref", ref, "--ctrl", "hinf_only", "--json", js)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(js) as f:
            n = json.load(f)["hinf_only"]["ref_limited_periods"]
        self.assertGreater(n, 0)
        self.assertIn("the drive limited the reference in %d periods" % n, r.stdout)

    def test_track_speed_cap_is_the_limiters(self):
        """br_track --speed-cap (the firmware limiter's caps, br_app_ref_speed_cap_mps) against a
        float64 oracle from the machine file the build is for (docs/modules/app.md, "Drive
        protections"): max speed, the discrete braking curve v (v + a T) / (2 a) to the soft limit,
        and the coast envelope k^2 v^2 / (2 a_c) + (2k + 1) v T to the stroke's end less the
        following limit (k = 1.2, a_c = Fc / (M + J / L^2)), at the longest period the application
        runs at; the smaller at HI toward the high end and at LO toward the low one. Mid-stroke,
        near each end and across the whole stroke; a range with LO > HI refused."""
        sys.path.insert(0, os.path.join(os.path.dirname(VERSION_FILE), "firmware", "design"))
        import machine  # noqa: E402
        m = machine.load(ARGS.machine)
        T = machine.loop_period_s(m)
        acc, e_max, x_min = machine.limit_defaults(m)
        soft_lo, soft_hi = machine.soft_limits_m(m)
        li, mech = m["limits"], m["mechanics"]
        L = mech["lead_m_per_rev"] / (2.0 * math.pi)
        a_c = m["friction"]["Fc_N"] / (mech["table_mass_kg"] + mech["inertia_kgm2"] / (L * L))
        k = 1.2

        def oracle(lo, hi):
            caps = [li["max_speed_mps"]]
            for brake_room, coast_room in ((soft_hi - hi, x_min + li["travel_m"] - e_max - hi),
                                           (lo - soft_lo, lo - x_min - e_max)):
                caps.append(-0.5 * acc * T + math.sqrt(0.25 * (acc * T) ** 2 + 2.0 * acc * brake_room)
                            if brake_room > 0.0 else 0.0)
                if machine.coast_in_stroke(m) and coast_room > 0.0:
                    # k^2 v^2 / (2 a_c) + (2k + 1) v T = room, for v
                    A, B = k * k / (2.0 * a_c), (2.0 * k + 1.0) * T
                    caps.append((-B + math.sqrt(B * B + 4.0 * A * coast_room)) / (2.0 * A))
            return min(caps)

        mid = 0.5 * (soft_lo + soft_hi)
        span = soft_hi - soft_lo
        for lo, hi in ((mid - 0.01 * span, mid + 0.01 * span), (mid, soft_hi - 0.002 * span),
                       (soft_lo + 0.002 * span, mid), (soft_lo + 0.2 * span, soft_hi - 0.2 * span)):
            r = run("br_track", "--speed-cap", "%.9g,%.9g" % (lo, hi))
            self.assertEqual(r.returncode, 0, r.stderr)
            v, want = float(r.stdout), oracle(lo, hi)
            self.assertGreater(want, 0.0)
            self.assertLess(abs(v / want - 1.0), 1e-4, (lo, hi, v, want))
        r = run("br_track", "--speed-cap", "0.1,0.0")
        self.assert_refused(r, 2, "--speed-cap needs LO,HI")

    def test_simlog_failed_run_writes_nothing(self):
        out, machine = self.existing("log.csv"), self.existing("log.machine.json")
        model = os.path.join(self.w, "model.json")
        with open(model, "w") as f:  # every value in bounds, but stiction below Coulomb: the plant refuses it
            f.write('{"params": {"Meff_kg": 30, "sigma2_Nspm": 100, "Fc_N": 20, "Fs_N": 10, "vs_mps": 0.01, '
                    '"sigma0_Npm": 1e6, "sigma1_Nspm": 100}}')
        r = run("br_simlog", "--out", out, "--machine-out", machine, "--model", model, "--cycles", "1")
        self.assert_refused(r, 1, "nothing written")
        # a run that fails part-way, 0.3 s into the log, after rows went to the temporary file:
        # a moving mass of 1e-300 kg (within its bounds) sends the plant state to infinity
        with open(model, "w") as f:
            f.write('{"params": {"Meff_kg": 1e-300, "sigma2_Nspm": 100, "Fc_N": 20, "Fs_N": 30, "vs_mps": 0.01, '
                    '"sigma0_Npm": 1e6, "sigma1_Nspm": 100}}')
        r = run("br_simlog", "--out", out, "--machine-out", machine, "--model", model, "--cycles", "1")
        self.assert_refused(r, 1, "not finite")
        self.assertIn("nothing written", r.stderr)
        os.remove(model)
        self.assert_untouched(out, machine)

    def test_simlog_unwritable_output_refused_before_the_run(self):
        for out in (self.w, os.path.join(self.w, "no", "dir.csv"), "/dev/null"):
            r = run("br_simlog", "--out", out, "--cycles", "1")
            self.assert_refused(r, 1, "cannot write")
        keep = self.existing("log.csv")
        r = run("br_simlog", "--out", keep, "--machine-out", os.path.join(self.w, "no", "m.json"), "--cycles", "1")
        self.assert_refused(r, 1, "cannot write")
        self.assert_untouched(keep)

    def test_simlog_success_replaces_whole(self):
        out = self.existing("log.csv")
        r = run("br_simlog", "--out", "log.csv", "--cycles", "1", "--machine-out", "log.machine.json", cwd=self.w)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(sorted(os.listdir(self.w)), ["log.csv", "log.machine.json"])
        with open(out) as f:
            lines = f.read().splitlines()
        self.assertEqual(lines[0], "t,ref,pos,force")
        self.assertGreater(len(lines), 9000)
        self.assertEqual(os.stat(out).st_mode & 0o077, 0o066 & ~_umask())

    def test_simlog_gms_zeta_sets_the_element_damping(self):
        # the damping of a ratio per element (br_gms_damping_ratio, whose physics test_plant_gms checks)
        # reaches the plant: the logged force differs from the demo's damping's; a LuGre log is refused above
        logs = []
        for extra in ([], ["--gms-zeta", "0.5"]):
            out = os.path.join(self.w, f"gms{len(logs)}.csv")
            r = run("br_simlog", "--out", out, "--traj", "circle", "--duration", "0.5", "--truth",
                    "--gms", "2e-7,1e-6", *extra)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(out) as f:
                logs.append(f.read())
        self.assertEqual(logs[0].splitlines()[0], logs[1].splitlines()[0])
        self.assertNotEqual(logs[0], logs[1])

    def test_demo_bad_options_touch_nothing(self):
        d = os.path.join(self.w, "demo")
        os.makedirs(d)
        summary = os.path.join(d, "summary.json")
        with open(summary, "wb") as f:
            f.write(OLD)
        for bad in (["--dt", "5"], ["--dt", "0"], ["--dt", "inf"], ["--nsub", "0"], ["--nsub", "1001"],
                    ["--gains", "1,2"], ["--gains", "1,2,inf"], ["--gains", "1,2,3x"], ["--only", "nope"],
                    ["--pf-proposal", "3"], ["--pf-proposal", "-1"], ["--ahead", "2.5"], ["--ahead", "-0.1"],
                    ["--ahead", "nan"], ["--pf-gate", "0.5"], ["--pf-gate", "1001"], ["--pf-gate", "nan"],
                    ["--bogus", "1"]):
            r = run("br_demo_circle", "--out", d, *bad)
            self.assert_refused(r, 2)
            with open(summary, "rb") as f:
                self.assertEqual(f.read(), OLD)
            self.assertEqual(os.listdir(d), ["summary.json"])
        r = run("br_demo_circle", "--out", os.path.join(self.w, "new"), "--only", "nope")
        self.assert_refused(r, 2, "no controller named nope")
        self.assertFalse(os.path.exists(os.path.join(self.w, "new")))

    def test_demo_unwritable_output_refused_before_the_run(self):
        plain = self.existing("plain")
        r = run("br_demo_circle", "--out", plain, "--only", "hinf_only")
        self.assert_refused(r, 1)
        self.assertNotIn("contour", r.stdout)
        self.assert_untouched(plain)

    def test_robust_run_bad_options_touch_nothing(self):
        keep = self.existing("robust.json")
        for bad in (["--drift", "0.6"], ["--drift", "nan"], ["--force-noise", "-1"], ["--enc-noise", "1.5"],
                    ["--seed", "-1"], ["--ff-veps", "0"], ["--pf-dt", "1"], ["--pf-n", "0"], ["--pf-proposal", "3"], ["--ahead", "2.5"], ["--ahead", "inf"], ["--delay-id", "2"], ["--delay-id", "-1"], ["--pf-gate", "0"], ["--pf-gate", "1e4"], ["--pf-adapt-max", "0.5"], ["--pf-adapt-max", "nan"], ["--pf-adapt-max", "1e13"], ["--ukf-load", "-1"], ["--ukf-load", "2e9"], ["--ukf-load", "nan"], ["--machine-causes=1"], ["--only", "nope"], ["--only", "hinf_only,hinf_pf_id"],
                    ["--bogus", "1"], ["--drift"]):
            r = run("br_robust_run", "--json", keep, *bad)
            self.assert_refused(r, 2)
            self.assertNotIn("contour RMS", r.stdout)
            self.assert_untouched(keep)
        r = run("br_robust_run", "--json", keep, "--only", "hinf_pf_id")
        self.assert_refused(r, 2, "needs --model")
        r = run("br_robust_run", "--json", keep, "--plant", os.path.join(self.w, "none.json"))
        self.assert_refused(r, 1, "cannot open")
        self.assert_untouched(keep)

    def test_robust_run_ukf_load_takes_effect(self):
        """--ukf-load (docs/modules/ukf.md, "External force"): absent is the machine file's state, 0
        turns it off and another random walk is another filter; with the reference's state on
        (estimator.ukf.load) its own q gives the default run to the digit"""
        def rms(*extra):
            r = run("br_robust_run", "--only", "hinf_ukf", *extra)
            self.assertEqual(r.returncode, 0, r.stderr)
            # the figure and the largest error (q 1e3 and 1e4 agree in the RMS to 5 digits here)
            return re.search(r"contour RMS \S+ m, max \S+ m|FAULT at \S+ s \(\w+", r.stdout).group(0)
        with open(ARGS.machine, encoding="utf-8") as f:
            q = json.load(f)["estimator"]["ukf"].get("load", {}).get("q_N2_per_s", 0.0)
        default = rms()
        self.assertEqual(rms("--ukf-load", repr(float(q))), default)
        self.assertNotEqual(rms("--ukf-load", repr(float(q) * 10.0 if q > 0 else 1e3)), default)

    def test_robust_run_identified_force_cause_runs_the_pf(self):
        """an identified model with a force cause (offset_N) makes the estimators' model the
        extended one, which the PF's shared external force cannot carry (br_pf_init refuses it):
        the *_id runs switch it off as a diagnosis's machine.json does (br_circle_use_causes), so
        the PF runs instead of being refused at init; with the force forced on it is refused"""
        with open(ARGS.machine, encoding="utf-8") as f:
            mm = json.load(f)
        fr, me = mm["friction"], mm["mechanics"]
        lead = me["lead_m_per_rev"] / (2.0 * math.pi)
        params = {k: fr[k] for k in ("sigma2_Nspm", "Fc_N", "Fs_N", "vs_mps", "sigma0_Npm", "sigma1_Nspm")}
        params["Meff_kg"] = me["inertia_kgm2"] / lead ** 2 + me["table_mass_kg"]
        params["offset_N"] = 2.5
        model = os.path.join(self.w, "model.json")
        with open(model, "w", encoding="utf-8") as f:
            json.dump({"params": params}, f)
        r = run("br_robust_run", "--plant", model, "--model", model, "--only", "hinf_pf_id")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("contour RMS", r.stdout)  # measured: 4.6e-8 m
        self.assertNotIn("REFUSED", r.stdout)
        if "load" in mm["estimator"]["pf"]:
            r = run("br_robust_run", "--plant", model, "--model", model, "--only", "hinf_pf_id", "--pf-load", "1e4")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("REFUSED at init", r.stdout)

    def test_robust_run_pf_adapt_max_takes_effect(self):
        """--pf-adapt-max (docs/fleet.md, "The PF's start on the fleet's axes"): 1 is the PF without
        cfg.adapt's inflation, the machine's own factor gives the default run to the digit; under force
        noise the reference's PF (its shared external force off) inflates, so the two differ (a machine
        with cfg.adapt off, nis_ref 0: the same run whatever the factor)"""
        def rms(*extra):
            # without the PF's shared external force, which takes up the force noise itself (the
            # inflation then never acts: the same run at every factor)
            r = run("br_robust_run", "--only", "hinf_pf", "--force-noise", "0.2", "--seed", "3", "--pf-load", "0",
                    *extra)
            self.assertEqual(r.returncode, 0, r.stderr)
            # a figure, or the fault (without the inflation this PF loses lock here)
            return re.search(r"contour RMS (\S+) m|FAULT at \S+ s \(\w+", r.stdout).group(0)
        with open(ARGS.machine, encoding="utf-8") as f:
            adapt = json.load(f)["estimator"]["pf"].get("adapt", {})
        default = rms()
        if adapt.get("nis_ref", 0.0) == 0.0:
            self.assertEqual(rms("--pf-adapt-max", "1"), default)
            return
        self.assertEqual(rms("--pf-adapt-max", repr(float(adapt["max_scale"]))), default)
        self.assertNotEqual(rms("--pf-adapt-max", "1"), default)

    def test_circle_ext_output_checked_before_the_runs(self):
        keep = self.existing("ext.json")
        r = run("br_circle_ext", "--json", os.path.join(self.w, "no", "x.json"))
        self.assert_refused(r, 1, "cannot write")
        self.assertNotIn("contour RMS", r.stdout)
        r = run("br_circle_ext", "--json", keep, "--delay", "1")
        self.assert_refused(r, 2, "delay_s")
        for bad in ("2.5", "-0.1", "nan"):  # the lead's bounds, 0 .. BR_EST_AHEAD_MAX_PERIODS
            r = run("br_circle_ext", "--json", keep, "--ahead", bad)
            self.assert_refused(r, 2, "--ahead")
        r = run("br_circle_ext", "--json", keep, "--model", os.path.join(self.w, "none.json"))
        self.assert_refused(r, 1, "cannot open")
        self.assert_untouched(keep)

    # the circle's options (sim/lib/circle_args/br_circle_args.h, docs/tools.md): each bound refused just beyond it,
    # nothing written; the pair's bound (a revolution 0.1 .. 3600 s) likewise
    CIRCLE_BAD = tuple((b, " ".join(b) + ": must be") for b in (
        ["--radius-m", "0.9e-6"], ["--radius-m", "0.1501"], ["--radius-m", "0"], ["--radius-m", "nan"],
        ["--radius-m", "1e-4x"], ["--feed-mm-min", "0.0099"], ["--feed-mm-min", "3000.1"], ["--feed-mm-min", "-1"],
        ["--feed-mm-min", "inf"], ["--dir", "up"], ["--dir", "CW"], ["--direction", ""])) + (
        # a revolution of 0.094 s (< 0.1 s), of 12000 s and of 37700 s (> 3600 s)
        (["--radius-m", "1e-4", "--feed-mm-min", "400"], "lasts 0.0942478 s: must be 0.1 .. 3600 s"),
        (["--radius-m", "0.15"], "lasts 12000 s"), (["--radius-m", "1e-3", "--feed-mm-min", "0.01"], "lasts 37699.1 s"))

    def test_circle_options_bounds(self):
        d = os.path.join(self.w, "demo")
        os.makedirs(d)
        summary = os.path.join(d, "summary.json")
        with open(summary, "wb") as f:
            f.write(OLD)
        keep = self.existing("robust.json")
        ext = self.existing("ext.json")
        for bad, msg in self.CIRCLE_BAD:
            for tool, out in (("br_demo_circle", ["--out", d]), ("br_circle_ext", ["--json", ext]),
                              ("br_robust_run", ["--json", keep])):
                if tool == "br_robust_run" and bad[0] == "--dir":  # its --dir is the trace folder
                    bad, msg = ["--direction", *bad[1:]], msg.replace("--dir", "--direction")
                r = run(tool, *out, *bad)
                self.assert_refused(r, 2, msg)
                self.assertNotIn("contour", r.stdout)
            with open(summary, "rb") as f:
                self.assertEqual(f.read(), OLD)
            self.assertEqual(os.listdir(d), ["summary.json"])
        shutil.rmtree(d)
        # "both" only where both directions are run: the demo
        for tool, opt, out in (("br_circle_ext", "--dir", ext), ("br_robust_run", "--direction", keep)):
            self.assert_refused(run(tool, "--json", out, opt, "both"), 2, "must be cw or ccw\n")
        self.assert_untouched(keep, ext)
        # the bounds themselves are accepted (each checked against its own bound first: the message is the pair's)
        for ok in (["--radius-m", "0.15"], ["--radius-m", "1e-6"], ["--feed-mm-min", "0.01"],
                   ["--feed-mm-min", "3000"]):
            r = run("br_circle_ext", "--json", ext, *ok)
            self.assert_refused(r, 2, "a revolution of radius")

    def test_demo_circle_options_run(self):
        # 300 mm/min on the thesis radius (a revolution of 0.126 s), both directions: the ccw traces mirror x
        d = os.path.join(self.w, "demo")
        r = run("br_demo_circle", "--out", d, "--only", "hinf_only", "--feed-mm-min", "300", "--dir", "both")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        e = s["experiment"]
        self.assertEqual((e["radius_m"], e["direction"], e["directions"]), (1e-4, "cw", ["cw", "ccw"]))
        self.assertAlmostEqual(e["period_s"], 2 * 3.141592653589793 * 1e-4 / 0.005, places=12)
        self.assertAlmostEqual(e["feed_mm_min"], 300.0, places=9)
        self.assertEqual(e["duration_s"], e["period_s"])
        self.assertEqual(s["ccw"]["hinf_only"]["trace"], "trace_ccw_hinf_only.csv")
        self.assertEqual(s["realistic"]["ccw"]["hinf_only"]["trace"], "trace_real_ccw_hinf_only.csv")
        rows = {}
        for n in ("trace_hinf_only.csv", "trace_ccw_hinf_only.csv"):
            with open(os.path.join(d, n)) as f:
                rows[n] = [ln.split(",") for ln in f.read().splitlines()[1:]]
        self.assertEqual(len(rows["trace_hinf_only.csv"]), 127)  # 0 .. 0.1257 s at 1 ms
        for a, b in zip(rows["trace_hinf_only.csv"][1:60], rows["trace_ccw_hinf_only.csv"][1:60]):
            self.assertGreater(float(a[1]), 0.0)  # clockwise from (0, A): x_ref > 0 in the first half turn
            self.assertEqual(float(b[1]), -float(a[1]))
            self.assertEqual(b[2], a[2])
        # a radius alone keeps the thesis's feed: 1.5e-5 m, 1.2 s a revolution; --dir ccw alone: unprefixed traces
        d2 = os.path.join(self.w, "demo2")
        r = run("br_demo_circle", "--out", d2, "--only", "hinf_only", "--radius-m", "1.5e-5", "--dir", "ccw")
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d2, "summary.json")) as f:
            s = json.load(f)
        self.assertAlmostEqual(s["experiment"]["period_s"], 1.2, places=12)
        self.assertEqual((s["experiment"]["direction"], s["hinf_only"]["trace"]), ("ccw", "trace_hinf_only.csv"))
        self.assertNotIn("ccw", s)

    def test_make_demo_passes_the_circle_quoted(self):
        # make demo RADIUS_M=... FEED=... DIR=...: each value one argument of br_demo_circle, whatever it holds,
        # passed as data (the environment's BR_MK_*), never recipe text (docs/tools.md, "Inputs that cannot inject")
        root = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
        env = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MAKELEVEL", "MFLAGS", "DIR")}
        evil = "1e-4'; touch pwned-demo; '"
        vals = ["RADIUS_M=" + evil, "FEED=300 x", "DIR=both"]
        r = subprocess.run(["make", "-n", "-C", root, "demo"] + vals, capture_output=True, text=True, env=env,
                           timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        line = next(ln for ln in r.stdout.splitlines() if "br_demo_circle --out" in ln)
        self.assertNotIn("pwned", line)
        # the arguments the recipe's shell builds from DEMO_ARGS, one NUL-terminated each
        argv_rule = "br-demo-argv: ; @for a in $(DEMO_ARGS); do printf '%s\\0' \"$$a\"; done"
        r = subprocess.run(["make", "-s", "-C", root, "--eval", argv_rule, "br-demo-argv"] + vals, capture_output=True,
                           text=True, env=env, timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout.split("\0")[:-1], ["--radius-m=" + evil, "--feed-mm-min=300 x", "--dir=both"])
        self.assertFalse(os.path.exists(os.path.join(root, "pwned-demo")))
        r = subprocess.run(["make", "-s", "-C", root, "--eval", argv_rule, "br-demo-argv"], capture_output=True,
                           text=True, env=env, timeout=120)
        self.assertEqual(r.stdout, "")  # without them: the thesis's circle

    def test_link_sim_bounds(self):
        """br_link_sim (docs/link.md): each bound named, nothing written, no pty path file"""
        for a, word in ((["--speed", "1001"], "--speed 1001"), (["--duration", "0.01"], "--duration 0.01"),
                        (["--queue", "65"], "--queue 65"), (["--tlm-every", "0"], "--tlm-every 0"),
                        (["--rec-capacity", "65536"], "--rec-capacity 65536"),
                        (["--rec-capacity", "10", "--rec-pre", "10"], "--rec-pre 10: must be below --rec-capacity 10"),
                        (["--est", "kalman"], "--est kalman: must be none, ukf or pf"),
                        (["--plant", "x"], "--plant x: must be thesis or hardware_like")):
            r = run("br_link_sim", *a, "--pty-path", "pty.txt", cwd=self.w)
            self.assert_refused(r, 2, word, "usage:")
        self.assertEqual(os.listdir(self.w), [])
        # a run: the path of a pty that exists while it runs, the summary at the end
        r = run("br_link_sim", "--speed", "0", "--duration", "0.5", "--pty-path", "pty.txt", cwd=self.w)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(self.w, "pty.txt")) as f:
            self.assertRegex(f.read(), r"^/dev/pts/[0-9]+\n$")
        self.assertIn("br_link_sim: 500 periods (0.500 s simulated)", r.stderr)

    def test_pf_study_bounds(self):
        table = os.path.join(self.w, "t.bin")
        with open(table, "wb") as f:
            f.write(b"\0" * 12)  # 3 samples: not a power of two
        for bad in (["--duration", "inf"], ["--duration", "1e12"], ["--dt", "5"], ["--particles", "0"],
                    ["--particles", "99999"], ["--q", "1,2,3"], ["--q", "1,2,3,-4"], ["--r", "0"],
                    ["--skip", "-1"], ["--bogus", "1"]):
            self.assert_refused(run("br_pf_study", *bad), 2)
        self.assert_refused(run("br_pf_study", "--table", table), 1, "2^k")

    def test_dt_study_bounds(self):
        for bad in (["--seeds", "1"], ["--seeds", "17"], ["--m-per-ms", "inf"], ["--budget", "2", "--cost-ns", "1"],
                    ["--budget", "0.5"], ["--bogus", "1"], ["--seeds"]):
            self.assert_refused(run("br_dt_study", *bad), 2)

    def test_bench_plant_named(self):
        # br_bench --plant: thesis, realistic or hardware_like, anything else refused by name before any run
        for bad in ("nominal", "", "Realistic"):
            r = run("br_bench", "--plant", bad)
            self.assert_refused(r, 2, "--plant")
            self.assertNotIn("PF recording", r.stdout)
        # --plant-delay: 0 .. the plant's BR_PLANT_DELAY_MAX_S (0.1 s); --pf-load 0 .. 1e9 N^2/s; --pf-gate
        # 1 .. 1000 sigmas (br_tool_limits.h)
        for opt, bads in (("--plant-delay", ("-0.001", "0.2", "nan", "1ms")), ("--pf-load", ("-1", "2e9", "inf")),
                          ("--pf-gate", ("0.5", "1001", "nan"))):
            for bad in bads:
                r = run("br_bench", opt, bad)
                self.assert_refused(r, 2, opt)
                self.assertNotIn("PF recording", r.stdout)

    def test_tune_outputs_checked_before_the_tuning(self):
        header, log = self.existing("tuned.h"), self.existing("tune.csv")
        r = run("br_tune_est", "--est", "pf", "--out", header, "--log", os.path.join(self.w, "no", "l.csv"))
        self.assert_refused(r, 1, "cannot write")
        self.assertNotIn("tuning", r.stdout)
        for bad in (["--max-fev", "0"], ["--max-fev", "1e9"], ["--est", "kf"], ["--log", header],
                    ["--stat", "mean"], ["--plants"]):
            r = run("br_tune_est", "--est", "pf", "--out", header, *bad)
            self.assert_refused(r, 2)
        # a plant set with a file that cannot be read: refused before the tuning, nothing written
        r = run("br_tune_est", "--est", "pf", "--out", header, "--plants", os.path.join(self.w, "none.json"))
        self.assert_refused(r, 1, "cannot open")
        self.assertNotIn("tuning", r.stdout)
        for bad in (["--guard-noise", "-0.1"], ["--guard-noise", "11"], ["--guard-noise", "nan"],
                    ["--guard-outliers", "-1"], ["--guard-outliers", "1001"], ["--guard-outliers", "nan"]):
            self.assert_refused(run("br_tune_est", "--est", "pf", "--out", header, *bad), 2)
        # the guard plants' options only where they act: the PF's nominal objective
        for est, extra in (("ukf", ["--guard-outliers", "0.1"]), ("ukf", ["--guard-noise", "0.3"]),
                           ("pf", ["--guard-outliers", "0.1", "--plants", os.path.join(self.w, "none.json")])):
            r = run("br_tune_est", "--est", est, "--out", header, "--max-fev", "6", *extra)
            self.assert_refused(r, 2, "--guard-noise and --guard-outliers")
        # the PF's shared external force: bounded, and for the PF only (the UKF's runs would ignore it)
        for bad in (["--pf-load", "-1"], ["--pf-load", "2e9"], ["--pf-load", "nan"]):
            self.assert_refused(run("br_tune_est", "--est", "pf", "--out", header, *bad), 2)
        r = run("br_tune_est", "--est", "ukf", "--out", header, "--max-fev", "6", "--pf-load", "0")
        self.assert_refused(r, 2, "--pf-load needs --est pf")
        # the Maxwell-slip guards' target: bounded, the nominal objective only; the checkpoint has its budget
        for bad in (["--mslip-target", "-0.1"], ["--mslip-target", "1.5"], ["--mslip-target", "nan"]):
            self.assert_refused(run("br_tune_est", "--est", "ukf", "--out", header, *bad), 2)
        r = run("br_tune_est", "--est", "ukf", "--out", header, "--mslip-target", "0.1", "--plants",
                os.path.join(self.w, "none.json"))
        self.assert_refused(r, 2, "--mslip-target needs the nominal objective")
        # below Nelder-Mead's first simplex (n + 1: 5 for the PF, 6 for the UKF): refused up front
        for est, fev in (("pf", "4"), ("ukf", "5")):
            self.assert_refused(run("br_tune_est", "--est", est, "--out", header, "--max-fev", fev), 2,
                                "at least")
        r = run("br_tune_est", "--est", "ukf", "--out", header, "--checkpoint", "--max-fev", "6")
        self.assert_refused(r, 2, "--checkpoint has its own budget")
        self.assert_untouched(header, log)


def _umask():
    m = os.umask(0)
    os.umask(m)
    return m


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--machine", required=True, help="the machine file the tools are built for")
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0], *rest])
