# SPDX-License-Identifier: Apache-2.0
"""The ISO 230-4 figures of the demo (sim/plots/iso230_4.py,
docs/circle-test.md) on synthetic circles whose figures are known in closed
form, the insertion into summary.json (only additions), and, with --bin, the
chain br_demo_circle --dir both -> iso230_4.py -> plot_demo.py.

Usage: test_iso230_4.py [--bin DIR --work DIR]"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "sim", "plots"))
import iso230_4  # noqa: E402

ARGS = None
A = 1e-4       # nominal radius, m
T = 8.0        # s per revolution
N = 36000      # samples per revolution: 0.01 deg apart
CENTRE = (2e-6, -1e-6)  # the path's centre, off the nominal one


def path(r_of_theta, ccw=False, n=N):
    """one revolution from (0, A) in the demo's sense (clockwise: x = A sin,
    y = A cos), samples at k T / n, k = 0 .. n-1: the reference and the actual
    points at radius r(theta) about CENTRE, theta the reference's polar angle (deg)"""
    t = np.arange(n) * (T / n)
    w = 2 * np.pi / T * (-1 if ccw else 1)
    x_ref, y_ref = A * np.sin(w * t), A * np.cos(w * t)
    th = np.arctan2(y_ref, x_ref)
    r = r_of_theta(np.degrees(th))
    return t, x_ref, y_ref, CENTRE[0] + r * np.cos(th), CENTRE[1] + r * np.sin(th)


def bumps(h, sigma, delta, ccw=False):
    """Gaussian bumps of height h, width sigma (deg), delta deg after each
    axis reversal (polar 0, 90, 180, 270) along the path: 4-fold symmetric,
    so that they do not move the least-squares centre"""
    sgn = 1 if ccw else -1  # the polar angle grows along a ccw path

    def r(th):
        out = np.full_like(th, A)
        for rev in (0.0, 90.0, 180.0, 270.0):
            u = np.mod(th - (rev + sgn * delta) + 180.0, 360.0) - 180.0
            out += h * np.exp(-0.5 * (u / sigma) ** 2)
        return out
    return r


