# SPDX-License-Identifier: Apache-2.0
"""What a diagnosis never writes as measured (python/bristle/diagnose/identify.py,
physical.py; docs/diagnose.md, "Identifiability"), one rule a test, on small
logs made from the model's own force around the reference machine
(machines/reference.json, read here, never copied):

1. a parameter the assessment calls poorly determined (the log tells the
   machine file's value from its fit, but does not fix it) is held at the
   machine file's value, and machine.json takes that value with the file's
   provenance (before: kept as fitted, fleet axis 67's sigma1 = 2.4e5);
2. the presliding zone is judged by the log, not by the fitted sigma0: a fit
   whose zone spans five position steps on a log whose zone is a fifth of
   one does not vouch for itself (fleet axis 87);
3. a borderline cause that moves a parameter beyond its interval and by
   more than half its value keeps that parameter out of machine.json (a
   smaller move is reported, the value written);
4. a bristle damping ratio above physical.ZETA_MAX is held at the machine
   file's value; a shape parameter on its search bound is flagged;
5. a mass on its floor (model.COEF_LOWER) is held at the machine file's
   value, in the nominal model and in the extended (fleet axes 23, 34, 96,
   103, 131: Meff = 1e-9 kg, a model the closed-loop check cannot run);
6. a held Fs the machine file assumes goes into machine.json as the model
   holds it, the file's Fs/Fc at the identified Fc, not the file's value
   in N (fleet axis 62: Fs = 18 N on an identified Fc of 0.39 N); one the
   file gives stays as given.
"""
import math
import os
import sys
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "python"))
sys.path.insert(0, HERE)
from bristle.diagnose import identify, logreader, machinejson, model, physical, selection, signals  # noqa: E402
from test_model import synthetic_log  # noqa: E402

P0 = identify.prior(machinejson.base(None))  # the reference machine: the file a diagnosis falls back to


def prepared(truth, causes=(), q=0.0, noise_N=0.05, seed=1):
    """A 6 s two-speed back-and-forth whose force is the model's own, plus noise;
    positions on an encoder of step q when q > 0."""
    f = model.from_params(truth, causes)
    t, pos = synthetic_log(6000)
    log = logreader.Log("synthetic", t, pos, pos, np.zeros_like(t), 1e-3, len(t))
    y = f.predict(signals.Prepared(log))
    if q > 0.0:
        log.pos = np.round(pos / q) * q
    log.force = np.concatenate([y, y[-1:]]) + np.random.default_rng(seed).normal(scale=noise_N, size=len(t))
    return signals.Prepared(log)


def diagnosis(fit, rounds=()):
    return selection.Diagnosis(fit, [], fit, list(rounds))


def nominal_truth(**kw):
    return dict({k: P0[k] for k in ("Meff_kg", "sigma2_Nspm", "Fc_N", "Fs_N", "vs_mps", "sigma0_Npm",
                                    "sigma1_Nspm")}, **kw)


def zeta(p):
    return p["sigma1_Nspm"] / (2.0 * math.sqrt(p["sigma0_Npm"] * p["Meff_kg"]))


