# SPDX-License-Identifier: Apache-2.0
"""Gain-matrix state feedback with integral action (thesis eq. 7), float64
golden reference of one control period.

    d       = wrapdiff(enc, prev)                  (0 on the priming call)
    omega   = d rad_per_count / dt
    e_theta = (wrapdiff(enc, ref_counts) - ref_frac) rad_per_count
    e_omega = omega - ref_omega
    u       = K0 e_theta + K1 e_omega + K2 eps + L comp_N   (eps before update)
    tau     = clamp(u, -tau_max, tau_max),  saturated = (tau != u)
    eps    += e_theta dt, unless saturated and K2 e_theta has the sign of u
             (conditional integration: never integrate deeper into saturation)
    duty    = tau / tau_per_duty
"""
import math
from dataclasses import dataclass, replace

BR_OK = 0
BR_E_INPUT = -3


@dataclass(frozen=True)
class CtrlCfg:
    K: tuple               # gains on [e_theta, e_omega, eps]
    dt: float              # s
    tau_max: float         # N m
    tau_per_duty: float    # N m
    rad_per_count: float   # rad
    L: float               # m/rad


@dataclass(frozen=True)
class CtrlState:
    eps: float = 0.0
    prev_counts: int = 0
    primed: bool = False


def wrapdiff(now, prev):
    """(now - prev) modulo 2^32 read as a signed 32-bit integer."""
    d = (int(now) - int(prev)) & 0xFFFFFFFF
    return d - (1 << 32) if d >= (1 << 31) else d


def to_int32(n):
    """An integer wrapped modulo 2^32 into the int32 range."""
    n = int(n) & 0xFFFFFFFF
    return n - (1 << 32) if n >= (1 << 31) else n


def step(cfg, st, enc, ref_counts, ref_frac, ref_omega, comp_N):
    """One control period. Returns (status, new_state, out) with out a dict of
    tau, duty, e_theta, omega, u, saturated (0/1).

    A non-finite float input gives BR_E_INPUT, zero torque, state unchanged."""
    if not all(math.isfinite(v) for v in (ref_frac, ref_omega, comp_N)):
        return BR_E_INPUT, st, dict(tau=0.0, duty=0.0, e_theta=0.0, omega=0.0,
                                    u=0.0, saturated=0)
    # velocity from the wrap-safe encoder difference; the first call primes
    d = wrapdiff(enc, st.prev_counts) if st.primed else 0
    omega = d * cfg.rad_per_count / cfg.dt
    # errors: integer count difference first (wrap-safe), then the fraction
    e_theta = (wrapdiff(enc, ref_counts) - ref_frac) * cfg.rad_per_count
    e_omega = omega - ref_omega
    # eq. 7 with the friction compensation force converted to torque
    K0, K1, K2 = cfg.K
    u = K0 * e_theta + K1 * e_omega + K2 * st.eps + cfg.L * comp_N
    tau = min(max(u, -cfg.tau_max), cfg.tau_max)
    saturated = tau != u
    # anti-windup by conditional integration
    deeper = (K2 * e_theta > 0.0 and u > 0.0) or (K2 * e_theta < 0.0 and u < 0.0)
    eps = st.eps if (saturated and deeper) else st.eps + e_theta * cfg.dt
    out = dict(tau=tau, duty=tau / cfg.tau_per_duty, e_theta=e_theta, omega=omega,
               u=u, saturated=int(saturated))
    return BR_OK, replace(st, eps=eps, prev_counts=int(enc), primed=True), out
