#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""make firmware's sub-step line (firmware/design/machine.py model_substeps,
docs/modules/model.md "Sub-steps"): rho h and n from the machine file as
br_model_init chooses them, each case computed here from the presliding
mode's characteristic equation with numpy's roots: the reference machine
needs one step at both estimators' periods; 16x stiffer bristles a 4x faster
mode; a large sigma1 the fast real root; elements keep one step.

Usage: test_model_substeps.py"""
import copy
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import DESIGN  # noqa: E402,F401  (puts firmware/design on the path)
import machine  # noqa: E402


def expected(m, T):
    """(rho T, n) from the roots of s^2 + b s + wn^2 (eq. S1) and eq. S2"""
    p = machine.params(m)
    meff = p["Jeff_kgm2"] / p["L_mprad"] ** 2
    rho = max(abs(r) for r in np.roots([1.0, (p["sigma1_Nspm"] + p["sigma2_Nspm"]) / meff, p["sigma0_Npm"] / meff]))
    c, _ = machine.model_substep_bounds()
    return rho * T, max(1, math.ceil(rho * T / c))


def main():
    fails = []
    ref = machine.load(machine.REFERENCE_MACHINE)
    if machine.model_substep_bounds() != (1.0, 32):
        fails.append("bounds read from br_model.h: %r" % (machine.model_substep_bounds(),))
    stiff = copy.deepcopy(ref)
    stiff["friction"]["sigma0_Npm"] *= 16.0
    damped = copy.deepcopy(ref)
    damped["friction"]["sigma1_Nspm"] = 3.0e5
    for name, m, want_n in (("reference", ref, 1), ("sigma0 x 16", stiff, 3), ("sigma1 3e5", damped, None)):
        for est, T in (("pf", m["estimator"]["pf"]["period_s"]), ("ukf", m["control"]["period_s"])):
            got, exp = machine.model_substeps(m, est), expected(m, T)
            if abs(got[0] - exp[0]) > 1e-9 * exp[0] or got[1] != exp[1] or (want_n and est == "pf" and got[1] != want_n):
                fails.append("%s, %s: %r, expected %r" % (name, est, got, exp))
    if not expected(damped, 1.0)[0] > 2.0 * math.sqrt(damped["friction"]["sigma0_Npm"] * machine.params(damped)["L_mprad"] ** 2
                                                       / machine.params(damped)["Jeff_kgm2"]):
        fails.append("sigma1 3e5 does not make the real root the fast one")
    for f in fails:
        print("FAIL: " + f, file=sys.stderr)
    print("model sub-steps: %d failures" % len(fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
