# SPDX-License-Identifier: Apache-2.0
"""Closed-loop re-simulation of a log: the fitted model as the plant, the
log's position controller (when it is known), the log's reference as input.

Controller (a machine file's "controller"), type "emps_pd" (the EMPS loop,
and br_simlog's identification loop, which writes it with --machine-out):

  qf(k) = (q(k) + q(k-1)) / 2,  qdot(k) = (qf(k) - qf(k-1)) / dt
  u = kp kv (ref - q) - kv qdot,  |u| <= u_max,  F = gain u

keys: dt_s, kp_1ps, kv, gain_N, u_max.

Plant, load side (model.py's force model as dynamics, model.json's names):

  Meff dv/dt = F(t - d) - k(x, t) [sigma2_d v + sigma0 z + sigma1 dz/dt] - load(x)

nominal: k = 1, sigma2_d = sigma2_Nspm, load = 0, d = 0, the Stribeck curve
the same in both directions; each cause whose parameters the model holds
sets its terms (its module's closed_loop(p, plant): causes/). Integrated
like the C plant (docs/modules/plant.md): N_SUB substeps per period; in
each, z follows the exact displacement-domain solution with g held
(lugre.step, the fit's bristle update), the friction impulse is integrated
in closed form, the rigid body by the trapezoidal rule with fixed-point
passes on the mean velocity. The measured position q is the simulated one
quantised to the log's resolution (the smallest position step found in the
log), rounded down like an encoder count.
"""
import math

import numpy as np

from . import causes, lugre
from .params import GT0, Param

N_SUB = 10
PASSES = 3
CONTROLLER_TYPES = ("emps_pd",)
# a machine file's controller keys, with their bounds (params.Param)
CONTROLLER = (
    Param("dt_s", "s", "control period", GT0, 1.0),
    Param("kp_1ps", "1/s", "position gain", 0.0, 1e5),
    Param("kv", "N s/m", "velocity gain", GT0, 1e7),
    Param("gain_N", "N", "force per unit of u", GT0, 1e5),
    Param("u_max", "", "limit of u", GT0, 1e7),
)


class ControllerError(ValueError):
    pass


def check_controller(c, where):
    """Validates a controller description (a dict); where ("file:line")
    names it in messages."""
    if not isinstance(c, dict) or c.get("type") not in CONTROLLER_TYPES:
        raise ControllerError(f"{where}: \"type\" must be one of {', '.join(CONTROLLER_TYPES)}")
    for q in CONTROLLER:
        if q.name not in c:
            raise ControllerError(f"{where}: \"{q.name}\" is missing")
        problem = q.check(c[q.name])
        if problem:
            raise ControllerError(f"{where}: {problem}")
    return c


class Plant:
    """The cause terms of the re-simulated plant (what causes/*.closed_loop set)."""

    def __init__(self, p):
        self.stribeck_neg_ratio = 1.0         # the Stribeck curve in -x over the one in +x
        self.sigma2_neg_Nspm = p["sigma2_Nspm"]  # viscous friction in -x
        self.friction_scales = []             # k(x, t) = product of these
        self.loads = []                       # load(x) = sum of these, N
        self.delay_s = 0.0                    # actuator dead time


def plant(p):
    pl = Plant(p)
    for m in causes.present(p):
        m.closed_loop(p, pl)
    return pl


def position_quantum(pos):
    """The log's position resolution: the smallest nonzero step, if the
    steps are whole multiples of it (an encoder), else 0 (no quantising)."""
    d = np.abs(np.diff(pos))
    d = d[d > 0]
    if len(d) == 0:
        return 0.0
    q = float(d.min())
    r = d / q
    return q if np.mean(np.abs(r - np.round(r)) < 0.02) > 0.95 else 0.0


