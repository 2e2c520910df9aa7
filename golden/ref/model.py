# SPDX-License-Identifier: Apache-2.0
"""Four-state estimation model of one ball-screw axis (thesis eq. 6),
float64 golden reference.

State x = [theta (rad), omega (rad/s), z (m), g_p (N)] on the motor side,
input u = motor torque (N m), held over the step h:

    dtheta/dt = omega
    domega/dt = (u - L (sigma2 L omega + f_nl)) / Jeff,   Jeff = J + L^2 M
    dz/dt     = L omega - sigma0 L |omega| z / g_p
    dg_p/dt   = 0
    f_nl      = sigma0 z + sigma1 (L omega - sigma0 L |omega| z / g_p)

Discretisation: classic RK4 while the bristle rate times the step,
a h = sigma0 L |omega| h / g_p, is <= 2 both at the start and at the RK4 end
point; otherwise the bounded displacement-exact scheme (B2 below).
"""
import math
from dataclasses import dataclass

import numpy as np

from .lugre import LugreParams

BR_OK = 0
BR_E_INPUT = -3

BRANCH_RK4 = 0
BRANCH_BOUNDED = 1
BRANCH_INVALID = -1

RK4_AH_MAX = 2.0
BOUNDED_PASSES = 3


@dataclass(frozen=True)
class ModelParams:
    J: float       # motor + screw inertia, kg m^2
    M: float       # table mass, kg
    L: float       # lead / (2 pi), m/rad
    sigma2: float  # viscous friction, N s/m
    lugre: LugreParams

    @property
    def Jeff(self):
        return self.J + self.L * self.L * self.M

    @classmethod
    def from_machine(cls, m):
        return cls(J=m["J_kgm2"], M=m["M_kg"], L=m["L_mprad"],
                   sigma2=m["sigma2_Nspm"], lugre=LugreParams.from_machine(m))


def fnl(p, x):
    """Lumped friction f_nl(x) = sigma0 z + sigma1 dz/dt (eqs. 3, 4 with g = g_p)."""
    _, w, z, gp = x
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    zd = L * w - s0 * L * abs(w) * z / gp
    return s0 * z + s1 * zd


def deriv(p, x, u):
    """Eq. 6 right-hand side f(x, u)."""
    _, w, z, gp = x
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    zd = L * w - s0 * L * abs(w) * z / gp          # eq. 4 on the load side
    f = s0 * z + s1 * zd                           # eq. 3
    wd = (u - L * (p.sigma2 * L * w + f)) / p.Jeff  # rigid body
    return np.array([w, wd, zd, 0.0], dtype=np.float64)


def rk4(p, x, u, h, stages=None):
    """Classic four-stage Runge-Kutta step of eq. 6 with u held; the omega of
    stages 2, 3, 4 appended to the list stages when one is given."""
    x = np.asarray(x, dtype=np.float64)
    k1 = deriv(p, x, u)
    x2 = x + (h / 2.0) * k1
    k2 = deriv(p, x2, u)
    x3 = x + (h / 2.0) * k2
    k3 = deriv(p, x3, u)
    x4 = x + h * k3
    k4 = deriv(p, x4, u)
    if stages is not None:
        stages.extend((x2[1], x3[1], x4[1]))
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def bounded(p, x, u, h):
    """B2: displacement-exact bristle update + trapezoidal rigid body.

    Three fixed-point passes on the mean velocity wm (first pass wm = omega0):
        dth  = wm h,  dx = L dth,  r = sigma0 |dx| / g_p
        z1   = zss + (z - zss) e,              zss = sgn(dx) g_p / sigma0, e = exp(-r)
        zint = h (zss + (z - zss) (1 - e) / r) (= integral of z over the step)
        (dx = 0: z1 = z, zint = z h)
        w1   = w + (u h - L^2 sigma2 dth - L (sigma0 zint + sigma1 (z1 - z))) / Jeff
        wm   = (w + w1) / 2
    The result uses dth, w1, z1 of the last pass; g_p is unchanged."""
    theta, w, z, gp = (float(v) for v in x)
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    Jeff = p.Jeff
    wm = w
    for _ in range(BOUNDED_PASSES):
        dth = wm * h
        dx = L * dth
        r = s0 * abs(dx) / gp
        if dx != 0.0:
            zss = (1.0 if dx > 0.0 else -1.0) * gp / s0
            e = math.exp(-r)
            z1 = zss + (z - zss) * e
            zint = h * (zss + (z - zss) * (1.0 - e) / r)
        else:
            z1 = z
            zint = z * h
        w1 = w + (u * h - L * L * p.sigma2 * dth - L * (s0 * zint + s1 * (z1 - z))) / Jeff
        wm = (w + w1) / 2.0
    return np.array([theta + dth, w1, z1, gp], dtype=np.float64)


