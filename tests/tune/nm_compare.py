#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Holds the C Nelder-Mead (nm_functions) against scipy.optimize's on the same
functions and starting points: the same minimum within tolerance and
evaluation counts of the same order (ratio within 1/3..3); prints both.

Usage: nm_compare.py PATH_TO_nm_functions"""
import json
import subprocess
import sys

import numpy as np
from scipy.optimize import minimize


def rosen(x):
    return 100.0 * (x[1] - x[0] ** 2) ** 2 + (1.0 - x[0]) ** 2


def beale(x):
    return ((1.5 - x[0] + x[0] * x[1]) ** 2 + (2.25 - x[0] + x[0] * x[1] ** 2) ** 2
            + (2.625 - x[0] + x[0] * x[1] ** 3) ** 2)


def powell(x):
    return ((x[0] + 10 * x[1]) ** 2 + 5 * (x[2] - x[3]) ** 2 + (x[1] - 2 * x[2]) ** 4
            + 10 * (x[0] - x[3]) ** 4)


CASES = {
    # name: (function, x0, true minimiser, tolerance on x)
    "rosenbrock": (rosen, [-1.2, 1.0], [1.0, 1.0], 1e-3),
    "beale": (beale, [1.0, 1.0], [3.0, 0.5], 1e-3),
    "powell": (powell, [3.0, -1.0, 0.0, 1.0], [0.0, 0.0, 0.0, 0.0], 5e-2),
}


def main(exe):
    c = json.loads(subprocess.run([exe], check=True, capture_output=True, text=True).stdout)
    ok = True
    print("%-11s %-34s %-34s %6s %6s" % ("function", "C minimiser (f)", "scipy minimiser (f)", "C fev", "scipy"))
    for name, (fn, x0, xtrue, tol) in CASES.items():
        s = minimize(fn, np.array(x0), method="Nelder-Mead",
                     options={"xatol": 1e-4, "fatol": 1e-4, "maxfev": 200 * len(x0)})
        xc = np.array(c[name]["x"])
        print("%-11s %-34s %-34s %6d %6d" % (
            name, "%s (%.2g)" % (np.array2string(xc, precision=4), c[name]["f"]),
            "%s (%.2g)" % (np.array2string(s.x, precision=4), s.fun), c[name]["nfev"], s.nfev))
        same_min = np.max(np.abs(xc - s.x)) <= tol and np.max(np.abs(xc - xtrue)) <= tol
        same_order = 1.0 / 3.0 <= c[name]["nfev"] / s.nfev <= 3.0
        if not (same_min and same_order and c[name]["converged"]):
            print("  FAIL: same minimum %s, evaluation counts of the same order %s, converged %s" % (
                same_min, same_order, bool(c[name]["converged"])))
            ok = False
    print("3 passed, 0 failed" if ok else "comparison failed")
    return 0 if ok else 1


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1]))
