# SPDX-License-Identifier: Apache-2.0
"""The loop of the PF's shared external force as a linear map (docs/modules/pf.md,
"The period-2 mode"; issue 31 item 3).

One PF period h, the reference machine's numbers (machines/reference.json):
the axis a free mass M_eff (J / L^2 + m, positions in metres) whose torque
is the command of period j over [j h + D, (j + 1) h + D) (an actuator delay
D = (m + f) h, exactly integrated); the cloud's mean [x, v] predicted with
the torque the filter takes for it, (1 - f') c[k-m'] + f' c[k-m'-1] of the
identified delay D' = (m' + f') h, minus the load F_d, and corrected with
the load filter's steady-state Kalman gains K (Phi = [1 h -g; 0 1 -2g/h;
0 0 1], g = h^2 / (2 M_eff), q per period, measurement variance the
cloud's spread + R + rpc^2 / 12); the command c[k] the compensation of F_d
alone (the controller's share and the friction are left out: the loop's
period-2 mode is the load filter's and the delay's):

  plain   c[k] = F_d,k
  notch   c[k] = y_k,  y_k = (1 + r)/2 (F_d,k + F_d,k-1) - r y_k-1

The state: the axis' [x, v], the estimate [x, v, F_d], the commands of the
last periods (and F_d,k-1, y_k-1). Prints the largest |eigenvalue| for each
delay, the identified delay within 0.3 ms of it (the identification's step
is 0.5 ms). The axis' own pair at 1 (a free mass) is in every spectrum; a
mode beyond 1 is the ring.

The UKF's external-force state (--est ukf, docs/modules/ukf.md, "On in the
reference machine") has the same loop at the control period with the
UKF's R and no cloud spread; its identification's candidates are on the
same 0.5 ms grid. --unknown adds the map with the model's delay 0 (the
identification off or not yet decided).

Usage: pf_load_map.py [--est pf|ukf] [--q Q ...] [--spread S] [--unknown] [--check]
  --est E      the filter: pf (default; its period and R) or ukf (the control period, its R)
  --spread S   the cloud's spread var theta_j in units of R (default 1; the PF only)
  --unknown    also the largest |eigenvalue| with the model's delay 0
  --check      exit 1 unless: the plain loop holds (<= 1) at delays 0 .. 1.5 ms
               and rings (< -1) at 2 ms, at q = 1e4 N^2/s; the notch (its r
               read from firmware/private/br_pf_load.h) holds at every delay
               up to 3.5 ms and every q up to 3e5 N^2/s
"""
import argparse
import json
import math
import os
import re
import sys

import numpy as np

REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
DELAYS_MS = (0.0, 0.5, 1.0, 1.5, 1.775, 2.0, 2.263, 2.5, 3.0, 3.5)
ID_STEP_MS = 0.5   # machines/reference.json: estimator.pf.delay_id.step_s
ID_NEAR_MS = 0.3   # the identified delay: a candidate within this of the plant's
TOL = 1e-6         # the free mass' double eigenvalue 1 (a Jordan pair: 1 +- ~1e-8 in floating point)


def machine(est="pf"):
    with open(os.path.join(REPO, "machines", "reference.json")) as f:
        mm = json.load(f)
    L = mm["mechanics"]["lead_m_per_rev"] / (2.0 * math.pi)
    e = mm["estimator"][est]
    return {"M": mm["mechanics"]["inertia_kgm2"] / L ** 2 + mm["mechanics"]["table_mass_kg"],
            "h": e["period_s"] if est == "pf" else mm["control"]["period_s"], "R": e["position_noise_m2"],
            "rpc": mm["mechanics"]["lead_m_per_rev"] / mm["encoder"]["counts_per_rev"]}


def notch_r():
    with open(os.path.join(REPO, "firmware", "private", "br_pf_load.h")) as f:
        return float(re.search(r"#define BR_PF_LOAD_NOTCH_R ([0-9.]+)f", f.read()).group(1))


def gains(mc, q, s):
    """The load filter's steady-state Kalman gain (P <- Phi P Phi^T + diag(0, 0, q h), then
    the update on x with variance s)."""
    h, g = mc["h"], mc["h"] ** 2 / (2.0 * mc["M"])
    Phi = np.array([[1.0, h, -g], [0.0, 1.0, -2.0 * g / h], [0.0, 0.0, 1.0]])
    P = np.diag([0.0, 0.0, 502.0 ** 2])
    K = np.zeros(3)
    for _ in range(100000):
        P = Phi @ P @ Phi.T + np.diag([0.0, 0.0, q * h])
        Kn = P[:, 0] / (P[0, 0] + s)
        P = P - np.outer(Kn, P[0, :])
        if np.allclose(Kn, K, rtol=1e-13, atol=0.0):
            break
        K = Kn
    return K


