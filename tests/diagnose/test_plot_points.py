# SPDX-License-Identifier: Apache-2.0
"""A figure draws each series with at most plots.MAX_POINTS points
(python/bristle/diagnose/plots.py: envelope for lines, dots for dot plots;
docs/diagnose.md "Memory": 2 million points drawn as they are took a
5-million-row diagnosis with figures to 1.75 GB):

- envelope keeps the order of x, every bucket's minimum and maximum (a
  one-sample spike stays), and a short series as it is;
- dots takes every k-th sample of all its arrays alike;
- force_fit, residuals and closed_loop on a stand-in log of 600 000
  samples: no drawn line holds more than MAX_POINTS points, and the figures
  are written."""
import os
import sys
import tempfile
import unittest

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
os.environ.setdefault("MPLBACKEND", "Agg")
from bristle.diagnose import plots  # noqa: E402

N = 600_000


class Fit:
    """A stand-in fitted model: a prediction and a residual over the intervals."""

    causes = ("offset",)

    def __init__(self, y):
        self.y = y

    def predict(self, prep):
        return self.y

    def residual(self, prep):
        return prep.y - self.y


class Prep:
    def __init__(self):
        rng = np.random.default_rng(1)
        self.dt = 1e-3
        self.t = np.arange(N + 1) * self.dt
        self.y = np.sin(self.t[:-1]) + 0.01 * rng.standard_normal(N)
        self.y[N // 3] = 40.0  # one spike
        self.v = np.cos(self.t[:-1])
        self.xm = np.sin(self.t[:-1])
        self.pos = self.ref = np.sin(self.t)
        self.force = np.concatenate((self.y, [0.0]))
        self.lo, self.hi, self.split = 50, N - 50, int(0.7 * N)
        self.whole = slice(self.lo, self.hi)

    def lp(self, x):
        return x


class Diag:
    def __init__(self, prep):
        self.nominal = Fit(0.9 * prep.y)
        self.extended = Fit(0.95 * prep.y)


class PlotPoints(unittest.TestCase):
    def test_envelope(self):
        x = np.arange(1_000_003.0)
        y = np.sin(x / 500.0)
        y[777_777] = 9.0
        xe, ye = plots.envelope(x, y)
        k = -(-len(x) // (plots.MAX_POINTS // 2))  # the bucket; the tail shorter than one is kept whole
        self.assertLessEqual(len(xe), plots.MAX_POINTS + k)
        self.assertTrue(np.all(np.diff(xe) >= 0))
        self.assertEqual(ye.max(), 9.0)
        self.assertAlmostEqual(ye.min(), y.min())
        self.assertIn(777_777.0, xe)
        short = np.arange(10.0)
        self.assertIs(plots.envelope(short, short)[1], short)

    def test_dots(self):
        a, b = np.arange(N), np.arange(N) * 2
        da, db = plots.dots(a, b)
        self.assertLessEqual(len(da), plots.MAX_POINTS)
        self.assertTrue(np.array_equal(db, 2 * da))
        self.assertEqual(len(plots.dots(a[:1000])[0]), 1000)

    def test_figures_bounded(self):
        prep = Prep()
        diag = Diag(prep)
        sims = {"nominal": {"q": prep.pos, "force": prep.force}, "extended": {"q": prep.pos, "force": prep.force}}
        drawn = []
        real_save = plots.save

        def save(fig, path):
            drawn.extend(len(line.get_xdata()) for ax in fig.axes for line in ax.get_lines())
            real_save(fig, path)

        plots.save = save
        try:
            with tempfile.TemporaryDirectory() as d:
                plots.force_fit(os.path.join(d, "f.png"), prep, diag)
                plots.residuals(os.path.join(d, "r.png"), prep, diag)
                plots.closed_loop(os.path.join(d, "c.png"), prep, sims)
                self.assertEqual(sorted(os.listdir(d)), ["c.png", "f.png", "r.png"])
        finally:
            plots.save = real_save
        self.assertGreater(len(drawn), 10)
        self.assertLessEqual(max(drawn), plots.MAX_POINTS + 64)  # + the tail of a bucket


if __name__ == "__main__":
    unittest.main()
