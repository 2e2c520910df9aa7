# SPDX-License-Identifier: Apache-2.0
"""Margins and bandwidth of the H-infinity loop (docs/modules/hinf.md,
"Margins and bandwidth"), computed here from the frequency responses,
independently of python-control (which tests/design cross-checks them with).

The loop is broken at the torque input u (the one actuator):
    continuous  L(s) = -K (sI - A)^-1 B2                  (A, B2 of the augmented model)
    sampled     L(z) = -Ku (zI - Phi0)^-1 Gu              (the loop as implemented at dt:
                ZOH plant, rectangular integral, backward-difference velocity; Phi0 its open loop)
Gain crossover |L| = 1: phase margin PM = arg(-L) in degrees. Phase crossover
Im L = 0 with Re L < 0: gain margin GM = 1/|L| (> 1: how much the gain may rise;
< 1: how far it may fall, the loop being conditionally stable with its two
integrators). Crossings are bracketed on a log grid and refined by Brent's method.
Closed-loop bandwidth: the first frequency where |T| = |L/(1+L)| falls 3 dB below
|T(0)| (= 1, integral action); T is also theta/theta_ref, the position's
response to its reference, since u acts on the errors.
"""
import numpy as np
import scipy.linalg as sla
from scipy.optimize import brentq

DB_DROP = -3.0


def _solve_each(s, A, B, K):
    """-K (s_i I - A)^-1 B for each s_i of the array s (one batched solve)."""
    n = A.shape[0]
    M = s[:, None, None] * np.eye(n)[None] - A[None]
    x = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (len(s),) + B.shape))
    return -(np.asarray(K, dtype=float).reshape(1, -1) @ x)[:, 0, 0]


def continuous_loop(A, B2, K):
    """L(jw) for an array of w (rad/s)."""

    def resp(w):
        w = np.atleast_1d(np.asarray(w, dtype=float))
        return _solve_each(1j * w, A, B2, K)
    return resp


def sampled_open_loop(A, B2, K, dt):
    """Phi0, Gu, Ku of the loop as implemented at dt, state [theta_k, omega_k, eps_k, theta_{k-1}]:
    u_k = k0 th_k + k1 (th_k - th_{k-1})/dt + k2 eps_k, applied through a ZOH."""
    Ap, Bp = A[:2, :2], B2[:2]
    M = sla.expm(np.block([[Ap, Bp], [np.zeros((1, 3))]]) * dt)
    Ad, Bd = M[:2, :2], M[:2, 2:]
    k0, k1, k2 = K
    Ku = np.array([[k0 + k1 / dt, 0.0, k2, -k1 / dt]])
    Phi0 = np.zeros((4, 4))
    Phi0[:2, :2] = Ad
    Phi0[2, :] = [dt, 0.0, 1.0, 0.0]
    Phi0[3, :] = [1.0, 0.0, 0.0, 0.0]
    Gu = np.zeros((4, 1))
    Gu[:2] = Bd
    return Phi0, Gu, Ku


def sampled_loop(A, B2, K, dt):
    """L(e^{jw dt}) for an array of w (rad/s, up to the Nyquist frequency pi/dt)."""
    Phi0, Gu, Ku = sampled_open_loop(A, B2, K, dt)

    def resp(w):
        w = np.atleast_1d(np.asarray(w, dtype=float))
        return _solve_each(np.exp(1j * w * dt), Phi0, Gu, Ku)
    return resp


def _roots(f, w):
    """Refined roots of the real function f over the sorted grid w (sign changes)."""
    v = f(w)
    out = []
    for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
        out.append(brentq(lambda x: float(f(np.array([x]))[0]), w[i], w[i + 1], xtol=1e-12, rtol=1e-12))
    return out