class Synthetic(unittest.TestCase):
    def test_centre_and_G_of_an_out_of_round_circle(self):
        # r = A + c2 cos(2 theta) about CENTRE: G = 2 c2 exactly; without the centre's fit the 2.2 um offset dominates
        c2 = 1e-7
        t, xr, yr, x, y = path(lambda th: A + c2 * np.cos(np.radians(2 * th)))
        f = iso230_4.analyse(t, xr, yr, x, y)
        self.assertAlmostEqual(f["centre_m"][0], CENTRE[0], delta=1e-14)
        self.assertAlmostEqual(f["centre_m"][1], CENTRE[1], delta=1e-14)
        self.assertAlmostEqual(f["lsq_radius_m"], A, delta=1e-14)
        self.assertAlmostEqual(f["circular_deviation_m"], 2 * c2, delta=1e-14)
        self.assertAlmostEqual(f["radial_deviation_m"]["max"], c2, delta=1e-14)
        self.assertAlmostEqual(f["radial_deviation_m"]["min"], -c2, delta=1e-14)

    def test_centre_of_an_uneven_arc(self):
        # a true circle sampled unevenly over 290 deg: the least-squares centre is exact, G 0
        # (the samples' centroid is 30 um off: a centre taken as the mean point fails)
        th = np.radians(10 + 290 * np.linspace(0, 1, 5000) ** 2)
        x, y = CENTRE[0] + A * np.cos(th), CENTRE[1] + A * np.sin(th)
        a, b, R = iso230_4.lsq_circle(x, y)
        self.assertLess(max(abs(a - CENTRE[0]), abs(b - CENTRE[1]), abs(R - A)), 1e-15)
        self.assertGreater(np.hypot(x.mean() - CENTRE[0], y.mean() - CENTRE[1]), 1e-5)

    def check_spikes(self, h, ccw):
        sigma, delta = 3.0, 15.0  # the bump 5 sigma after the reversal: nothing of it in the local mean's arc
        t, xr, yr, x, y = path(bumps(h, sigma, delta, ccw), ccw)
        f = iso230_4.analyse(t, xr, yr, x, y)
        mean_b = 4 * h * sigma * np.sqrt(2 * np.pi) / 360  # the bumps' mean over the circle, absorbed by R
        self.assertAlmostEqual(f["lsq_radius_m"], A + mean_b, delta=1e-15)
        self.assertAlmostEqual(f["centre_m"][0], CENTRE[0], delta=1e-15)
        # G: the bump's peak to the flat circle between the bumps (max |d| would be h - mean_b)
        self.assertAlmostEqual(f["circular_deviation_m"], abs(h), delta=1e-15)
        # the three reversals the run crosses (its start and end, at 90 deg, are not crossings)
        sp = f["reversal_spikes"]
        want = [("x", 180.0, 2.0), ("y", 270.0, 4.0), ("x", 0.0, 6.0)] if ccw else \
               [("x", 0.0, 2.0), ("y", 270.0, 4.0), ("x", 180.0, 6.0)]
        self.assertEqual([(p["axis"], p["angle_deg"]) for p in sp], [w[:2] for w in want])
        fwhm = 2 * sigma * np.sqrt(2 * np.log(2))
        for p, (_, ang, tr) in zip(sp, want):
            self.assertAlmostEqual(p["t_s"], tr, delta=1e-9)
            # height above the local mean (-mean_b): h itself; the deviation's peak alone would read h - mean_b
            self.assertAlmostEqual(p["height_m"], h, delta=1e-13)
            self.assertAlmostEqual(p["local_mean_m"], -mean_b, delta=1e-13)
            self.assertAlmostEqual(p["peak_after_deg"], delta, delta=1e-6)
            self.assertAlmostEqual(p["peak_angle_deg"], np.mod(ang + (delta if ccw else -delta), 360), delta=1e-6)
            self.assertAlmostEqual(p["width_deg"], fwhm, delta=1e-3)
            self.assertAlmostEqual(p["width_s"], fwhm / 360 * T, delta=1e-4)
            self.assertFalse(p["width_clipped"])

    def test_spikes_outward_cw(self):
        self.check_spikes(5e-7, False)

    def test_spikes_inward_ccw(self):
        self.check_spikes(-3e-7, True)

    def test_hysteresis_and_bidirectional_deviation(self):
        # cw: A + c2 cos 2theta + c4 sin 4theta, ccw: the same with - c4 sin 4theta: H = 2 c4 at the
        # same polar angle (paired by time instead, the mirrored paths would read 0)
        c2, c4 = 1e-7, 2e-8
        cw = path(lambda th: A + c2 * np.cos(np.radians(2 * th)) + c4 * np.sin(np.radians(4 * th)))
        ccw = path(lambda th: A + c2 * np.cos(np.radians(2 * th)) - c4 * np.sin(np.radians(4 * th)), ccw=True)
        bi = iso230_4.bidirectional((cw[3], cw[4]), (ccw[3], ccw[4]))
        self.assertAlmostEqual(bi["circular_hysteresis_m"], 2 * c4, delta=1e-14)
        self.assertAlmostEqual(bi["centre_m"][0], CENTRE[0], delta=1e-14)
        # G(b): the range of both profiles together, evaluated densely from their formulas
        th = np.radians(np.linspace(0, 360, 3600001))
        both = np.concatenate([c2 * np.cos(2 * th) + c4 * np.sin(4 * th), c2 * np.cos(2 * th) - c4 * np.sin(4 * th)])
        self.assertAlmostEqual(bi["bidirectional_circular_deviation_m"], both.max() - both.min(), delta=1e-13)


