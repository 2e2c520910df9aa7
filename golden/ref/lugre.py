# SPDX-License-Identifier: Apache-2.0
"""LuGre dynamic friction (thesis eqs. 3-5), float64 golden reference.

    F_nl  = sigma0 z + sigma1 dz/dt                  (eq. 3)
    dz/dt = v - sigma0 |v| z / g(v)                  (eq. 4)
    g(v)  = Fc + (Fs - Fc) exp(-|v| / vs)            (eq. 5)

v: load-side sliding velocity (m/s), z: mean bristle deflection (m).
"""
import math
from dataclasses import dataclass


@dataclass(frozen=True)
class LugreParams:
    sigma0: float  # bristle stiffness, N/m
    sigma1: float  # bristle damping, N s/m
    Fc: float      # Coulomb level, N
    Fs: float      # stiction level, N
    vs: float      # Stribeck velocity, m/s

    @classmethod
    def from_machine(cls, m):
        return cls(sigma0=m["sigma0_Npm"], sigma1=m["sigma1_Nspm"],
                   Fc=m["Fc_N"], Fs=m["Fs_N"], vs=m["vs_mps"])


def g(p, v):
    """Eq. 5: Stribeck level g(v) = Fc + (Fs - Fc) exp(-|v|/vs)."""
    return p.Fc + (p.Fs - p.Fc) * math.exp(-abs(v) / p.vs)


def zdot(p, z, v, g_N):
    """Eq. 4: dz/dt = v - sigma0 |v| z / g."""
    return v - p.sigma0 * abs(v) * z / g_N


def force(p, z, zd):
    """Eq. 3: F = sigma0 z + sigma1 dz/dt."""
    return p.sigma0 * z + p.sigma1 * zd


def z_advance(p, z, dx, g_N):
    """Exact solution of eq. 4 over the displacement dx with g held:
    dz/dx = 1 - sigma0 sgn(dx) z / g, so with s = sgn(dx), zss = s g / sigma0,
        z1 = zss + (z - zss) exp(-sigma0 |dx| / g).
    No displacement, no change."""
    if dx == 0.0:
        return z
    s = 1.0 if dx > 0.0 else -1.0
    zss = s * g_N / p.sigma0
    return zss + (z - zss) * math.exp(-p.sigma0 * abs(dx) / g_N)


def step(p, z, v, dt):
    """One step at constant velocity v over dt (what br_lugre_step does):
        g  = g(v)                                    (eq. 5)
        z1 = z_advance(z, v dt, g)                   (exact eq. 4)
        F  = sigma0 z1 + sigma1 zdot(z1, v, g)       (eqs. 3, 4), same g
    Returns (z1, F, g)."""
    g_N = g(p, v)
    z1 = z_advance(p, z, v * dt, g_N)
    F = force(p, z1, zdot(p, z1, v, g_N))
    return z1, F, g_N
