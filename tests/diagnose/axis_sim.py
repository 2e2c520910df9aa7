# SPDX-License-Identifier: Apache-2.0
"""An axis simulator independent of the diagnosis and of br_simlog, for the
hidden-cause suite (hidden_cause.py) and the tests of the noise floor:
logs of other machines, another trajectory, a finer integrator, and forces
no named cause describes.

Not the diagnosis's model:
  - trajectory: cosine moves (x0 + (x1 - x0)(1 - cos(pi tau / T)) / 2, the
    acceleration jumps at each end and passes every speed) between seeded
    random targets and speeds, with seeded dwells; br_simlog's is
    trapezoidal between four fixed targets;
  - integrator: SUBSTEPS substeps per period (br_simlog 10), the rigid body
    by the midpoint rule on velocity with the substep's friction (no
    closed-form impulse), the bristle state by the exact update over the
    substep's displacement;
  - causes are written here from their physical description, not from the
    cause modules; two forces of no named cause: a drag growing with the
    square of the speed (a seal, a fluid) and a friction bump at one place
    of the travel (a dent, a chip on the guide).

Machines (MACHINES): the reference axis, a heavy one (EMPS-like mass and
friction), a light one, the reference with a coarse encoder (0.1 µm, 13 times the reference's step), and
the reference logged every 0.5 ms.

Usage as a module: write_log(path, machine_name, causes, noise_N, seed).
"""
import math

import numpy as np

SUBSTEPS = 20
DURATION_S = 24.0
TRAVEL_M = 0.1
KP_1PS = 160.18
KV_PER_KG = 90.0          # velocity-loop gain over the moving mass, 1/s (EMPS's)

MACHINES = {
    "reference": dict(M=34.67, Fc=7.0, Fs=18.0, vs=2e-5, s0=4e6, s1=2e3, s2=50.0, q=0.008 / 2 ** 20, dt=1e-3),
    "heavy": dict(M=95.0, Fc=20.0, Fs=26.0, vs=1e-3, s0=2e6, s1=3e3, s2=170.0, q=0.008 / 2 ** 20, dt=1e-3),
    "light": dict(M=6.0, Fc=2.0, Fs=3.0, vs=5e-4, s0=1e6, s1=600.0, s2=15.0, q=0.005 / 2 ** 18, dt=1e-3),
    "coarse": dict(M=34.67, Fc=7.0, Fs=18.0, vs=2e-5, s0=4e6, s1=2e3, s2=50.0, q=1e-7, dt=1e-3),
    "fast": dict(M=34.67, Fc=7.0, Fs=18.0, vs=2e-5, s0=4e6, s1=2e3, s2=50.0, q=0.008 / 2 ** 20, dt=5e-4),
}


def trajectory(n, dt, rng):
    """Cosine moves between random targets in [0, TRAVEL_M] at random top
    speeds (0.01 .. 0.06 m/s), each followed by a 0.15 .. 0.4 s dwell."""
    ref = np.empty(n)
    x, k = 0.0, 0
    dwell = int(0.3 / dt)
    ref[:dwell] = 0.0
    k = dwell
    while k < n:
        x1 = float(rng.uniform(0.0, TRAVEL_M))
        if abs(x1 - x) < 0.01:
            x1 = TRAVEL_M - x1
        vmax = float(rng.uniform(0.01, 0.06))
        T = math.pi * abs(x1 - x) / (2.0 * vmax)
        m = max(2, int(T / dt))
        tau = np.arange(m) * dt
        seg = x + (x1 - x) * 0.5 * (1.0 - np.cos(np.pi * tau / (m * dt)))
        take = min(m, n - k)
        ref[k:k + take] = seg[:take]
        k += take
        d = int(rng.uniform(0.15, 0.4) / dt)
        take = min(d, n - k)
        ref[k:k + take] = x1
        k += take
        x = x1
    return ref