SUMMARY = """{
  "experiment": {"radius_m": 1e-4, "period_s": 8, "duration_s": 8, "feed_mm_min": 4.71238898038469, "direction": "cw", "directions": ["cw"]},
  "hinf_only": {"dt_s": 0.001, "contour_rms_m": 2.287911e-06, "max_err_m": 7.482168e-06, "thesis_contour_rms_m": 2.400000e-06, "fhat_rms_err_N": 7.160612e+00, "saturated_steps": 0, "outlier_steps": 0, "trace": "trace_hinf_only.csv"},
  "realistic": {
    "plant": {"sigma0_Npm": 2.4e+06, "seed": 1},
    "hinf_only": {"dt_s": 0.001, "contour_rms_m": 2.358867e-06, "trace": "trace_real_hinf_only.csv"}
  }
}
"""


class Insertion(unittest.TestCase):
    def test_only_additions(self):
        res = {"trace_hinf_only.csv": {"circular_deviation_m": 1e-5, "reversal_spikes": []},
               "trace_real_hinf_only.csv": {"circular_deviation_m": 2e-5, "reversal_spikes": []}}
        new = iso230_4.insert(SUMMARY, res)
        # removing the insertions gives the original text byte for byte
        back = new
        for iso in res.values():
            back = back.replace(', "iso230_4": ' + json.dumps(iso), "")
        self.assertEqual(back, SUMMARY)
        s = json.loads(new)
        self.assertEqual(s["hinf_only"]["iso230_4"], res["trace_hinf_only.csv"])
        self.assertEqual(s["realistic"]["hinf_only"]["iso230_4"], res["trace_real_hinf_only.csv"])
        # run again (make demo twice over one summary): replaced, not added twice
        res2 = {k: {**v, "circular_deviation_m": 3e-5} for k, v in res.items()}
        again = iso230_4.insert(new, res2)
        self.assertEqual(again, iso230_4.insert(SUMMARY, res2))


class Chain(unittest.TestCase):
    def test_demo_both_directions(self):
        if not ARGS or not ARGS.bin:
            self.skipTest("no --bin")
        d = os.path.join(ARGS.work, "demo")
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(ARGS.work, exist_ok=True)
        r = subprocess.run([os.path.join(ARGS.bin, "br_demo_circle"), "--out", d, "--only", "hinf_only",
                            "--feed-mm-min", "60", "--dir", "both"], capture_output=True, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "summary.json")) as f:
            before = f.read()
        py = sys.executable
        env = dict(os.environ, MPLBACKEND="Agg")
        r = subprocess.run([py, os.path.join(ROOT, "sim", "plots", "iso230_4.py"), d], capture_output=True,
                           text=True, env=env, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("ISO 230-4 circular test", r.stdout)
        self.assertIn("cw / ccw pair", r.stdout)
        with open(os.path.join(d, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(iso230_4._strip(s), json.loads(before))
        for sec in (s, s["realistic"]):
            iso = sec["hinf_only"]["iso230_4"]
            self.assertEqual([(p["axis"], p["angle_deg"]) for p in iso["reversal_spikes"]],
                             [("x", 0.0), ("y", 270.0), ("x", 180.0)])
            self.assertGreater(iso["circular_deviation_m"], 0)
            self.assertEqual(iso["bidirectional"]["pair_trace"], sec["ccw"]["hinf_only"]["trace"])
            ccw = sec["ccw"]["hinf_only"]["iso230_4"]
            self.assertEqual([(p["axis"], p["angle_deg"]) for p in ccw["reversal_spikes"]],
                             [("x", 180.0), ("y", 270.0), ("x", 0.0)])
        r = subprocess.run([py, os.path.join(ROOT, "sim", "plots", "plot_demo.py"), d], capture_output=True,
                           text=True, env=env, timeout=600)
        self.assertEqual(r.returncode, 0, r.stderr)
        for f in ("iso230_4_polar.png", "real_iso230_4_polar.png"):
            self.assertGreater(os.path.getsize(os.path.join(d, f)), 10000, f)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin")
    ap.add_argument("--work")
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0], *rest])
