"""LuGre bristle state along a measured motion, bounded at any speed.

Over each interval the displacement dx is known (from the filtered position)
and g is held at the interval's velocity; the bristle equation written over
the displacement, dz/dx = 1 - sgn(dx) sigma0 z / g, has the exact solution
(docs/modules/lugre.md)

  z1 = z0 + (zss - z0)(1 - exp(-r)),  zss = sgn(dx) g / sigma0,  r = sigma0 |dx| / g

bounded for any dx: the same displacement-exact update as the C plant.

Scaling: with g = Fc * gn(v), gn = 1 + (beta - 1) exp(-|v|/vs), z depends only
on rho = sigma0 / Fc, beta = Fs / Fc and vs; the LuGre force is then
Fc * (rho z) + sigma1 dz/dt, linear in Fc and sigma1.

z_k = A_k z_k-1 + B_k is a linear recurrence with A_k = exp(-r_k) in [0, 1];
it is evaluated for all k at once by a parallel prefix (Hillis-Steele) over
the affine maps, which only multiplies by numbers in [0, 1] (no division, no
growth), in log2(n) vectorised passes.
"""
import numpy as np


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

    neg_ratio scales the Stribeck curve while moving in -x (asymmetric
    friction: Fc and Fs in -x are neg_ratio times those in +x; sigma0 is
    common, so the force stays sigma0 z).

    Returns (zmean, zend): the mean of z over each interval (closed form with g
    held) and z at each interval's end, in metres."""
    dx = np.asarray(dx, dtype=float)
    v = dx / dt
    gn = 1.0 + (beta - 1.0) * np.exp(-np.abs(v) / vs)
    if neg_ratio != 1.0:
        gn = np.where(dx < 0.0, neg_ratio * gn, gn)
    r = rho * np.abs(dx) / gn
    q = -np.expm1(-r)                      # 1 - exp(-r)
    zss = np.sign(dx) * gn / rho
    zend = affine_scan(1.0 - q, zss * q, z0)
    zstart = np.concatenate([[z0], zend[:-1]])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(r > 1e-9, q / np.where(r > 1e-9, r, 1.0), 1.0 - 0.5 * r)
    zmean = zss + (zstart - zss) * ratio
    return zmean, zend


def bristle_columns(dx, dt, rho, beta, vs, neg_ratio=1.0):
    """(rho * mean z, mean dz/dt) per interval: the LuGre force is
    Fc * first + sigma1 * second."""
    zmean, zend = bristle(dx, dt, rho, beta, vs, neg_ratio=neg_ratio)
    zstart = np.concatenate([[0.0], zend[:-1]])
    return rho * zmean, (zend - zstart) / dt