class RulesTest(unittest.TestCase):
    def test_1_poorly_determined_sigma1_is_held(self):
        # sigma1 ten times the file's (a damping ratio under 1) under 0.5 N of noise: the log shows it, weakly
        truth = nominal_truth(sigma1_Nspm=10.0 * P0["sigma1_Nspm"])
        self.assertLess(zeta(truth), physical.ZETA_MAX)
        prep = prepared(truth, noise_N=0.5)
        free = model.fit_nominal(prep)
        aside, _ = identify.assess(prep, free, P0)
        self.assertIn("sigma1_Nspm", dict(aside))
        held_trial = identify._refit(prep, free, {"Fc_ref_N": P0["Fc_N"], "sigma1_Nspm": P0["sigma1_Nspm"]})
        prep.fixed = None
        # the log tells the file's value from the fit: before this rule it was kept as fitted
        self.assertTrue(identify._tells(prep, held_trial, free, free.relerr(prep, prep.test)))
        diag = diagnosis(free)
        out = identify.apply(prep, diag, P0, say=lambda m: None)
        self.assertIn("sigma1_Nspm", out["held"])
        self.assertIn("poorly determined", out["held"]["sigma1_Nspm"]["why"])
        self.assertEqual(diag.extended.params()["sigma1_Nspm"], P0["sigma1_Nspm"])
        self.assertEqual(out["poorly_determined"], {})
        diag.identifiability = out
        m, _ = machinejson.build(prep, diag)
        self.assertEqual(m["friction"]["sigma1_Nspm"], P0["sigma1_Nspm"])
        self.assertEqual(m["provenance"]["friction.sigma1_Nspm"], "assumed")

    def test_2_presliding_zone_is_not_vouched_by_the_fitted_sigma0(self):
        q = 1e-5
        truth = nominal_truth(sigma0_Npm=P0["Fc_N"] / (0.2 * q))  # a zone of a fifth of a step
        prep = prepared(truth, q=q)
        self.assertAlmostEqual(machinejson.encoder_step(prep.pos) / q, 1.0, places=6)
        # a fit whose zone spans five steps: the fitted-sigma0 check (2 steps) passes it
        five = model.refine(prep, model.solve(prep, (1.0 / (5 * q),) + model.fit_nominal(prep).shape[1:], (), {}),
                            rounds=0)
        prep.fixed = {"Fc_ref_N": 1.0, "sigma0_Npm": 1.0 / (5 * q)}
        five = model.fit_shape(prep, (), {}, starts=(five.shape,))
        prep.fixed = None
        p = five.params()
        self.assertGreater(p["Fc_N"] / p["sigma0_Npm"], machinejson.PRESLIDING_MIN_QUANTA * q)
        h = identify._Holder(prep, five, P0)
        identify._hold_presliding(h)
        self.assertIn("sigma0_Npm", h.kept_out)
        self.assertIn("sigma1_Nspm", h.kept_out)
        self.assertIn("does not show the presliding zone", h.kept_out["sigma0_Npm"])
        # the model keeps a zone under a step (the file's zone would add a presliding the log has not)
        p = h.best.params()
        self.assertAlmostEqual(p["Fc_N"] / p["sigma0_Npm"] / q, identify.ZONE_STEPS)
        # machine.json takes the file's sigma0 and sigma1
        diag = diagnosis(h.best)
        diag.identifiability = {"held": h.held, "kept_out": h.kept_out}
        m, _ = machinejson.build(prep, diag)
        self.assertEqual((m["friction"]["sigma0_Npm"], m["friction"]["sigma1_Nspm"]),
                         (P0["sigma0_Npm"], P0["sigma1_Nspm"]))
        self.assertEqual(m["provenance"]["friction.sigma0_Npm"], "assumed")

    def test_3_a_borderline_cause_that_moves_a_parameter_keeps_it_out(self):
        # -x friction three times +x's: the symmetric fit's Fc is the two sides' mean
        truth = dict(nominal_truth(), dFc_neg_N=2.0 * P0["Fc_N"], dsigma2_neg_Nspm=0.0)
        prep = prepared(truth, causes=("asymmetric_friction",))
        free = model.fit_nominal(prep)
        border = {"cause": "asymmetric_friction", "significant": False, "relative_gain": 0.04, "p_value": 0.02}
        diag = diagnosis(free, rounds=[[border]])
        self.assertEqual([c["cause"] for c in selection.borderline(diag)], ["asymmetric_friction"])
        out = identify.apply(prep, diag, P0, say=lambda m: None)
        moves = out["borderline_moves"]["asymmetric_friction"]
        self.assertIn("Fc_N", moves)
        without, with_, (lo, hi) = moves["Fc_N"]
        self.assertFalse(lo <= with_ <= hi)
        self.assertGreater(abs(with_ - without), identify.REL_95 * without)
        self.assertIn("Fc_N", out["kept_out"])
        diag.identifiability = out
        m, _ = machinejson.build(prep, diag)
        self.assertEqual(m["friction"]["Fc_N"], P0["Fc_N"])
        self.assertEqual(m["provenance"]["friction.Fc_N"], "assumed")
        # without the borderline cause nothing moves: nothing kept out for it
        out2 = identify.apply(prep, diagnosis(free), P0, say=lambda m: None)
        self.assertNotIn("Fc_N", out2["kept_out"])
        # a small asymmetry moves Fc beyond its interval but by less than half: written as fitted
        truth = dict(truth, dFc_neg_N=0.4 * P0["Fc_N"])
        prep = prepared(truth, causes=("asymmetric_friction",))
        free = model.fit_nominal(prep)
        diag = diagnosis(free, rounds=[[border]])
        out = identify.apply(prep, diag, P0, say=lambda m: None)
        self.assertIn("Fc_N", out["borderline_moves"]["asymmetric_friction"])
        self.assertNotIn("Fc_N", out["kept_out"])

    def test_4_non_physical_values_are_flagged(self):
        p = nominal_truth()
        s1 = 2.0 * physical.ZETA_MAX * 2.0 * math.sqrt(p["sigma0_Npm"] * p["Meff_kg"])  # zeta = 2 ZETA_MAX
        self.assertAlmostEqual(physical.damping_ratio(dict(p, sigma1_Nspm=s1)), 2.0 * physical.ZETA_MAX)
        self.assertEqual(physical.unphysical(model.from_params(p, ())), {})
        bad = physical.unphysical(model.from_params(dict(p, sigma1_Nspm=s1), ()))
        self.assertTrue(bad["sigma1_Nspm"].startswith(physical.NON_PHYSICAL))
        bad = physical.unphysical(model.from_params(dict(p, vs_mps=model.VS_BOUNDS[0]), ()))
        self.assertEqual(set(bad), {"vs_mps", "Fs_N"})
        bad = physical.unphysical(model.from_params(dict(p, Fs_N=p["Fc_N"]), ()))
        self.assertEqual(set(bad), {"Fs_N"})
        # a log whose fit has zeta above ZETA_MAX: sigma1 held at the file's value
        truth = dict(p, sigma1_Nspm=s1)
        prep = prepared(truth)
        free = model.fit_nominal(prep)
        self.assertGreater(physical.damping_ratio(free.params()), physical.ZETA_MAX)
        h = identify._Holder(prep, free, P0)
        identify._hold_unphysical(h)
        self.assertIn("sigma1_Nspm", h.held)
        self.assertEqual(h.best.params()["sigma1_Nspm"], P0["sigma1_Nspm"])


    def test_5_mass_on_its_floor_is_held(self):
        # a force that falls with the acceleration (an apparent mass below zero): the free fit's Meff on its floor
        truth = nominal_truth(Meff_kg=-P0["Meff_kg"])
        prep = prepared(truth)
        free = model.fit_nominal(prep)
        self.assertTrue(identify._at_bound(free, "Meff_kg"))
        diag = diagnosis(free)
        out = identify.apply(prep, diag, P0, say=lambda m: None)
        self.assertIn("Meff_kg", out["nominal_held"])
        self.assertEqual(diag.nominal.params()["Meff_kg"], P0["Meff_kg"])
        self.assertIn("Meff_kg", out["held"])
        self.assertEqual(diag.extended.params()["Meff_kg"], P0["Meff_kg"])
        # a fit off its floor is left as fitted
        prep = prepared(nominal_truth())
        free = model.fit_nominal(prep)
        diag = diagnosis(free)
        out = identify.apply(prep, diag, P0, say=lambda m: None)
        self.assertEqual(out["nominal_held"], {})
        self.assertIs(diag.nominal, free)

    def test_6_held_shape_keeps_the_files_ratio_to_fc(self):
        # an axis with a tenth of the file's Coulomb friction and the file's Stribeck ratio: Fs held
        fc = 0.1 * P0["Fc_N"]
        ratio = lambda k: fc * P0[k] / P0["Fc_N"]  # noqa: E731
        prep = prepared(nominal_truth(Fc_N=fc, Fs_N=ratio("Fs_N"), sigma0_Npm=ratio("sigma0_Npm")))
        free = model.fit_nominal(prep)
        h = identify._Holder(prep, free, P0)
        h.take(("Fs_N",), h.trial({"Fs_N": P0["Fs_N"]}), "held for the test")
        prep.fixed = None
        p = h.best.params()
        self.assertLess(p["Fc_N"], 0.2 * P0["Fc_N"])
        # the model holds the file's Fs/Fc (model.FIXED_SHAPE), not its Fs in N
        self.assertAlmostEqual(p["Fs_N"] / p["Fc_N"], P0["Fs_N"] / P0["Fc_N"])
        diag = diagnosis(h.best)
        diag.identifiability = {"held": h.held, "kept_out": {}}
        m, _ = machinejson.build(prep, diag)
        # machine.json writes what the model holds: before, the file's 18 N on this 0.7 N axis (Fs/Fc 26)
        self.assertAlmostEqual(m["friction"]["Fs_N"] / p["Fs_N"], 1.0, places=9)
        self.assertEqual(m["provenance"]["friction.Fs_N"], "assumed")
        # a stiction the machine file gives (no provenance block: every value given) stays as given
        m, _ = machinejson.build(prep, diag, given=machinejson._loader().REFERENCE_MACHINE)
        self.assertEqual(m["friction"]["Fs_N"], P0["Fs_N"])

if __name__ == "__main__":
    unittest.main()
