# SPDX-License-Identifier: Apache-2.0
"""The forward selection of the diagnosis (python/bristle/diagnose/selection.py,
docs/diagnose.md "Significance", "Ranking") on small logs made from the
model's own force (exact causes, seeded noise), a second or so each:

- a real offset is the one finding; the asymmetry, significant too in round 1
  (it can mimic an offset), is not taken with it: the largest significant
  gain is taken first, the model refitted, and the rest tested again against
  it until none is significant;
- every candidate's "significant" is the two gates together, its gain is
  1 - relerr / base relerr, and the console lines say so;
- a log without a cause gives no finding, one round, the nominal model;
- a tested cause whose gain reaches REFINE_GAIN is refitted with the shape
  (its relerr is not worse than the shape-held one).
"""
import os
import sys
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(HERE)), "python"))
sys.path.insert(0, HERE)
from bristle.diagnose import causes, logreader, model, selection, signals  # noqa: E402
from test_model import synthetic_log  # noqa: E402

TRUTH = {"Meff_kg": 30.0, "sigma2_Nspm": 60.0, "Fc_N": 8.0, "Fs_N": 12.0, "vs_mps": 1e-3, "sigma0_Npm": 4e6,
         "sigma1_Nspm": 0.0, "offset_N": 0.0, "dFc_neg_N": 0.0, "dsigma2_neg_Nspm": 0.0, "ripple_amp_N": 0.0,
         "ripple_period_m": 0.006, "ripple_phase_rad": 0.0, "grad_per_m": 0.0, "delay_s": 0.0}


def prepared(offset_N, n=4000, seed=1, noise_N=0.05):
    truth = dict(TRUTH, offset_N=offset_N)
    f = model.from_params(truth, ("offset",))
    t, pos = synthetic_log(n)
    log = logreader.Log("synthetic", t, pos, pos, np.zeros_like(t), 1e-3, len(t))
    y = f.predict(signals.Prepared(log))
    log.force = np.concatenate([y, y[-1:]]) + np.random.default_rng(seed).normal(scale=noise_N, size=len(t))
    return signals.Prepared(log)


class SelectionTest(unittest.TestCase):
    def check_candidates(self, rnd):
        for c in rnd:
            self.assertAlmostEqual(c["relative_gain"], 1.0 - c["relerr_percent"] / c["base_relerr_percent"], places=12)
            self.assertEqual(c["significant"],
                             c["relative_gain"] >= selection.MIN_REL_GAIN and c["p_value"] < selection.P_MAX)

    def test_offset_is_the_one_finding(self):
        prep = prepared(1.5)
        msgs = []
        d = selection.diagnose(prep, msgs.append)
        self.assertEqual([c.cause for c, _ in d.findings], ["offset"])
        self.assertEqual(len(d.rounds), 2)
        r1 = {c["cause"]: c for c in d.rounds[0]}
        # every cause the log can show (presliding_hysteresis needs MIN_PRESLIDING_SAMPLES)
        ps = causes.get("presliding_hysteresis")
        shown = ps.presliding_samples(prep) >= ps.MIN_PRESLIDING_SAMPLES
        self.assertEqual(set(r1), set(causes.NAMES) - (set() if shown else {ps.NAME}))
        for rnd in d.rounds:
            self.check_candidates(rnd)
        # round 1: more than one significant; the largest gain is taken
        sig = [c for c in d.rounds[0] if c["significant"]]
        self.assertGreaterEqual(len(sig), 2)
        self.assertEqual(max(sig, key=lambda c: c["relative_gain"])["cause"], "offset")
        # round 2 tests the others against the model with the offset: none significant
        self.assertEqual({c["cause"] for c in d.rounds[1]}, set(r1) - {"offset"})
        self.assertFalse(any(c["significant"] for c in d.rounds[1]))
        # the extended model is the refitted finding, far better than the nominal
        cand, refined = d.findings[0]
        self.assertIs(d.extended, refined)
        te = prep.test
        self.assertLessEqual(refined.relerr(prep, te), cand.relerr + 1e-9)
        self.assertLess(d.extended.relerr(prep, te), 0.2 * d.nominal.relerr(prep, te))
        self.assertAlmostEqual(refined.params()["offset_N"], 1.5, delta=0.05)
        # the console: the nominal, one line per candidate and round, the finding
        self.assertTrue(msgs[0].startswith("nominal: held-out relerr"))
        lines = [m for m in msgs if m.startswith("  ")]
        self.assertEqual(len(lines), len(d.rounds[0]) + len(d.rounds[1]))
        for m, c in zip(lines, d.rounds[0] + d.rounds[1]):
            self.assertIn(c["cause"], m)
            self.assertIn(f"gain {100 * c['relative_gain']:.1f} %", m)
            self.assertEqual(m.endswith(" significant"), c["significant"])
        self.assertTrue(any(m.startswith("finding 1: offset, refitted") for m in msgs))

    def test_no_cause_no_finding(self):
        prep = prepared(0.0)
        d = selection.diagnose(prep)
        self.assertEqual(d.findings, [])
        self.assertEqual(len(d.rounds), 1)
        self.assertIs(d.extended, d.nominal)
        self.check_candidates(d.rounds[0])

    def test_large_gain_is_refitted_with_the_shape(self):
        prep = prepared(1.5)
        base = model.fit_nominal(prep)
        held = model.add_cause(prep, base, "offset")
        cand = selection.test(prep, base, "offset")
        te = prep.test
        self.assertGreaterEqual(cand.rel_gain, selection.REFINE_GAIN)
        self.assertLessEqual(cand.relerr, held.relerr(prep, te) + 1e-9)
        self.assertAlmostEqual(cand.base_relerr, base.relerr(prep, te), places=12)
        self.assertNotEqual(cand.fit.shape, held.shape)  # the shape was searched again


if __name__ == "__main__":
    unittest.main()