def margins(resp, w_lo, w_hi, n=20000):
    """Every crossing of L over [w_lo, w_hi] rad/s: dict with
    gain_crossings [(w, PM deg)], phase_crossings [(w, GM)], and the worst:
    pm_deg, w_pm (smallest PM), gm_up, w_gm_up (smallest GM > 1, inf if none),
    gm_down, w_gm_down (largest GM < 1, 0 if none)."""
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), n)
    gc = [(x, float(np.degrees(np.angle(-resp(x)[0])))) for x in _roots(lambda v: np.abs(resp(v)) - 1.0, w)]
    pc = []
    for x in _roots(lambda v: resp(v).imag, w):
        L = resp(x)[0]
        if L.real < 0:
            pc.append((x, float(1.0 / abs(L))))
    r = dict(gain_crossings=gc, phase_crossings=pc, pm_deg=np.inf, w_pm=np.nan,
             gm_up=np.inf, w_gm_up=np.nan, gm_down=0.0, w_gm_down=np.nan)
    for x, pm in gc:
        if pm < r["pm_deg"]:
            r["pm_deg"], r["w_pm"] = pm, x
    for x, gm in pc:
        if gm > 1.0 and gm < r["gm_up"]:
            r["gm_up"], r["w_gm_up"] = gm, x
        if gm < 1.0 and gm > r["gm_down"]:
            r["gm_down"], r["w_gm_down"] = gm, x
    return r


def bandwidth(resp, dc, w_lo, w_hi, n=20000):
    """First w (rad/s) where |T| = |L/(1+L)| is DB_DROP dB below |T(0)| = dc; nan if none."""
    lim = abs(dc) * 10.0 ** (DB_DROP / 20.0)

    def f(v):
        L = resp(v)
        return np.abs(L / (1.0 + L)) - lim
    w = np.logspace(np.log10(w_lo), np.log10(w_hi), n)
    v = f(w)
    below = np.nonzero(v < 0)[0]
    if below.size == 0 or below[0] == 0:
        return np.nan
    i = below[0]
    return brentq(lambda x: float(f(np.array([x]))[0]), w[i - 1], w[i], xtol=1e-12, rtol=1e-12)


def analyse(A, B2, K, dts):
    """The report's figures: continuous margins and bandwidth, and the sampled loop's at each dt."""
    out = {"continuous": dict(margins(continuous_loop(A, B2, K), 1e-2, 1e6),
                              bandwidth_rad_s=bandwidth(continuous_loop(A, B2, K), 1.0, 1e-2, 1e6))}
    for dt in dts:
        resp = sampled_loop(A, B2, K, dt)
        w_hi = np.pi / dt * (1 - 1e-9)
        out[dt] = dict(margins(resp, 1e-2, w_hi), bandwidth_rad_s=bandwidth(resp, 1.0, 1e-2, w_hi))
    return out


def _db(g):
    return 20.0 * np.log10(g)


def render(res):
    """Text lines of the report."""
    lines = ["loop broken at the torque input, L = -K (sI - A)^-1 B2 (sampled: the loop as implemented)"]
    for key, r in res.items():
        name = "continuous" if key == "continuous" else "sampled at %g ms" % (key * 1e3)
        hz = 1.0 / (2.0 * np.pi)
        up = ("no upper limit" if not np.isfinite(r["gm_up"]) else
              "%+.2f dB (x%.4g) at %.4g Hz" % (_db(r["gm_up"]), r["gm_up"], r["w_gm_up"] * hz))
        down = ("no lower limit" if r["gm_down"] == 0.0 else
                "%+.2f dB (x%.4g) at %.4g Hz" % (_db(r["gm_down"]), r["gm_down"], r["w_gm_down"] * hz))
        lines.append("  %s: phase margin %.2f deg at %.4g Hz; gain margin up %s, down %s; "
                     "closed-loop bandwidth (-3 dB of theta/theta_ref) %.4g Hz"
                     % (name, r["pm_deg"], r["w_pm"] * hz, up, down, r["bandwidth_rad_s"] * hz))
    return lines
