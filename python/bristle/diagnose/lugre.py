# SPDX-License-Identifier: Apache-2.0
"""LuGre bristle state, bounded at any speed: the one implementation the fit
(model.py, along a measured motion) and the closed-loop re-simulation
(closedloop.py, substep by substep) share.

Over an interval the displacement dx is known and g is held at the
interval's velocity; the bristle equation written over the displacement,
dz/dx = 1 - sgn(dx) sigma0 z / g, has the exact solution
(docs/modules/lugre.md)

  z1 = z0 + (zss - z0) q,  q = 1 - exp(-r),  zss = sgn(dx) g / sigma0,  r = sigma0 |dx| / g

bounded for any dx (the same displacement-exact update as the C plant), and
the mean of z over the interval in closed form,

  zbar = zss + (z0 - zss) q / r.

Scaling: with g = Fc gn(v), gn = 1 + (beta - 1) exp(-|v|/vs) (times
neg_ratio while moving in -x: asymmetric friction), z depends only on
rho = sigma0 / Fc, beta = Fs / Fc and vs; the LuGre force is then
Fc (rho z) + sigma1 dz/dt, linear in Fc and sigma1.

The same functions serve numpy arrays (ARRAY, the fit) and Python floats
(SCALAR, the closed loop's substeps, where numpy's per-call cost would
dominate): `Ops` is the handful of operations they need.

Along a whole motion z_k = A_k z_k-1 + B_k is a linear recurrence with
A_k = 1 - q_k in [0, 1]; `affine_scan` evaluates it for all k at once by a
parallel prefix (Hillis-Steele) over the affine maps, which only multiplies
by numbers in [0, 1] (no division, no growth), in log2(n) vectorised passes.
"""
import math
from typing import Callable, NamedTuple

import numpy as np

SMALL_R = 1e-9  # below it q / r is evaluated as 1 - r / 2


class Ops(NamedTuple):
    exp: Callable
    expm1: Callable
    abs: Callable
    sign: Callable
    select: Callable  # select(cond, a, b): a where cond, else b


ARRAY = Ops(np.exp, np.expm1, np.abs, np.sign, np.where)
SCALAR = Ops(math.exp, math.expm1, math.fabs, lambda x: math.copysign(1.0, x) if x != 0.0 else 0.0,
             lambda c, a, b: a if c else b)


def stribeck(v, beta, vs, neg_ratio=1.0, ops=ARRAY):
    """g / Fc at velocity v: 1 + (beta - 1) exp(-|v|/vs), scaled by neg_ratio
    while moving in -x (Fc and Fs in -x are neg_ratio times those in +x)."""
    gn = 1.0 + (beta - 1.0) * ops.exp(-ops.abs(v) / vs)
    if neg_ratio != 1.0:
        gn = ops.select(v < 0.0, neg_ratio * gn, gn)
    return gn


def interval(dx, gn, rho, ops=ARRAY):
    """The displacement-exact update over displacement(s) dx with g = Fc gn
    held: (zss, q, m) with z1 = z0 + (zss - z0) q and zbar = zss + (z0 - zss) m."""
    r = rho * ops.abs(dx) / gn
    q = -ops.expm1(-r)                      # 1 - exp(-r)
    zss = ops.sign(dx) * gn / rho
    m = ops.select(r > SMALL_R, q / ops.select(r > SMALL_R, r, 1.0), 1.0 - 0.5 * r)
    return zss, q, m


def step(z0, dx, gn, rho):
    """One interval from z0 (floats): (z at its end, mean z over it)."""
    zss, q, m = interval(dx, gn, rho, SCALAR)
    return z0 + (zss - z0) * q, zss + (z0 - zss) * m


def affine_scan(A, B, z0=0.0):
    """z_k = A_k z_k-1 + B_k for k = 0.. with z_-1 = z0 (A in [0, 1])."""
    A = np.array(A, dtype=float)
    B = np.array(B, dtype=float)
    n = len(A)
    s = 1
    while s < n:
        # compose map k with map k - s: z -> A_k (A_k-s z + B_k-s) + B_k
        B[s:] = A[s:] * B[:-s] + B[s:]
        A[s:] = A[s:] * A[:-s]
        s *= 2
    return A * z0 + B


def bristle(dx, dt, rho, beta, vs, z0=0.0, neg_ratio=1.0):
    """Bristle state along the displacements dx (one per interval of dt).

    Returns (zmean, zend): the mean of z over each interval and z at each
    interval's end, in metres."""
    dx = np.asarray(dx, dtype=float)
    zss, q, m = interval(dx, stribeck(dx / dt, beta, vs, neg_ratio), rho)
    zend = affine_scan(1.0 - q, zss * q, z0)
    zstart = np.concatenate([[z0], zend[:-1]])
    return zss + (zstart - zss) * m, zend


def bristle_columns(dx, dt, rho, beta, vs, neg_ratio=1.0):
    """(rho * mean z, mean dz/dt) per interval: the LuGre force is
    Fc * first + sigma1 * second."""
    zmean, zend = bristle(dx, dt, rho, beta, vs, neg_ratio=neg_ratio)
    zstart = np.concatenate([[0.0], zend[:-1]])
    return rho * zmean, (zend - zstart) / dt
