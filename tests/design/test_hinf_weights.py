# SPDX-License-Identifier: Apache-2.0
"""The H-infinity weights from the machine (firmware/design/hinf_weights.py,
docs/modules/hinf.md, "Weights from the machine"), label `design`:

- on machines/reference.json the rule gives back its weights (0.1 %) and so
  its design's margins (0.05 deg) and bandwidths (0.1 %), computed here from
  both, never copied;
- on every machine of machines/ and on the fleet's axes whose copy of the
  reference's weights synth_hinf.py refuses (docs/fleet.md: seed 20261201,
  axes 25, 55, 124, 128, 136, 137, 184) the rule's design passes
  synth_hinf.py's checks (sampled loops stable at both periods) with a phase
  margin above 45 deg and a gain margin above 6 dB at each period;
- where one encoder count of velocity would ask more than COUNT_TORQUE_SHARE
  of the torque limit at the period's frequency (axis 176), the frequency is
  lowered to that share;
- the friction term (4): on a light axis with strong stiction (the truth of
  fleet axis 137) the frequency rises until a stiction step moves the axis
  FOLLOWING_SHARE of the following-error limit, on the same axis with the
  reference's stiction (its given file) it stays at the period's; where the
  margins stop the raise short of it (axis 55's truth) w0 is the largest
  frequency that keeps them;
- a machine whose period is too long for its mass's stiction (the reference
  with a 1.5 kg table, 300 N of stiction, a 2 ms period) gets the weights at
  the margins' bound with a warning naming the needed w0 and the Nyquist
  frequency (weights_or_rule's why, `synth_hinf.py --suggest`'s output);
- the guard: where the rule's own weights fail synth_hinf's checks (the
  reference with a 10-tonne table, a 4-count encoder, a 10 us control period
  and a 0.1 s PF period: the encoder bound takes w0 so low that the loop at
  10 us has a mode at 1 in float64) weights_or_rule raises DesignError;
- `synth_hinf.py --suggest` prints the block and writes no header;
- the diagnosis's machine.json takes the rule's weights, marked derived,
  where the given weights fail, keeps the given ones where they hold, and
  derives again the given file's derived weights for the identified friction.

Usage: test_hinf_weights.py WORKDIR"""
import json
import math
import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
DESIGN = os.path.join(REPO, "firmware", "design")
sys.path.insert(0, DESIGN)
sys.path.insert(0, os.path.join(REPO, "sim", "studies"))
sys.path.insert(0, os.path.join(REPO, "python"))
import hinf_weights  # noqa: E402
import loop_analysis  # noqa: E402
import machine  # noqa: E402
import synth_hinf  # noqa: E402
import fleet_axis  # noqa: E402
from bristle.diagnose import machinejson  # noqa: E402

WORK = None
FLEET_SEED = 20261201
FLEET_REFUSED = (25, 55, 124, 128, 136, 137, 184)
FLEET_ENCODER_BOUND = 176
FLEET_FRICTION_BOUND = 137   # light (1.4 kg), 436 N of stiction: the friction term raises w0
FLEET_MARGINS_BOUND = 55     # 4.7 kg, 445 N at a 1.68 ms PF period: the margins stop the raise
PM_MIN_DEG, GM_MIN = 45.0, 10.0 ** (6.0 / 20.0)


def figures(m):
    """the design of m's weights and its loop figures at each checked period"""
    p, wts = machine.params(m), synth_hinf.weights(m)
    d = synth_hinf.design(p, wts)
    A, B2 = synth_hinf.plant(p)
    return d, loop_analysis.analyse(A, B2, d["K"], wts["check_dt_s"])


def fleet_given(i):
    return fleet_axis.given_file(fleet_axis.draw(FLEET_SEED, i), "fleet-%04d" % i)


def fleet_truth(i):
    """the axis's true plant as a machine file: its drawn stiction, where the diagnosis identifies it"""
    ax = fleet_axis.draw(FLEET_SEED, i)
    return fleet_axis.truth_file(ax, fleet_axis.given_file(ax, "fleet-%04d" % i))


