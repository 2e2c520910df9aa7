# SPDX-License-Identifier: Apache-2.0
"""Maxwell-slip friction in its clamp form, float64 golden reference of the
firmware's firmware/mslip/br_mslip.c, written from
../shared/spec/presliding.md (the C -> infinity limit) and
docs/modules/mslip.md:

    Delta_i(g) = share_i g / k_i
    z_i       <- clamp(z_i + dx, -Delta_i(g), +Delta_i(g))
    F          = sum_i k_i z_i + sigma2 v

The element set is a numpy vector; the clamp is numpy's clip, the force a
dot product written out as an element-wise sum (no BLAS).
"""
from dataclasses import dataclass
from typing import Tuple

import numpy as np


@dataclass(frozen=True)
class MslipParams:
    k: Tuple[float, ...]      # element stiffness, N/m
    share: Tuple[float, ...]  # share of the Stribeck level, sum 1
    sigma2: float             # viscous term, N s/m

    @staticmethod
    def from_breakaway(d_m, share, Fs_N, sigma2):
        """Elements of breakaway displacements d_i at the level Fs: k_i = share_i Fs / d_i."""
        return MslipParams(k=tuple(a * Fs_N / d for a, d in zip(share, d_m)), share=tuple(share),
                           sigma2=float(sigma2))


def bounds(p, g):
    """Delta_i(g) = share_i g / k_i, the deflection at which each element slips."""
    return np.asarray(p.share, dtype=np.float64) * g / np.asarray(p.k, dtype=np.float64)


def move(p, z, dx, g):
    """The elements z (array) after the travel dx at the level g."""
    d = bounds(p, g)
    return np.clip(np.asarray(z, dtype=np.float64) + dx, -d, d)


def force(p, z, v):
    """F = sum_i k_i z_i + sigma2 v."""
    return float(np.sum(np.asarray(p.k, dtype=np.float64) * z)) + p.sigma2 * v


def presliding_curve(p, g, travel):
    """Force after a reversal from full slip in -x, along the travel (array, >= 0):
    sum_i k_i min(-Delta_i + s, Delta_i), the virgin-to-outer loop branch."""
    d = bounds(p, g)
    k = np.asarray(p.k, dtype=np.float64)
    s = np.asarray(travel, dtype=np.float64)[:, None]
    return np.sum(k * np.minimum(-d + s, d), axis=1)


def model_step(mp, p, theta, omega, gp, z, u, h, passes):
    """The Maxwell-slip estimation model's step (docs/modules/model.md,
    "Maxwell-slip model"): mp the eq. 6 parameters (ref.model.ModelParams),
    the elements moved along the step's travel at the level g_p, the rigid
    body by the trapezoidal rule solved by `passes` fixed-point passes from
    omega_m = omega. Returns (theta1, omega1, z1)."""
    z = np.asarray(z, dtype=np.float64)
    f0 = force(p, z, 0.0)
    om_m, th1, om1, z1 = omega, theta, omega, z
    for _ in range(passes):
        dth = om_m * h                                  # the step's rotation at the mean speed
        z1 = move(p, z, mp.L * dth, gp)                 # its travel L dtheta, clamped at Delta_i(g_p)
        f1 = force(p, z1, 0.0)
        # J_eff (omega1 - omega) = u h - L^2 sigma2 dtheta - L h (f0 + f1) / 2
        om1 = omega + (u * h - mp.L * mp.L * mp.sigma2 * dth - mp.L * h * 0.5 * (f0 + f1)) / mp.Jeff
        th1 = theta + dth
        om_m = 0.5 * (omega + om1)
    return th1, om1, z1
