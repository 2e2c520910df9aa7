# SPDX-License-Identifier: Apache-2.0
"""The held-out split of the diagnosis (python/bristle/diagnose/signals.py,
docs/diagnose.md "Held-out part"): every held-out figure the project
publishes rests on it. Properties, not bytes:

- the held-out part is the last part of the log in time, after the fit's
  part, disjoint from it, and together they cover the log less its edges;
- its share is 1 - TRAIN_FRAC, and the report's description names it (at
  another share too); the edges and the share are docs/diagnose.md's;
- the fit never sees it: changing the force in the held-out part leaves the
  fitted coefficients unchanged and changes only the held-out error;
- the relerr a model reports as held out is measured there, not on the fit's part;
and the interval quantities the fit uses (the interval's position, speed,
acceleration), the shortest log the split accepts, relerr itself.
"""
import os
import re
import sys
import unittest

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import logreader, model, signals  # noqa: E402

SHAPE = (1e-3, 1.0, 1.0)  # a fixed LuGre shape: the linear fit alone, no search


def synthetic(n=8000, dt=1e-3, seed=5):
    """A back-and-forth motion and a force with viscous, Coulomb-like and
    inertial parts plus noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    pos = 0.02 * (1 - np.cos(2 * np.pi * 0.4 * t)) + 0.002 * np.sin(2 * np.pi * 1.7 * t)
    v = np.gradient(pos, dt)
    a = np.gradient(v, dt)
    force = 90.0 * a + 200.0 * v + 15.0 * np.tanh(v / 1e-3) + rng.normal(scale=0.3, size=n)
    return logreader.Log("synthetic.csv", t, pos, pos, force, dt, n)


class IntervalTest(unittest.TestCase):
    def test_interval_position_is_its_midpoint(self):
        # a constant speed: the filtered path is the path (away from the edges),
        # and each interval's position is the path at its middle
        n, dt, v0 = 4000, 1e-3, 0.01
        t = np.arange(n) * dt
        pos = 0.003 + v0 * t
        prep = signals.Prepared(logreader.Log("ramp.csv", t, pos, pos, np.zeros(n), dt, n))
        k = np.arange(prep.lo, prep.hi)
        np.testing.assert_allclose(prep.xm[k], 0.003 + v0 * (t[k] + 0.5 * dt), rtol=0, atol=1e-9)
        np.testing.assert_allclose(prep.v[k], v0, rtol=1e-6)
        self.assertTrue(np.all(np.abs(prep.a[k]) < 1e-6))

    def test_shortest_log(self):
        # 4 edges and 100 intervals is the least the split accepts (EDGE_MIN at 1 ms)
        dt = 1e-3
        edge = max(signals.EDGE_MIN, int(round(signals.EDGE_S / dt)))
        need = 4 * edge + 101  # samples: intervals = samples - 1
        for n, ok in ((need, True), (need - 1, False)):
            t = np.arange(n) * dt
            pos = 0.01 * np.sin(2 * np.pi * 2.0 * t)
            log = logreader.Log("short.csv", t, pos, pos, pos, dt, n)
            if ok:
                signals.Prepared(log)
            else:
                with self.assertRaises(ValueError) as cm:
                    signals.Prepared(log)
                self.assertIn(f"{n} samples are too few for the diagnosis (at least {need} needed)", str(cm.exception))

    def test_relerr(self):
        y = np.array([3.0, 4.0])
        self.assertAlmostEqual(signals.relerr(y, np.array([0.3, 0.4])), 10.0, places=12)
        self.assertAlmostEqual(signals.relerr(1e-3 * y, np.array([3e-4, 4e-4])), 10.0, places=12)
        self.assertEqual(signals.relerr(np.zeros(3), np.ones(3)), float("inf"))


class FilterTest(unittest.TestCase):
    def test_butterworth_at_the_cutoff(self):
        # the module's filter: 4th-order Butterworth, -3 dB at fc (|H|^2 = 1 / (1 + (f/fc)^8)),
        # so filtfilt's zero-phase gain is 1 / (1 + (f/fc)^8)
        from scipy import signal as sg
        prep = signals.Prepared(synthetic())
        fs = 1.0 / prep.dt
        # exact at fc (the bilinear transform is prewarped there), within 30 % of the
        # analogue response one octave above (the warping: 18 % at 100 Hz of 1 kHz; a 5th order is off by 75 %)
        for f_over, rel in ((1.0, 1e-6), (2.0, 0.3)):
            _, h = sg.freqz(prep._b, prep._a, worN=[f_over * prep.fc_hz], fs=fs)
            want = 1.0 / (1.0 + f_over ** 8)
            self.assertAlmostEqual(float(np.abs(h[0]) ** 2), want, delta=rel * want)

    def test_cutoff_capped_below_nyquist(self):
        # an asked-for cutoff at or above Nyquist is capped at FC_MAX_FRAC of it, below it
        log = synthetic()
        nyq = 0.5 / log.dt
        for fc in (0.9 * nyq, 5.0 * nyq):
            prep = signals.Prepared(log, fc_hz=fc)
            self.assertLess(prep.fc_hz, nyq)
            self.assertAlmostEqual(prep.fc_hz, signals.FC_MAX_FRAC * nyq, places=9)
        self.assertEqual(signals.Prepared(log, fc_hz=10.0).fc_hz, 10.0)


class SplitTest(unittest.TestCase):
    def test_held_out_is_the_last_part_and_disjoint(self):
        for n in (2000, 8000, 20001):
            prep = signals.Prepared(synthetic(n))
            tr, te = prep.train, prep.test
            edge = max(signals.EDGE_MIN, int(round(signals.EDGE_S / prep.dt)))
            # the fit's part first, then the held-out part, touching, not overlapping
            self.assertEqual(tr.start, edge)
            self.assertEqual(tr.stop, te.start)
            self.assertLess(tr.start, tr.stop)
            self.assertLess(te.start, te.stop)
            self.assertEqual(set(range(tr.start, tr.stop)) & set(range(te.start, te.stop)), set())
            # the held-out part runs to the end of the log (less the filter's edge)
            self.assertEqual(te.stop, prep.n - edge)
            self.assertEqual((prep.whole.start, prep.whole.stop), (tr.start, te.stop))
            # its share is 1 - TRAIN_FRAC of what the edges leave, to one sample
            share = (te.stop - te.start) / (te.stop - tr.start)
            self.assertAlmostEqual(share, 1.0 - signals.TRAIN_FRAC, delta=1.0 / (te.stop - tr.start))
            # later in time than every sample of the fit
            self.assertGreater(prep.t[te.start], prep.t[tr.stop - 1])

    def test_description_names_the_held_out_times(self):
        prep = signals.Prepared(synthetic())
        d = prep.held_out_description()
        self.assertIn(f"the last {100 * (1 - signals.TRAIN_FRAC):.0f} %", d)
        self.assertIn(f"t = {prep.t[prep.test.start]:.3f} .. {prep.t[prep.test.stop]:.3f} s", d)
        self.assertIn(f"({prep.test.stop - prep.test.start} samples)", d)
        self.assertIn(f"the fit used t = {prep.t[prep.train.start]:.3f} .. {prep.t[prep.test.start]:.3f} s", d)

    def test_description_at_another_share(self):
        # the description follows the share asked for, not only the default:
        # 60 % held out (99 or 101 times 0.6 would round to another percent),
        # and a held-out part longer than the fit's (its count is not hi % split)
        prep = signals.Prepared(synthetic(), train_frac=0.4)
        d = prep.held_out_description()
        self.assertIn("the last 60 % of the log in time", d)
        n_test = prep.test.stop - prep.test.start
        self.assertGreater(n_test, prep.test.start)
        self.assertIn(f"({n_test} samples)", d)
        self.assertAlmostEqual(n_test / (prep.test.stop - prep.train.start), 0.6,
                               delta=1.0 / (prep.test.stop - prep.train.start))

    def test_edges_and_share_are_the_docs(self):
        # docs/diagnose.md "Held-out part": the first and last 0.15 s, at least
        # 50 samples, are left out; the fit uses the first 70 % of the rest
        with open(os.path.join(REPO, "docs", "diagnose.md")) as f:
            doc = " ".join(f.read().split())
        m = re.search(r"\*\*Held-out part\*\*: the first and last ([\d.]+) s \(at least (\d+) samples\) "
                      r"are left out \(filter transients\); the fit uses the first (\d+) % of the rest", doc)
        self.assertIsNotNone(m, "docs/diagnose.md no longer states the held-out part's edges and share")
        edge_s, edge_min, train_pct = float(m.group(1)), int(m.group(2)), int(m.group(3))
        self.assertEqual(signals.TRAIN_FRAC * 100, train_pct)
        # at 1 ms the edge is 0.15 s; at 10 ms 0.15 s is 15 samples, so the least number rules
        for dt, edge in ((1e-3, int(round(edge_s / 1e-3))), (1e-2, edge_min)):
            prep = signals.Prepared(synthetic(4000, dt=dt))
            self.assertEqual((prep.lo, prep.n - prep.hi), (edge, edge), msg=f"dt = {dt}")
            self.assertEqual(prep.train.start, edge)
            self.assertEqual(prep.test.stop, prep.n - edge)

    def test_fit_never_sees_the_held_out_part(self):
        log = synthetic()
        prep = signals.Prepared(log)
        fit = model.solve(prep, SHAPE, (), {})
        # a large disturbance in the held-out part only (the filter's reach, a
        # few hundred samples at 50 Hz, kept away from the boundary)
        f2 = log.force.copy()
        k0 = prep.test.start + 400
        f2[k0:] += 40.0 * np.sin(np.arange(len(f2) - k0) * 0.05)
        prep2 = signals.Prepared(logreader.Log(log.path, log.t, log.ref, log.pos, f2, log.dt, log.n_total))
        fit2 = model.solve(prep2, SHAPE, (), {})
        for k in fit.coef:
            self.assertAlmostEqual(fit.coef[k], fit2.coef[k], delta=1e-9 * max(1.0, abs(fit.coef[k])), msg=k)
        # the training error is the same; the held-out error sees the disturbance
        self.assertAlmostEqual(fit.relerr(prep, prep.train), fit2.relerr(prep2, prep2.train), places=9)
        self.assertGreater(abs(fit2.relerr(prep2, prep2.test) - fit.relerr(prep, prep.test)), 5.0)

    def test_relerr_is_measured_on_the_held_out_part(self):
        prep = signals.Prepared(synthetic())
        fit = model.solve(prep, SHAPE, (), {})
        y, e = fit.target(prep), fit.residual(prep)
        te = prep.test
        self.assertAlmostEqual(fit.relerr(prep, te),
                               100.0 * np.linalg.norm(e[te]) / np.linalg.norm(y[te]), places=10)


if __name__ == "__main__":
    unittest.main()