def ah(p, w, gp, h):
    """Bristle rate times the step: sigma0 L |omega| h / g_p."""
    return p.lugre.sigma0 * p.L * abs(w) * h / gp


def step(p, x, u, h, stages=True):
    """One discretisation step of eq. 6 over h with u held.

    Returns (status, x_next, branch). Invalid input (a non-finite entry of x
    or u, or g_p <= 0) gives (BR_E_INPUT, x, BRANCH_INVALID). stages False:
    the RK4 test at the two ends only (the particle filter's kernels)."""
    x = np.asarray(x, dtype=np.float64)
    if not (np.all(np.isfinite(x)) and math.isfinite(u)) or not x[3] > 0.0:
        return BR_E_INPUT, x.copy(), BRANCH_INVALID
    ws = [] if stages else None
    x1 = rk4(p, x, u, h, ws)
    # RK4 only while a h <= 2 at the start, at the stages (br_model_step's)
    # and at the RK4 end point (a NaN compares false and falls to the
    # bounded scheme).
    if all(ah(p, w, x[3], h) <= RK4_AH_MAX for w in [x[1]] + (ws or []) + [x1[1]]):
        return BR_OK, x1, BRANCH_RK4
    return BR_OK, bounded(p, x, u, h), BRANCH_BOUNDED


# --------------------------------------------------------------------------
# Extended model: the causes of a diagnosis (docs/modules/model.md, "Extended
# model"), written from the equations, not from the C kernel. theta is
# relative to an origin at load position p0, so the load position is
# pos = p0 + L theta and the load velocity v = L omega; t is the time since
# the estimator started (the model's clock):
#
#   Jeff omega' = u - L F,   F = k(pos) s(t) (sigma2_d v + f_nl) + offset + A sin(2 pi pos / P + phi)
#   k(pos) = max(0, 1 + grad pos),  s(t) = max(0, 1 + drift t)
#   z' = v - sigma0 |v| z / g,  g = g_p for v >= 0, c g_p for v < 0,  c = (Fc + dFc_neg) / Fc
#        (the level by the direction of motion, as eq. 5's g(v); in a bounded
#        step, by the direction of the move)
#   f_nl = sigma0 z + sigma1 z',  sigma2_d = sigma2 (+ dsigma2_neg for v < 0)
#
# The force to compensate is F - sigma2 v. The ripple is evaluated exactly
# here (the C kernel expands it about p0), and s(t) at each RK4 stage's time
# (the C kernel holds it over the step at its clock); docs/golden.md bounds
# both differences.
# --------------------------------------------------------------------------
@dataclass(frozen=True)
class Causes:
    offset: float = 0.0       # N
    dFc_neg: float = 0.0      # N
    dsigma2_neg: float = 0.0  # N s/m
    ripple_amp: float = 0.0   # N
    ripple_period: float = 1.0  # m
    ripple_phase: float = 0.0   # rad
    grad: float = 0.0         # 1/m
    drift: float = 0.0        # 1/s

    def level_factor(self, p, d):
        """The Stribeck level's factor for a deflection or move d: 1 towards
        +x, (Fc + dFc_neg) / Fc towards -x."""
        return (p.lugre.Fc + self.dFc_neg) / p.lugre.Fc if d < 0.0 else 1.0


def load_force_ext(p, c, pos, w, z, gp, t=0.0):
    """(F, z') of the extended model at load position pos and time t."""
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    v = L * w
    g = c.level_factor(p, v) * gp
    zd = v - s0 * abs(v) * z / g
    f = s0 * z + s1 * zd
    k = max(0.0, 1.0 + c.grad * pos) * max(0.0, 1.0 + c.drift * t)
    s2 = p.sigma2 + (c.dsigma2_neg if v < 0.0 else 0.0)
    ripple = c.ripple_amp * math.sin(2.0 * math.pi * pos / c.ripple_period + c.ripple_phase)
    return k * (s2 * v + f) + c.offset + ripple, zd