def loop(mc, K, D, Dh, r=None, n_hist=6):
    """The map of one period (state at k -> k + 1) for a plant delay D and an identified
    delay Dh (s); r None: the plain compensation, else the notch's pole."""
    h, M = mc["h"], mc["M"]
    g = h * h / (2.0 * M)
    m, f = int(D / h + 1e-12), D / h - int(D / h + 1e-12)
    mh, fh = int(Dh / h + 1e-12), Dh / h - int(Dh / h + 1e-12)
    assert m + 2 <= n_hist and mh + 2 <= n_hist
    # state: 0 x, 1 v, 2 xh, 3 vh, 4 F_d, 5.. c[k-1] .. c[k-n_hist], then F_d,k-1, y_k-1 (notch)
    nc = 5 + n_hist
    n = nc + (2 if r is not None else 0)

    def cmd(j):
        """c[k-j] as a row over the state at k (j = 0: the command issued at k)"""
        row = np.zeros(n)
        if j > 0:
            row[5 + j - 1] = 1.0
        elif r is None:
            row[4] = 1.0
        else:
            c = 0.5 * (1.0 + r)
            row[4], row[nc], row[nc + 1] = c, c, -r
        return row

    A = np.zeros((n, n))
    # the axis: c[k-m-1] over [0, f h), c[k-m] over [f h, h)
    A[0, 0], A[0, 1], A[1, 1] = 1.0, h, 1.0
    A[0] += (h * h / (2.0 * M)) * ((2.0 * f - f * f) * cmd(m + 1) + (1.0 - f) ** 2 * cmd(m))
    A[1] += (h / M) * (f * cmd(m + 1) + (1.0 - f) * cmd(m))
    # the estimate's prediction with the interpolated torque, minus F_d
    ua = (1.0 - fh) * cmd(mh) + fh * cmd(mh + 1)
    E = np.zeros((3, n))
    E[0, 2], E[0, 3], E[0, 4] = 1.0, h, -g
    E[0] += (h * h / (2.0 * M)) * ua
    E[1, 3], E[1, 4] = 1.0, -2.0 * g / h
    E[1] += (h / M) * ua
    E[2, 4] = 1.0
    # the update on the innovation x - xh (both after the period)
    A[2:5] = E + np.outer(K, A[0] - E[0])
    A[5] = cmd(0)
    for j in range(2, n_hist + 1):
        A[5 + j - 1] = cmd(j - 1)
    if r is not None:
        A[nc, 4] = 1.0
        A[nc + 1] = cmd(0)
    return A


def worst(mc, K, D, r):
    """The largest |eigenvalue| over the identified delays near D, and that eigenvalue."""
    best = (0.0, 0.0)
    k = 0
    while k * ID_STEP_MS <= 3.5 + 1e-9:
        dh = k * ID_STEP_MS
        if abs(dh - D) <= ID_NEAR_MS + 1e-9:
            ev = np.linalg.eigvals(loop(mc, K, D * 1e-3, dh * 1e-3, r))
            i = int(np.argmax(np.abs(ev)))
            if abs(ev[i]) > best[0]:
                best = (float(abs(ev[i])), complex(ev[i]))
        k += 1
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--est", choices=("pf", "ukf"), default="pf")
    ap.add_argument("--q", type=float, nargs="*", default=[1e3, 1e4, 1e5, 3e5])
    ap.add_argument("--spread", type=float, default=1.0)
    ap.add_argument("--unknown", action="store_true")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    if a.check and a.est != "pf":
        ap.error("--check is the PF's (its notch)")
    mc, r = machine(a.est), notch_r()
    spread = a.spread if a.est == "pf" else 0.0
    s = spread * mc["R"] + mc["R"] + mc["rpc"] ** 2 / 12.0
    ok = True
    print(f"M_eff {mc['M']:.4g} kg, h {mc['h'] * 1e3:g} ms, notch r {r:g}; largest |eigenvalue| "
          f"(its value) over identified delays within {ID_NEAR_MS} ms")
    for q in a.q:
        K = gains(mc, q, s)
        g = mc["h"] ** 2 / (2.0 * mc["M"])
        print(f"q {q:g} N^2/s: K_x {K[0]:.4f}, K_v h {K[1] * mc['h']:.4f}, K_F g {K[2] * g:.4f}")
        for D in DELAYS_MS:
            p, pe = worst(mc, K, D, None)
            nn, ne = worst(mc, K, D, r)
            unk = ""
            if a.unknown:
                ev = np.linalg.eigvals(loop(mc, K, D * 1e-3, 0.0, None))
                unk = f"   model's delay 0: {float(np.max(np.abs(ev))):.3f}"
            print(f"  delay {D:5.3f} ms: plain {p:.3f} ({pe.real:+.3f}{pe.imag:+.3f}j)   "
                  f"notch {nn:.3f} ({ne.real:+.3f}{ne.imag:+.3f}j){unk}")
            if a.check:
                if q <= 3e5 and nn > 1.0 + TOL:
                    ok = False
                    print("    CHECK: the notch rings here")
                if q == 1e4 and D <= 1.5 and p > 1.0 + TOL:
                    ok = False
                    print("    CHECK: the plain loop was expected to hold here")
                if q == 1e4 and D == 2.0 and not pe.real < -1.0 - 1e-3:
                    ok = False
                    print("    CHECK: the plain loop was expected to ring here")
    if a.check and 1e4 not in a.q:
        ok = False
        print("CHECK: --check needs q = 1e4 among --q")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