def too_slow_for_its_friction():
    """machines/reference.json with a 1.5 kg table on a light screw, 300 N of stiction and a 2 ms
    control period (3 ms for the PF): the friction needs a loop its period cannot carry"""
    m = machine.load(machine.REFERENCE_MACHINE)
    m["mechanics"].update({"table_mass_kg": 1.5, "inertia_kgm2": 1e-7})
    m["friction"].update({"Fc_N": 200.0, "Fs_N": 300.0})
    m["control"].update({"period_s": 0.002, "torque_limit_Nm": 3.0})
    m["amplifier"]["torque_per_duty_Nm"] = 3.0
    m["estimator"]["pf"]["period_s"] = 0.003
    return m


def too_coarse_for_its_periods():
    """machines/reference.json with a 10-tonne table, 4 counts per revolution, a 10 us control period
    and a 0.1 s PF period: one count of velocity at 10 us asks the torque limit at any w0 (3) allows"""
    m = machine.load(machine.REFERENCE_MACHINE)
    m["mechanics"]["table_mass_kg"] = 1e4
    m["encoder"]["counts_per_rev"] = 4
    m["control"]["period_s"] = 1e-5
    m["estimator"]["pf"]["period_s"] = 0.1
    return m


class Rule(unittest.TestCase):
    def assert_holds(self, m, what):
        d, res = figures(m)
        for key, r in res.items():
            if key == "continuous":
                continue
            self.assertGreater(r["pm_deg"], PM_MIN_DEG, "%s at %g s" % (what, key))
            self.assertGreater(r["gm_up"], GM_MIN, "%s at %g s" % (what, key))
        self.assertTrue(all(rho < 1.0 for _, rho, _ in d["checks"]), what)

    def test_reference_comes_back(self):
        ref = machine.load(machine.REFERENCE_MACHINE)
        hinf, info = hinf_weights.suggest(ref)
        self.assertEqual(info["bound"], "period")
        for k, v in ref["control"]["hinf"].items():
            self.assertAlmostEqual(hinf[k] / v, 1.0, delta=1e-3, msg=k)
        d0, r0 = figures(ref)
        d1, r1 = figures(hinf_weights.with_hinf(ref, hinf))
        for key in r0:
            self.assertAlmostEqual(r1[key]["pm_deg"], r0[key]["pm_deg"], delta=0.05)
            self.assertAlmostEqual(r1[key]["bandwidth_rad_s"] / r0[key]["bandwidth_rad_s"], 1.0, delta=1e-3)
            self.assertAlmostEqual(r1[key]["gm_down"] / r0[key]["gm_down"], 1.0, delta=1e-3)
        # the loop frequency of eq. (1): -K_eps / Jeff = w0^3
        w0 = (-d1["K"][2] / machine.params(ref)["Jeff_kgm2"]) ** (1.0 / 3.0)
        self.assertAlmostEqual(w0 / info["omega0_rad_s"], 1.0, delta=1e-3)

    def test_machines(self):
        folder = os.path.join(REPO, "machines")
        for name in sorted(os.listdir(folder)):
            if name.endswith(".json"):
                m = machine.load(os.path.join(folder, name))
                self.assert_holds(hinf_weights.with_hinf(m, hinf_weights.suggest(m)[0]), name)

    def test_fleet_axes_the_reference_fails(self):
        for i in FLEET_REFUSED:
            g = fleet_given(i)
            self.assertIsNotNone(hinf_weights.refusal(g), i)  # the case the rule is for
            hinf, why = hinf_weights.weights_or_rule(g)
            self.assertIn("the weights from the machine", why)
            self.assert_holds(hinf_weights.with_hinf(g, hinf), "axis %d" % i)
            # the given file the fleet writes takes them, marked derived, and loads
            self.assertIsNotNone(fleet_axis.use_hinf_rule(g))
            self.assertEqual(g["control"]["hinf"], hinf)
            self.assertEqual(g["provenance"]["control.hinf.weight_eps_per_rad_s"], "derived")
            path = os.path.join(WORK, "given-%d.json" % i)
            with open(path, "w", encoding="utf-8") as f:
                json.dump(g, f)
            machine.load(path)

    def test_fleet_axis_the_reference_holds(self):
        """where the reference's weights give a design, the fleet keeps them unless asked"""
        g = fleet_given(0)
        self.assertIsNone(hinf_weights.refusal(g))
        self.assertIsNone(fleet_axis.use_hinf_rule(g))
        self.assertEqual(g["control"]["hinf"], machine.load(machine.REFERENCE_MACHINE)["control"]["hinf"])
        self.assertIn("asked for", fleet_axis.use_hinf_rule(g, always=True))
        self.assert_holds(g, "axis 0, the weights from the machine")

    def test_encoder_bound(self):
        g = fleet_given(FLEET_ENCODER_BOUND)
        h_slow = hinf_weights.periods(g)[0]
        w_period = hinf_weights.NYQUIST_SHARE * math.pi / h_slow
        over = hinf_weights.count_torque_share(g, hinf_weights.from_omega(g, w_period))
        self.assertGreater(over, hinf_weights.COUNT_TORQUE_SHARE)
        hinf, info = hinf_weights.suggest(g)
        self.assertEqual(info["bound"], "encoder")
        self.assertLess(info["omega0_rad_s"], w_period)
        self.assertAlmostEqual(info["count_torque_share"], hinf_weights.COUNT_TORQUE_SHARE, delta=1e-3)
        self.assert_holds(hinf_weights.with_hinf(g, hinf), "axis %d" % FLEET_ENCODER_BOUND)

    def test_friction_raises_w0(self):
        t = fleet_truth(FLEET_FRICTION_BOUND)
        w_period = hinf_weights.NYQUIST_SHARE * math.pi / hinf_weights.periods(t)[0]
        target = hinf_weights.FOLLOWING_SHARE * machine.following_m(t)
        self.assertGreater(hinf_weights.friction_step_m(t, hinf_weights.from_omega(t, w_period)), target)
        hinf, info = hinf_weights.suggest(t)
        self.assertEqual(info["bound"], "friction")
        self.assertGreater(info["omega0_rad_s"], 1.2 * w_period)
        # the smallest w0 meeting (4), to the bisection's resolution
        self.assertLessEqual(info["friction_step_m"], target)
        below = info["omega0_rad_s"] / (1.0 + 2.0 * hinf_weights.REL_TOL)
        self.assertGreater(hinf_weights.friction_step_m(t, hinf_weights.from_omega(t, below)), target)
        self.assert_holds(hinf_weights.with_hinf(t, hinf), "axis %d's truth" % FLEET_FRICTION_BOUND)
        self.assertIn("friction", hinf_weights.weights_or_rule(t, always=True)[1])
        # the same axis with the reference's stiction (its given file): the period's w0
        g = fleet_given(FLEET_FRICTION_BOUND)
        self.assertEqual(hinf_weights.suggest(g)[1]["bound"], "period")

    def test_margins_stop_the_raise(self):
        t = fleet_truth(FLEET_MARGINS_BOUND)
        hinf, info = hinf_weights.suggest(t)
        self.assertEqual(info["bound"], "margins")
        self.assertGreater(info["friction_step_m"], hinf_weights.FOLLOWING_SHARE * info["following_m"])
        self.assertGreater(info["omega_friction_rad_s"], info["omega0_rad_s"])
        w0 = info["omega0_rad_s"]
        self.assertTrue(hinf_weights.raise_holds(t, w0))
        self.assertFalse(hinf_weights.raise_holds(t, w0 * (1.0 + 2.0 * hinf_weights.REL_TOL)))
        self.assert_holds(hinf_weights.with_hinf(t, hinf), "axis %d's truth" % FLEET_MARGINS_BOUND)
        # within the following-error limit: no warning
        self.assertIsNone(hinf_weights.friction_shortfall(info))

    def test_warns_on_a_period_too_long_for_the_friction(self):
        m = too_slow_for_its_friction()
        self.assertIsNotNone(hinf_weights.refusal(m))  # the reference's weights: unstable on it
        hinf, info = hinf_weights.suggest(m)
        self.assertEqual(info["bound"], "margins")
        self.assertGreater(info["friction_step_m"], machine.following_m(m))
        self.assertGreater(info["omega_friction_rad_s"], info["omega0_rad_s"])
        got, why = hinf_weights.weights_or_rule(m)
        self.assertEqual(got, hinf)
        self.assertIn("a stiction step moves the axis", why)
        self.assertIn("%.4g Hz" % (info["omega_friction_rad_s"] / (2.0 * math.pi)), why)
        self.assertIn("Nyquist frequency %.4g Hz" % (info["nyquist_rad_s"] / (2.0 * math.pi)), why)
        self.assertNotIn("stiction step", hinf_weights.weights_or_rule(fleet_truth(FLEET_FRICTION_BOUND),
                                                                        always=True)[1])
        path = os.path.join(WORK, "too-slow.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump({k: v for k, v in m.items() if k != "file"}, f)
        r = subprocess.run([sys.executable, os.path.join(DESIGN, "synth_hinf.py"), "--machine", path, "--suggest",
                            "--out", os.path.join(WORK, "never.h")], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("warning: a stiction step moves the axis", r.stdout)

    def test_guard_refuses_when_the_rule_fails_too(self):
        m = too_coarse_for_its_periods()
        self.assertIsNotNone(hinf_weights.refusal(m))
        hinf, info = hinf_weights.suggest(m)
        self.assertEqual(info["bound"], "encoder")
        self.assertIsNotNone(hinf_weights.refusal(hinf_weights.with_hinf(m, hinf)))
        with self.assertRaises(synth_hinf.DesignError) as cm:
            hinf_weights.weights_or_rule(m)
        self.assertIn("the weights from the machine fail too: the sampled loop is unstable", str(cm.exception))

    def test_suggest_cli(self):
        out = os.path.join(WORK, "never.h")
        r = subprocess.run([sys.executable, os.path.join(DESIGN, "synth_hinf.py"), "--machine",
                            os.path.join(REPO, "machines", "heavy.json"), "--suggest", "--out", out],
                           capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        block = json.loads(r.stdout[:r.stdout.index("\n}\n") + 3])
        self.assertEqual(block["control"]["hinf"], hinf_weights.suggest(machine.load(
            os.path.join(REPO, "machines", "heavy.json")))[0])
        self.assertFalse(os.path.exists(out))

    def test_diagnosis_writer(self):
        """machinejson's control.hinf step: the rule where the given weights fail, derived; else kept"""
        for i, fails in ((FLEET_REFUSED[0], True), (0, False)):
            g = fleet_given(i)
            given = dict(g["control"]["hinf"])
            prov, notes = {}, []
            machinejson._hinf(g, prov, notes, False)
            self.assertEqual(g["control"]["hinf"] != given, fails, i)
            self.assertEqual(prov.get("control.hinf.weight_theta_per_rad"), "derived" if fails else None)
            self.assertEqual(len(notes), 1 if fails else 0)

    def test_diagnosis_derives_again(self):
        """a given file whose weights are derived (the rule's, for its assumed stiction) gets the
        rule's for the identified stiction; the same weights marked given are kept"""
        g = fleet_given(FLEET_FRICTION_BOUND)
        fleet_axis.use_hinf_rule(g, always=True)
        ident = fleet_truth(FLEET_FRICTION_BOUND)["friction"]
        for marked, derives in (("derived", True), ("given", False)):
            m = dict(g, friction=dict(ident), control=dict(g["control"]))
            prov, notes = {"control.hinf." + k: marked for k in g["control"]["hinf"]}, []
            machinejson._hinf(m, prov, notes, False)
            want = hinf_weights.suggest(m)[0] if derives else g["control"]["hinf"]
            self.assertEqual(m["control"]["hinf"], want, marked)
            if derives:
                self.assertNotEqual(want, g["control"]["hinf"])
            self.assertEqual(len(notes), 1 if derives else 0, marked)


if __name__ == "__main__":
    WORK = sys.argv[1]
    os.makedirs(WORK, exist_ok=True)
    unittest.main(argv=[sys.argv[0]] + sys.argv[2:], verbosity=2)
