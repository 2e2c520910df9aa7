# SPDX-License-Identifier: Apache-2.0
"""What the EMPS log's residual near zero velocity is (docs/machines/emps.md,
"The residual near zero velocity"): presliding, a Stribeck shape, or
something else.

The diagnosis's model after its finding (nominal + asymmetric friction,
python/bristle/diagnose) is refitted on the log, and beside it
  - + presliding_hysteresis (a Maxwell-slip element set replacing the
    bristle, causes/presliding_hysteresis.py),
  - the same model with the Stribeck curve allowed below the Coulomb level
    (Fs/Fc < 1, friction lower at low speed than the sliding line), the
    best point of a grid of Fs/Fc and vs (the diagnosis bounds Fs/Fc to
    [1, 10]: a hump),
each measured on the held-out part (the last 30 % in time). The residual
of the first model is then split by speed, by accelerating or
decelerating, by direction, and by the travel since the last reversal
(where presliding lives).

Usage: emps_low_speed.py --log ../shared/data/emps/emps_estimation.csv
Prints markdown tables; about 30 s."""
import argparse
import os
import sys

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
from bristle.diagnose import logreader, model, signals  # noqa: E402
from bristle.diagnose.causes import presliding_hysteresis as ps  # noqa: E402

SLOW_MPS = 1e-2          # "near zero velocity": under 1 cm/s (the log's moves reach 0.125 m/s)
BETAS = (0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
VSS = (1e-3, 2e-3, 4e-3, 8e-3, 1.6e-2, 3.2e-2)
SPEED_BINS = (0.0, 5e-4, 2e-3, 1e-2, 3e-2, 10.0)
TRAVEL_BINS = (0.0, 10e-6, 30e-6, 100e-6, 1e-3, 10.0)


def rms(x):
    return float(np.sqrt(np.mean(x ** 2))) if len(x) else float("nan")


def fits(prep):
    # the diagnosis does not test the cause on this log (45 presliding samples, under
    # ps.MIN_PRESLIDING_SAMPLES): fitted here all the same, to measure what it would give
    ps.MIN_PRESLIDING_SAMPLES = 0
    nominal = model.fit_nominal(prep)
    asym = model.refine(prep, model.add_cause(prep, nominal, "asymmetric_friction"))
    pres = model.refine(prep, model.add_cause(prep, asym, ps.NAME))
    low = min((model.solve(prep, (asym.shape[0], b, vs), asym.causes, asym.nl) for b in BETAS for vs in VSS),
              key=lambda f: f.train_sse)
    return nominal, asym, pres, low


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--log", required=True)
    a = ap.parse_args()
    prep = signals.Prepared(logreader.read_log(a.log))
    nominal, asym, pres, low = fits(prep)
    te, tr, w = prep.test, prep.train, prep.whole
    held = (np.arange(prep.n) >= prep.split)[w]
    v, acc = prep.v[w], prep.a[w]
    slow = np.abs(v) < SLOW_MPS
    print("| model | held-out relerr | training relerr | residual RMS under 1 cm/s (held-out) |")
    print("|---|---|---|---|")
    for name, f in (("nominal", nominal), ("nominal + asymmetric_friction (the diagnosis's)", asym),
                    ("+ presliding_hysteresis", pres),
                    (f"asymmetric, Stribeck below Fc: Fs/Fc = {low.shape[1]:.2g}, vs = {low.shape[2]:.2g} m/s", low)):
        e = f.residual(prep)[w]
        print(f"| {name} | {f.relerr(prep, te):.3f} % | {f.relerr(prep, tr):.3f} % | {rms(e[slow & held]):.2f} N |")
    print()
    cp = pres.cause_params(ps.NAME)
    print(f"presliding_hysteresis's element set: "
          + ", ".join(f"{1e6 * q['breakaway_m']:.3g} um ({100 * q['share']:.0f} %)" for q in cp["elements"])
          + f"; presliding_m {1e6 * cp['presliding_m']:.3g} um")
    print()
    e = asym.residual(prep)[w]
    s = ps.since_reversal(prep)[w]
    print("Residual of nominal + asymmetric_friction (whole log less the edges), mean of residual x sign(v):")
    print()
    print("| samples | count | mean e sgn(v) | RMS |")
    print("|---|---|---|---|")
    for lo, hi in zip(SPEED_BINS[:-1], SPEED_BINS[1:]):
        m = (np.abs(v) >= lo) & (np.abs(v) < hi)
        print(f"| {lo:g} <= abs(v) < {hi:g} m/s | {m.sum()} | {np.mean(e[m] * np.sign(v[m])):+.2f} N | {rms(e[m]):.2f} N |")
    for name, m in (("under 1 cm/s, accelerating", slow & (v * acc > 0)), ("under 1 cm/s, decelerating", slow & (v * acc < 0)),
                    ("under 1 cm/s, in +x", slow & (v > 0)), ("under 1 cm/s, in -x", slow & (v < 0))):
        print(f"| {name} | {m.sum()} | {np.mean(e[m] * np.sign(v[m])):+.2f} N | {rms(e[m]):.2f} N |")
    for lo, hi in zip(TRAVEL_BINS[:-1], TRAVEL_BINS[1:]):
        m = (s >= lo) & (s < hi)
        print(f"| travel since the last reversal {1e6 * lo:g} .. {1e6 * hi:g} um | {m.sum()} | "
              f"{np.mean(e[m] * np.sign(v[m])):+.2f} N | {rms(e[m]):.2f} N |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