def simulate(machine, causes, noise_N, seed, duration_s=DURATION_S):
    """(t, ref, pos, force) of one log. causes: {name: value} with
    offset (N), asym (dFc_N, dFv_Nspm), ripple (A_N, P_m, phase_rad),
    gradient (1/m), delay (s), drag (N s^2/m^2), bump (relative height,
    centre m, width m)."""
    mc = MACHINES[machine]
    M, Fc, Fs, vs, s0, s1, s2, qres, dt = (mc[k] for k in ("M", "Fc", "Fs", "vs", "s0", "s1", "s2", "q", "dt"))
    rng = np.random.default_rng(seed)
    n = int(round(duration_s / dt))
    ref = trajectory(n, dt, rng)
    kv = KV_PER_KG * M
    umax = 15.0 * (Fs + s2 * 0.06 + M * 2.0)
    off = causes.get("offset", 0.0)
    dfc, dfv = causes.get("asym", (0.0, 0.0))
    ra, rp, rph = causes.get("ripple", (0.0, 1.0, 0.0))
    grad = causes.get("gradient", 0.0)
    delay = causes.get("delay", 0.0)
    drag = causes.get("drag", 0.0)
    bh, bc, bw = causes.get("bump", (0.0, 0.0, 1.0))
    c_neg = (Fc + dfc) / Fc
    h = dt / SUBSTEPS
    two_pi = 2.0 * math.pi
    exp, sin, floor = math.exp, math.sin, math.floor
    dm = int(floor(delay / dt + 1e-12))
    dfrac = delay / dt - dm
    cmd = np.zeros(n)
    pos = np.empty(n)
    force = np.empty(n)
    x = v = z = 0.0
    q_prev = qf_prev = 0.0
    for k in range(n):
        q = floor(x / qres + 1e-9) * qres
        qf = 0.5 * (q + q_prev)
        qdot = (qf - qf_prev) / dt
        q_prev, qf_prev = q, qf
        u = KP_1PS * kv * (ref[k] - q) - kv * qdot
        u = umax if u > umax else (-umax if u < -umax else u)
        cmd[k] = u
        pos[k] = q
        for i in range(SUBSTEPS):
            if delay > 0.0:
                j = k - dm - (1 if (i + 0.5) * h < dfrac * dt else 0)
                Fa = cmd[j] if j >= 0 else 0.0
            else:
                Fa = u
            # midpoint rule: the friction at the substep's mid velocity, twice
            vm = v
            for _ in range(2):
                dx = vm * h
                neg = vm < 0.0
                g = Fc * (c_neg if neg else 1.0) * (1.0 + (Fs / Fc - 1.0) * exp(-abs(vm) / vs))
                # the bristle state over the displacement dx at g: exact update
                if dx != 0.0:
                    r = s0 * abs(dx) / g
                    zss = math.copysign(g / s0, dx)
                    z1 = zss + (z - zss) * exp(-r)
                else:
                    z1 = z
                zm = 0.5 * (z + z1)
                xm = x + 0.5 * dx
                kx = max(0.0, 1.0 + grad * xm)
                if bh:
                    kx *= 1.0 + bh * exp(-((xm - bc) / bw) ** 2)
                fv = (s2 + dfv) if neg else s2
                ff = kx * (fv * vm + s0 * zm + s1 * (z1 - z) / h)
                fl = off + ra * sin(two_pi * xm / rp + rph) + drag * vm * abs(vm)
                v1 = v + (Fa - ff - fl) * h / M
                vm = 0.5 * (v + v1)
            x += vm * h
            v, z = v1, z1
        if not math.isfinite(x):
            raise RuntimeError("axis_sim: the simulation diverged")
    force = cmd + noise_N * rng.standard_normal(n)
    t = np.arange(n) * dt
    return t, ref, pos, force


def write_log(path, machine, causes, noise_N, seed):
    t, ref, pos, force = simulate(machine, causes, noise_N, seed)
    with open(path, "w") as f:
        f.write("t,ref,pos,force\n")
        np.savetxt(f, np.column_stack([t, ref, pos, force]), fmt=("%.7f", "%.10e", "%.10e", "%.8e"), delimiter=",")
    return path
