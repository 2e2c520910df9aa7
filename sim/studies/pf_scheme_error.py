#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""One-step error of a two-stage prediction for the PF (docs/modules/pf.md,
"Heun's step: measured, not adopted").

On the plant states of the golden circle trace (golden/traces/est_input.csv:
the x axis of the thesis circle at 1.5 ms, plant state and applied torque per
step), each state x_k = (0, omega_k, z_k, g(v_k)) (g_p = the plant's Stribeck
level) is stepped over h with the torque of the next period by RK4 and by
Heun's step (heun() below), in float64 (golden/ref/model.py's eq. 6), and
by RK4 with 64 substeps as the reference. Prints the error of f_nl (eq. 3) of each scheme against the
reference: median, p90, p99 and max over the steps, and the step of the max.

Usage: pf_scheme_error.py"""
import os
import sys

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "golden"))
import gen_est_traces  # noqa: E402
import gen_traces  # noqa: E402
from ref import lugre as rl  # noqa: E402
from ref import model as rm  # noqa: E402

SUBSTEPS = 64
COL_U, COL_OMEGA, COL_Z = 4, 8, 9  # est_input.csv: k,t,counts,frac,u_prev_Nm,fault,ref_counts,theta,omega,z,...


def heun(p, x, u, h):
    """Heun's two-stage step of eq. 6 with u held: x + h/2 (f(x) + f(x + h f(x)))"""
    k1 = rm.deriv(p, x, u)
    k2 = rm.deriv(p, x + h * k1, u)
    return x + (h / 2.0) * (k1 + k2)


def main():
    m = gen_traces.load_machine()
    p = gen_est_traces.model_params_f32(m, gen_traces.f32)
    h = gen_traces.f32(gen_est_traces.EST_DT)
    path = os.path.join(ROOT, "golden", "traces", "est_input.csv")
    with open(path) as f:
        rows = np.array([[float(v) for v in line.split(",")] for line in f if line[0].isdigit()])
    err = {"RK4": [], "Heun": []}
    for k in range(len(rows) - 1):
        w, z, u = rows[k, COL_OMEGA], rows[k, COL_Z], rows[k + 1, COL_U]
        gp = rl.g(p.lugre, p.L * w)  # eq. 5
        x = np.array([0.0, w, z, gp])
        ref = x.copy()
        for _ in range(SUBSTEPS):
            ref = rm.rk4(p, ref, u, h / SUBSTEPS)
        f_ref = rm.fnl(p, ref)
        err["RK4"].append(abs(rm.fnl(p, rm.rk4(p, x, u, h)) - f_ref))
        err["Heun"].append(abs(rm.fnl(p, heun(p, x, u, h)) - f_ref))
    print("one-step error of f_nl against RK4 with %d substeps, %d plant states of %s, h = %.4g s"
          % (SUBSTEPS, len(rows) - 1, os.path.relpath(path, ROOT), h))
    for name, e in err.items():
        e = np.array(e)
        print("  %-5s median %.2g N  p90 %.2g N  p99 %.2g N  max %.3g N (step %d)"
              % (name, np.median(e), np.percentile(e, 90), np.percentile(e, 99), e.max(), int(e.argmax())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
