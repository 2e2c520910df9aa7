# SPDX-License-Identifier: Apache-2.0
"""br_tune_est --guard-outliers K (docs/tuning.md, "A noise-aware
objective"): the PF's objective is the nominal one times (1 + K x the outlier
steps of the guard plants' runs). From the tuner's second start (where the
guard plants' runs have outlier steps with the committed machine) the
printed start value with K must be the one with K = 0 times 1 + K n for a
whole number n >= 1; the header names the objective only with K > 0, and
without the option the tuner runs its default K (BR_TUNE_GUARD_OUTLIERS_PF,
`make tune`'s objective) and names it (its bounds and where it is refused:
test_tools.py). Run with a release build of the tuner.

Usage: test_tune_guard_outliers.py --tuner BIN --work DIR"""
import os
import re
import subprocess
import sys

import tool_check

K = 0.1


def start2(tuner, out, extra):
    # the thesis filter (--pf-load 0): with the machine's shared external force the guard plants'
    # runs have no outlier step to count; no Maxwell-slip guard (its factor is the same for every K)
    r = subprocess.run([tuner, "--est", "pf", "--out", out, "--max-fev", "5", "--pf-load", "0", "--mslip-target", "0"] + extra,
                       capture_output=True, text=True)
    m = re.search(r"start 2, contour RMS (\S+) m", r.stdout)
    if r.returncode != 0 or not m:
        sys.exit("br_tune_est %s: exit %d, no start-2 line:\n%s%s" % (" ".join(extra), r.returncode, r.stdout, r.stderr))
    return float(m.group(1))


def main():
    tuner, work = tool_check.start("tuner")
    fails = []
    h0, hk, hd = os.path.join(work, "k0.h"), os.path.join(work, "k.h"), os.path.join(work, "kd.h")
    f0 = start2(tuner, h0, ["--guard-outliers", "0"])
    fk = start2(tuner, hk, ["--guard-outliers", str(K)])
    fd = start2(tuner, hd, [])
    n = (fk / f0 - 1.0) / K
    print("start 2: %.4e m without, %.4e m with --guard-outliers %g: %.3f outlier steps" % (f0, fk, K, n))
    # the printed values have 5 significant digits
    if not (n >= 0.5 and abs(n - round(n)) <= 1e-3 * max(1.0, n)):
        fails.append("the ratio %.6g is not 1 + %g n for a whole n >= 1" % (fk / f0, K))
    with open(h0) as f:
        t0 = f.read()
    with open(hk) as f:
        tk = f.read()
    if "--guard-outliers" in t0 or "(1 + %g x the guard plants' outlier steps)" % K not in tk:
        fails.append("the header does not name the objective (only) with --guard-outliers")
    # the default: the source's BR_TUNE_GUARD_OUTLIERS_PF, named in the header, the same factor
    src = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "sim", "apps", "br_tune_est.c")
    with open(src) as f:
        kd = float(re.search(r"#define BR_TUNE_GUARD_OUTLIERS_PF (\S+)", f.read()).group(1))
    with open(hd) as f:
        td = f.read()
    if kd <= 0.0 or "(1 + %g x the guard plants' outlier steps)" % kd not in td:
        fails.append("the default header does not name the default objective (K = %g)" % kd)
    nd = (fd / f0 - 1.0) / kd
    if abs(nd - n) > 1e-2 * max(1.0, n):
        fails.append("the default's factor %.6g is not 1 + %g x the %.3f outlier steps" % (fd / f0, kd, n))
    return tool_check.finish(fails)


if __name__ == "__main__":
    sys.exit(main())
