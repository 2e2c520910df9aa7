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
