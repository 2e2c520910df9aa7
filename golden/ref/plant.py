# SPDX-License-Identifier: Apache-2.0
"""Double-precision plant of one ball-screw axis (thesis eqs. 1-5), float64
golden reference of sim/lib/plant.

    Jeff domega/dt = tau - L (sigma2 L omega + F_nl)
    F_nl  = sigma0 z + sigma1 dz/dt,  dz/dt = L omega - sigma0 L |omega| z / g(L omega)
    g(v)  = Fc + (Fs - Fc) exp(-|v| / vs)                           (eq. 5)
    tau   = clamp(duty, -1, 1) tau_per_duty, held over the step

One step of dt = n_sub substeps of h = dt / n_sub; per substep, from
(theta, w, z), four fixed-point passes on the mean velocity wm (first wm = w):
    dth  = wm h,  dx = L dth,  v = L wm,  g = g(v)
    z1   = zss + (z - zss) e,  zss = sgn(dx) g / sigma0,  r = sigma0 |dx| / g,  e = exp(-r)
    zint = h (zss + (z - zss) (-expm1(-r)) / r)     (integral of z over the substep)
    (dx = 0: z1 = z, zint = z h)
    w1   = w + (tau h - L^2 sigma2 dth - L (sigma0 zint + sigma1 (z1 - z))) / Jeff
    wm   = (w + w1) / 2
and the new state is (theta + dth, w1, z1) of the last pass.
"""
import math
from dataclasses import dataclass

from .lugre import LugreParams, g as stribeck_g

PASSES = 4


@dataclass(frozen=True)
class PlantParams:
    J: float
    M: float
    L: float
    sigma2: float
    lugre: LugreParams
    counts_per_rev: float
    tau_per_duty: float
    n_sub: int

    @property
    def Jeff(self):
        return self.J + self.L * self.L * self.M

    @property
    def rad_per_count(self):
        return 2.0 * math.pi / self.counts_per_rev

    @classmethod
    def from_machine(cls, m, n_sub):
        return cls(J=m["J_kgm2"], M=m["M_kg"], L=m["L_mprad"], sigma2=m["sigma2_Nspm"],
                   lugre=LugreParams.from_machine(m), counts_per_rev=m["counts_per_rev"],
                   tau_per_duty=m["tau_per_duty_Nm"], n_sub=int(n_sub))


def substep(p, theta, w, z, tau, h):
    """One substep of h: bounded bristle update, closed-form friction impulse,
    trapezoidal rigid body solved by PASSES fixed-point passes."""
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    Jeff = p.Jeff
    wm = w
    for _ in range(PASSES):
        dth = wm * h
        dx = L * dth
        v = L * wm
        g_N = stribeck_g(p.lugre, v)                      # eq. 5 at the mean velocity
        if dx != 0.0:
            s = 1.0 if dx > 0.0 else -1.0
            zss = s * g_N / s0
            r = s0 * abs(dx) / g_N
            e = math.exp(-r)
            z1 = zss + (z - zss) * e                      # exact eq. 4 over dx
            zint = h * (zss + (z - zss) * (-math.expm1(-r)) / r)
        else:
            z1 = z
            zint = z * h
        w1 = w + (tau * h - L * L * p.sigma2 * dth - L * (s0 * zint + s1 * (z1 - z))) / Jeff
        wm = (w + w1) / 2.0
    return theta + dth, w1, z1


def fnl(p, w, z):
    """F_nl = sigma0 z + sigma1 (L w - sigma0 L |w| z / g(L w))   (eqs. 3-5)."""
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    g_N = stribeck_g(p.lugre, L * w)
    return s0 * z + s1 * (L * w - s0 * L * abs(w) * z / g_N)


class Plant:
    def __init__(self, p, theta0=0.0, omega0=0.0, z0=0.0):
        self.p = p
        self.theta, self.omega, self.z = float(theta0), float(omega0), float(z0)
        self.tau = 0.0
        self.fnl = fnl(p, self.omega, self.z)

    def step(self, duty, dt):
        """Advances by dt with the duty held (zero-order hold)."""
        p = self.p
        self.tau = min(max(duty, -1.0), 1.0) * p.tau_per_duty
        h = dt / p.n_sub
        th, w, z = self.theta, self.omega, self.z
        for _ in range(p.n_sub):
            th, w, z = substep(p, th, w, z, self.tau, h)
        self.theta, self.omega, self.z = th, w, z
        self.fnl = fnl(p, w, z)

    def encoder(self):
        """floor(theta / rad_per_count) wrapped modulo 2^32 into int32."""
        n = int(math.floor(self.theta / self.p.rad_per_count)) & 0xFFFFFFFF
        return n - (1 << 32) if n >= (1 << 31) else n
