#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The H-infinity design (firmware/design/synth_hinf.py) cross-checked against
python-control and its SLICOT routines (docs/modules/hinf.md, "Cross-check"):

  - `synth_hinf.py --report` is accepted (its usage advertises it) and prints
    the margins and bandwidth;
  - gamma_min: python-control's hinfsyn (SLICOT SB10AD, output feedback) on the
    same generalised plant, measuring the full state with a small noise eps
    (SB10AD needs D21 of full row rank); its optimal gamma lies above the
    full-information gamma_min and tends to it as eps -> 0;
  - the closed-loop H-inf norm of our K: control.system_norm (SLICOT AB13DD);
  - the continuous and sampled loops' margins: control.stability_margins;
  - the closed-loop bandwidth: control.bandwidth of T = feedback(L, 1).
The machine's values come from the machine file through firmware/design's
loader; no figure is copied here."""
import os
import re
import subprocess
import sys

import control as ct
import numpy as np

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DESIGN = os.path.join(REPO, "firmware", "design")
sys.path.insert(0, DESIGN)
import loop_analysis  # noqa: E402
import machine  # noqa: E402
import synth_hinf  # noqa: E402

FAILS = []


def check(ok, what):
    print("%s: %s" % ("ok  " if ok else "FAIL", what))
    if not ok:
        FAILS.append(what)


def rel(a, b):
    return abs(a - b) / abs(b)


def report_numbers(work):
    """Runs synth_hinf.py --report; the printed figures by loop (continuous, each dt)."""
    r = subprocess.run([sys.executable, os.path.join(DESIGN, "synth_hinf.py"), "--report",
                        "--out", os.path.join(work, "gains.h")], capture_output=True, text=True)
    check(r.returncode == 0, "synth_hinf.py --report exits 0 (%s)" % r.stderr.strip())
    h = subprocess.run([sys.executable, os.path.join(DESIGN, "synth_hinf.py"), "--help"], capture_output=True, text=True)
    check("--report" in h.stdout, "synth_hinf.py --help lists --report")
    out = {}
    pat = re.compile(r"^\s+(continuous|sampled at ([0-9.]+) ms): phase margin ([0-9.e+-]+) deg at ([0-9.e+-]+) Hz; "
                     r"gain margin up (no upper limit|[+-][0-9.]+ dB \(x([0-9.e+-]+)\) at ([0-9.e+-]+) Hz), "
                     r"down (no lower limit|[+-][0-9.]+ dB \(x([0-9.e+-]+)\) at ([0-9.e+-]+) Hz); "
                     r"closed-loop bandwidth \(-3 dB of theta/theta_ref\) ([0-9.e+-]+) Hz$")
    for line in r.stdout.splitlines():
        m = pat.match(line)
        if m:
            key = "continuous" if m.group(1) == "continuous" else float(m.group(2)) * 1e-3
            f = lambda g: float(g) if g is not None else None  # noqa: E731
            out[key] = dict(pm=f(m.group(3)), f_pm=f(m.group(4)), gm_up=f(m.group(6)), f_up=f(m.group(7)),
                            gm_down=f(m.group(9)), f_down=f(m.group(10)), bw=f(m.group(11)))
    return out, r.stdout


def ct_bandwidth(T):
    """control.bandwidth; for a sampled T (which control.bandwidth does not bracket) the first
    frequency below the Nyquist frequency where python-control's own response of T falls 3 dB."""
    if T.isctime():
        return ct.bandwidth(T)
    lim = abs(T.dcgain()) * 10 ** (-3 / 20)
    w = np.logspace(-2, np.log10(np.pi / T.dt * (1 - 1e-9)), 20000)
    mag = np.abs(T.frequency_response(w).complex.ravel())
    i = int(np.nonzero(mag < lim)[0][0])
    lo, hi = w[i - 1], w[i]
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if abs(T(np.exp(1j * mid * T.dt))) < lim:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def main():
    work = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(work, exist_ok=True)
    m = machine.load(machine.REFERENCE_MACHINE)
    p, wts = machine.params(m), synth_hinf.weights(m)
    d = synth_hinf.design(p, wts)
    A, B2 = synth_hinf.plant(p)
    B1 = B2 * (p["L_mprad"] * p["Fs_N"])
    Cz = np.diag(wts["Cz_diag"])
    Dz = np.array([[1.0 / wts["u_norm_Nm"]]])
    K = d["K"]

    # gamma_min against SB10AD: z = [Cz x; Dz u], y = x + eps n, w = [w_f; n]
    gams = []
    for eps in (1e-3, 1e-4, 1e-5):
        Bp = np.hstack([B1, np.zeros((3, 3)), B2])
        Cp = np.vstack([Cz, np.zeros((1, 3)), np.eye(3)])
        Dp = np.zeros((7, 5))
        Dp[3, 4] = Dz[0, 0]
        Dp[4:, 1:4] = eps * np.eye(3)
        Kc, CL, gam, _ = ct.hinfsyn(ct.ss(A, Bp, Cp, Dp), 3, 1)
        check(np.all(CL.poles().real < 0), "hinfsyn (eps %g): a stable closed loop" % eps)
        gams.append(gam)
        print("     hinfsyn eps %g: gamma %.9g (ours, full information: gamma_min %.9g)" % (eps, gam, d["gamma_min"]))
    check(all(g >= d["gamma_min"] * (1 - 1e-8) for g in gams), "hinfsyn's gamma >= our gamma_min (full information "
          "is the lower bound; 1e-8: our bisection's tolerance is 1e-9)")
    check(gams[0] >= gams[1] >= gams[2], "hinfsyn's gamma falls as the measurement noise eps falls")
    check(rel(gams[-1], d["gamma_min"]) < 1e-5, "gamma_min agrees with hinfsyn's at eps 1e-5 (rel %.2e < 1e-5)"
          % rel(gams[-1], d["gamma_min"]))

    # the closed-loop norm of our K against AB13DD
    Acl = A + B2 @ K[None, :]
    Ccl = np.vstack([Cz, Dz @ K[None, :]])
    n_ct = ct.system_norm(ct.ss(Acl, B1, Ccl, np.zeros((4, 1))), p="inf")
    check(rel(d["norm"], n_ct) < 1e-6, "closed-loop H-inf norm %.9g, python-control %.9g (rel %.1e < 1e-6)"
          % (d["norm"], n_ct, rel(d["norm"], n_ct)))
    check(d["norm"] <= d["gamma"], "closed-loop norm below gamma")

    # margins and bandwidth: ours (loop_analysis, as printed by --report) against python-control
    printed, text = report_numbers(work)
    print(text)
    loops = {"continuous": ct.ss(A, B2, -K[None, :], 0)}
    for dt in wts["check_dt_s"]:
        Phi0, Gu, Ku = loop_analysis.sampled_open_loop(A, B2, K, dt)
        loops[dt] = ct.ss(Phi0, Gu, -Ku, 0, dt)
    ours_all = loop_analysis.analyse(A, B2, K, wts["check_dt_s"])
    hz = 1.0 / (2.0 * np.pi)
    for key, L in loops.items():
        name = "continuous" if key == "continuous" else "sampled at %g ms" % (key * 1e3)
        ours, pr = ours_all[key], printed.get(key)
        check(pr is not None, "%s: the report prints its margins and bandwidth" % name)
        if pr is None:
            continue
        # the sampled loop through python-control's frequency-response method: its polynomial
        # method (the default) reports a gain crossover at 7.4 Hz with 22 deg there, where |L|
        # is 4.8 (two poles at z = 1 make the polynomial ill-conditioned)
        method = "poly" if L.isctime() else "frd"
        gm, pm, _, wpc, wgc, _ = ct.stability_margins(L, returnall=True, method=method)
        # python-control lists every crossing; ours are above 0.01 rad/s (below it the double
        # integrator's asymptote at -180 deg gives only numerical crossings)
        keep = wpc > 1e-2
        gm, wpc = gm[keep], wpc[keep]
        keep = wgc > 1e-2
        pm, wgc = pm[keep], wgc[keep]
        i = int(np.argmin(pm))
        check(abs(pr["pm"] - pm[i]) < 0.01 and rel(pr["f_pm"], wgc[i] * hz) < 1e-3,
              "%s: phase margin %.2f deg at %.4g Hz; python-control %.4f deg at %.5g Hz"
              % (name, pr["pm"], pr["f_pm"], pm[i], wgc[i] * hz))
        down = gm < 1
        j = int(np.argmax(np.where(down, gm, -1.0)))
        check(down.any() and pr["gm_down"] is not None and rel(pr["gm_down"], gm[j]) < 1e-3
              and rel(pr["f_down"], wpc[j] * hz) < 1e-3,
              "%s: lower gain margin x%s at %s Hz; python-control x%.5g at %.5g Hz"
              % (name, pr["gm_down"], pr["f_down"], gm[j] if down.any() else np.nan, wpc[j] * hz))
        up = gm > 1
        if up.any():
            j = int(np.argmin(np.where(up, gm, np.inf)))
            check(pr["gm_up"] is not None and rel(pr["gm_up"], gm[j]) < 1e-3 and rel(pr["f_up"], wpc[j] * hz) < 1e-3,
                  "%s: upper gain margin x%s at %s Hz; python-control x%.5g at %.5g Hz"
                  % (name, pr["gm_up"], pr["f_up"], gm[j], wpc[j] * hz))
        else:
            check(pr["gm_up"] is None and not np.isfinite(ours["gm_up"]),
                  "%s: no upper gain limit, as python-control finds" % name)
        bw = ct_bandwidth(ct.feedback(L, 1))
        check(rel(pr["bw"], bw * hz) < 1e-3, "%s: closed-loop bandwidth %.4g Hz; python-control %.5g Hz"
              % (name, pr["bw"], bw * hz))
    if FAILS:
        print("%d check(s) failed" % len(FAILS))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