def fcomp_ext(p, c, p0, x, t=0.0):
    """The force a compensation must cancel at time t: F - sigma2 v."""
    th, w, z, gp = (float(v) for v in x)
    F, _ = load_force_ext(p, c, p0 + p.L * th, w, z, gp, t)
    return F - p.sigma2 * p.L * w


def deriv_ext(p, c, p0, x, u, t=0.0):
    th, w, z, gp = (float(v) for v in x)
    F, zd = load_force_ext(p, c, p0 + p.L * th, w, z, gp, t)
    return np.array([w, (u - p.L * F) / p.Jeff, zd, 0.0], dtype=np.float64)


def rk4_ext(p, c, p0, x, u, h, t=0.0, stages=None):
    """RK4 from time t, each stage at its own time; the omega of stages 2, 3,
    4 appended to the list stages when one is given."""
    x = np.asarray(x, dtype=np.float64)
    k1 = deriv_ext(p, c, p0, x, u, t)
    x2 = x + (h / 2.0) * k1
    k2 = deriv_ext(p, c, p0, x2, u, t + h / 2.0)
    x3 = x + (h / 2.0) * k2
    k3 = deriv_ext(p, c, p0, x3, u, t + h / 2.0)
    x4 = x + h * k3
    k4 = deriv_ext(p, c, p0, x4, u, t + h)
    if stages is not None:
        stages.extend((x2[1], x3[1], x4[1]))
    return x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def bounded_ext(p, c, p0, x, u, h, t=0.0):
    """B2 with the causes: the level and sigma2_d by the direction of the move,
    the friction impulse scaled by k s, the offset and ripple impulses added; k
    and the ripple at the middle of the move, s at the middle of the step."""
    theta, w, z, gp = (float(v) for v in x)
    s0, s1, L = p.lugre.sigma0, p.lugre.sigma1, p.L
    wm = w
    for _ in range(BOUNDED_PASSES):
        dth = wm * h
        dx = L * dth
        g = c.level_factor(p, dx) * gp
        if dx != 0.0:
            r = s0 * abs(dx) / g
            zss = (1.0 if dx > 0.0 else -1.0) * g / s0
            e = math.exp(-r)
            z1 = zss + (z - zss) * e
            zint = h * (zss + (z - zss) * (1.0 - e) / r)
        else:
            z1 = z
            zint = z * h
        pos = p0 + L * (theta + 0.5 * dth)
        k = max(0.0, 1.0 + c.grad * pos) * max(0.0, 1.0 + c.drift * (t + 0.5 * h))
        s2 = p.sigma2 + (c.dsigma2_neg if dx < 0.0 else 0.0)
        ripple = c.ripple_amp * math.sin(2.0 * math.pi * pos / c.ripple_period + c.ripple_phase)
        imp = k * (s2 * dx + s0 * zint + s1 * (z1 - z)) + (c.offset + ripple) * h
        w1 = w + (u * h - L * imp) / p.Jeff
        wm = (w + w1) / 2.0
    return np.array([theta + dth, w1, z1, gp], dtype=np.float64)


def ah_ext(p, c, w, gp, h):
    """a h with the smaller of the two direction levels."""
    cmin = min(1.0, (p.lugre.Fc + c.dFc_neg) / p.lugre.Fc)
    return p.lugre.sigma0 * p.L * abs(w) * h / (cmin * gp)


def step_ext(p, c, p0, x, u, h, t=0.0):
    """br_model_step_at of the extended model from time t: (status, x_next, branch)."""
    x = np.asarray(x, dtype=np.float64)
    if not (np.all(np.isfinite(x)) and math.isfinite(u) and math.isfinite(p0)) or not x[3] > 0.0:
        return BR_E_INPUT, x.copy(), BRANCH_INVALID
    ws = []
    x1 = rk4_ext(p, c, p0, x, u, h, t, ws)
    if all(ah_ext(p, c, w, x[3], h) <= RK4_AH_MAX for w in [x[1]] + ws + [x1[1]]):
        return BR_OK, x1, BRANCH_RK4
    return BR_OK, bounded_ext(p, c, p0, x, u, h, t), BRANCH_BOUNDED