def simulate(params, ctrl, ref, pos0, vel0):
    """Runs the loop over len(ref) periods (params: model.json's). Returns
    (q, force, x_true)."""
    p = params
    dt = float(ctrl["dt_s"])
    kp, kv, gain, umax = (float(ctrl[k]) for k in ("kp_1ps", "kv", "gain_N", "u_max"))
    M = p["Meff_kg"]
    Fc = p["Fc_N"]
    beta = p["Fs_N"] / Fc
    vs = p["vs_mps"]
    s0 = p["sigma0_Npm"]
    s1 = p["sigma1_Nspm"]
    Fv_p = p["sigma2_Nspm"]
    pl = plant(p)
    Fv_n, c_neg, scales, loads, delay = (pl.sigma2_neg_Nspm, pl.stribeck_neg_ratio, pl.friction_scales, pl.loads,
                                         pl.delay_s)
    quantum = ctrl.get("_quantum", 0.0)
    h = dt / N_SUB
    rho = s0 / Fc
    stribeck, bristle_step, SCALAR = lugre.stribeck, lugre.step, lugre.SCALAR
    copysign = math.copysign

    n = len(ref)
    q_out = np.empty(n)
    f_out = np.empty(n)
    x_out = np.empty(n)
    x, v = float(pos0), float(vel0)
    z = copysign(Fc / s0, v) if v != 0.0 else 0.0
    cmd = np.zeros(n)
    dm = int(math.floor(delay / dt))
    dfrac = delay / dt - dm

    def quant(xx):  # an incremental encoder: whole counts below the position
        return math.floor(xx / quantum + 1e-9) * quantum if quantum > 0 else xx

    q_prev = qf_prev = quant(x)
    for k in range(n):
        if not (math.isfinite(x) and math.isfinite(v)):  # diverged: the rest is not simulated
            q_out[k:] = f_out[k:] = x_out[k:] = math.nan
            break
        q = quant(x)
        qf = 0.5 * (q + q_prev)
        qdot = (qf - qf_prev) / dt
        q_prev, qf_prev = q, qf
        u = kp * kv * (ref[k] - q) - kv * qdot
        u = umax if u > umax else (-umax if u < -umax else u)
        F = gain * u
        cmd[k] = F
        q_out[k], f_out[k], x_out[k] = q, F, x
        for i in range(N_SUB):
            # force reaching the axis over this substep: the command of delay earlier (ZOH)
            if delay > 0.0:
                ts = (i + 0.5) * h - dfrac * dt  # substep mid time minus the fractional part
                j = k - dm + (-1 if ts < 0 else 0)
                Fa = cmd[j] if j >= 0 else 0.0
            else:
                Fa = F
            vm = v
            tm = (k * N_SUB + i + 0.5) * h  # the substep's mid time from the log's start
            for _ in range(PASSES):
                dx = vm * h
                z1, zbar = bristle_step(z, dx, stribeck(vm, beta, vs, c_neg, SCALAR), rho)
                zint = h * zbar
                xm = x + 0.5 * dx
                kx = 1.0
                for scale in scales:
                    kx *= scale(xm, tm)
                fv = Fv_n if dx < 0.0 else Fv_p
                imp = kx * (fv * dx + s0 * zint + s1 * (z1 - z))
                for load in loads:
                    imp += load(xm) * h
                v1 = v + (Fa * h - imp) / M
                vm = 0.5 * (v + v1)
            x += dx
            v, z = v1, z1
    return q_out, f_out, x_out


def resimulate(prep, params, ctrl):
    """Re-simulates the whole log; relative errors (percent) of position,
    velocity, acceleration and force against the measured ones; velocity,
    acceleration (central differences of the low-passed positions) and force
    compared after the diagnosis's low-pass (like the fit)."""
    ctrl = dict(ctrl)
    if abs(ctrl["dt_s"] - prep.dt) > 1e-6 * prep.dt:
        raise ControllerError(f"controller period {ctrl['dt_s']} s differs from the log's {prep.dt:.6g} s")
    ctrl["_quantum"] = position_quantum(prep.pos)
    vel0 = (prep.pos[1] - prep.pos[0]) / prep.dt
    try:
        q, f, _ = simulate(params, ctrl, prep.ref, prep.pos[0], vel0)
    except (OverflowError, ZeroDivisionError):
        q = f = np.array([np.nan])
    bad = ~(np.isfinite(q) & np.isfinite(f))
    if np.any(bad):
        at = f" at {int(np.argmax(bad)) * prep.dt:.4g} s" if len(q) == len(prep.ref) else ""
        raise ControllerError(f"the closed-loop re-simulation diverged{at} (non-finite position or force; model "
                              f"Meff_kg = {params['Meff_kg']:.4g})")
    w = prep.whole
    v_meas = np.gradient(prep.xf, prep.dt)
    v_sim = np.gradient(prep.lp(q), prep.dt)
    a_meas, a_sim = np.gradient(v_meas, prep.dt), np.gradient(v_sim, prep.dt)
    f_meas, f_sim = prep.lp(prep.force), prep.lp(f)

    def rel(a, b):
        return 100.0 * float(np.linalg.norm((a - b)[w]) / np.linalg.norm(a[w]))

    with np.errstate(over="ignore", invalid="ignore"):
        out = {
            "relerr_position_percent": rel(prep.pos, q),
            "relerr_velocity_percent": rel(v_meas, v_sim),
            "relerr_acceleration_percent": rel(a_meas, a_sim),
            "relerr_force_percent": rel(f_meas, f_sim),
        }
    # a loop that ran away to finite but huge values overflows the norms
    if not all(math.isfinite(v) for v in out.values()):
        raise ControllerError("the closed-loop re-simulation diverged (its relative errors are not finite)")
    return {"q": q, "force": f, **out}
