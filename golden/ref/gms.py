# SPDX-License-Identifier: Apache-2.0
"""Generalized Maxwell-slip friction and the plant that carries it, float64
golden reference of sim/lib/plant/br_gms.c and the Maxwell-slip path of
sim/lib/plant/br_sim_plant.c, written from ../shared/spec/presliding.md:

    s(v)       = Fc + (Fs - Fc) exp(-(|v| / vs)^delta)
    Delta_i(v) = alpha_i s(v) / k_i
    sticking:  dz_i/dt = v
    slipping:  dz_i/dt = C alpha_i (sgn(v) - z_i / Delta_i(v))
    F          = sum_i (k_i z_i + sigma1_i dz_i/dt)        (+ sigma2 v, the plant's viscous term)

An element sticks until sgn(v) z_i reaches Delta_i, then slips until the
velocity changes sign or stops. The clamp limit: z_i <- clamp(z_i + dx, -Delta_i, Delta_i).

Over a substep the velocity v is held. The stick phase is written over the
travel: the element sticks over the travel Delta - sgn(v) z (what is left
to its breakaway), so it breaks away after that much of |dx|; the slip
phase is the linear ODE's exact solution over the time left. The clamp
limit's path is z(t) = clamp(z0 + v t); its integral is summed piece by
piece over the travel. The rigid body is golden/ref/plant.py's scheme
(trapezoidal rule, PASSES fixed-point passes on the mean velocity).
"""
import math
from dataclasses import dataclass
from typing import Tuple

from .plant import PASSES


@dataclass(frozen=True)
class GmsParams:
    k: Tuple[float, ...]       # N/m
    alpha: Tuple[float, ...]   # shares, sum 1
    sigma1: Tuple[float, ...]  # N s/m
    C: float                   # m/s (slip law)
    delta: float
    clamp: bool


def level(pp, g, v):
    """s(v) of presliding.md with the plant's Fc, Fs, vs."""
    lg = pp.lugre
    return lg.Fc + (lg.Fs - lg.Fc) * math.exp(-((abs(v) / lg.vs) ** g.delta))


def clamp_element(z, v, h, D):
    """(z1, integral of z): z(t) = clamp(z + v t, -D, D) over [0, h]."""
    x_end = v * h
    z1 = min(max(z + x_end, -D), D)
    if v == 0.0:
        return z1, z1 * h
    # the travel splits into: held at the bound behind (until the line comes
    # back inside), inside, held at the bound ahead; integrate over travel
    # and divide by |v|
    sg = 1.0 if v > 0.0 else -1.0
    u0, u1 = sg * z, sg * z + abs(x_end)   # the line in the direction of motion
    total = 0.0
    # piece below -D (held at -D): u in [u0, min(u1, -D)]
    a, b = u0, min(u1, -D)
    if b > a:
        total += -D * (b - a)
    # inside: u in [max(u0, -D), min(u1, D)]
    a, b = max(u0, -D), min(u1, D)
    if b > a:
        total += 0.5 * (a + b) * (b - a)
    # above D (held at D)
    a, b = max(u0, D), u1
    if b > a:
        total += D * (b - a)
    return z1, sg * total / abs(v)


def slip_element(z, slip, v, h, D, Ca):
    """Slip law, v != 0: (z1, slip1, integral of z)."""
    sg = 1 if v > 0.0 else -1
    target = sg * D
    t_left, zint = h, 0.0
    if slip != sg:
        travel = abs(v) * h
        to_breakaway = D - sg * z
        if to_breakaway >= travel:               # sticks all the substep
            z1 = z + v * h
            return z1, 0, 0.5 * (z + z1) * h
        if to_breakaway > 0.0:                   # sticks, then breaks away at +-D
            t_stick = to_breakaway / abs(v)
            zint = 0.5 * (z + target) * t_stick
            z, t_left = target, h - t_stick
        # else: beyond D already, slips from where it is
    lam = Ca / D
    e = math.exp(-lam * t_left)
    # z(t) = target + (z - target) e^{-lam t}
    z1 = target + (z - target) * e
    zint += target * t_left + (z - target) * (-math.expm1(-lam * t_left)) / lam
    return z1, sg, zint


def advance(pp, g, zs, slips, v, h):
    """All elements over h at v: (zs1, slips1, friction impulse)."""
    s = level(pp, g, v)
    zs1, slips1, imp = [], [], 0.0
    for i, z in enumerate(zs):
        D = g.alpha[i] * s / g.k[i]
        if g.clamp:
            z1, zint = clamp_element(z, v, h, D)
            sl = slips[i]
        elif v == 0.0:
            z1, sl, zint = z, 0, z * h
        else:
            z1, sl, zint = slip_element(z, slips[i], v, h, D, g.C * g.alpha[i])
        zs1.append(z1)
        slips1.append(sl)
        imp += g.k[i] * zint + g.sigma1[i] * (z1 - z)
    return zs1, slips1, imp


def force(pp, g, zs, slips, v):
    """F = sum_i (k_i z_i + sigma1_i dz_i/dt) at the state, velocity v."""
    s = level(pp, g, v)
    f = 0.0
    for i, z in enumerate(zs):
        D = g.alpha[i] * s / g.k[i]
        sg = 0 if v == 0.0 else (1 if v > 0.0 else -1)
        if g.clamp:
            rate = 0.0 if (sg != 0 and sg * z >= D) else v
        elif sg != 0 and slips[i] == sg:
            rate = g.C * g.alpha[i] * (sg - z / D)
        else:
            rate = v
        f += g.k[i] * z + g.sigma1[i] * rate
    return f


class GmsPlant:
    """golden/ref/plant.py's Plant with the Maxwell-slip friction; elements
    start undeflected and sticking."""

    def __init__(self, pp, g, theta0=0.0, omega0=0.0):
        self.p, self.g = pp, g
        self.theta, self.omega = float(theta0), float(omega0)
        self.zs = [0.0] * len(g.k)
        self.slips = [0] * len(g.k)
        self.fnl = force(pp, g, self.zs, self.slips, pp.L * self.omega)

    def substep(self, tau, h):
        p, L = self.p, self.p.L
        w = self.omega
        wm = w
        for _ in range(PASSES):
            dth = wm * h
            zs1, sl1, imp = advance(p, self.g, self.zs, self.slips, L * wm, h)
            w1 = w + (tau * h - L * L * p.sigma2 * dth - L * imp) / p.Jeff
            wm = (w + w1) / 2.0
        self.theta += dth
        self.omega = w1
        self.zs, self.slips = zs1, sl1

    def step(self, duty, dt):
        tau = min(max(duty, -1.0), 1.0) * self.p.tau_per_duty
        h = dt / self.p.n_sub
        for _ in range(self.p.n_sub):
            self.substep(tau, h)
        self.fnl = force(self.p, self.g, self.zs, self.slips, self.p.L * self.omega)

    def encoder_count(self):
        """floor(theta / rad_per_count) wrapped modulo 2^32 into int32."""
        n = int(math.floor(self.theta / self.p.rad_per_count)) & 0xFFFFFFFF
        return n - (1 << 32) if n >= (1 << 31) else n
