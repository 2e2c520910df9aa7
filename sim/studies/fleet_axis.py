# SPDX-License-Identifier: Apache-2.0
"""One axis of the fleet study (docs/fleet.md, "The axes"): its draw from its
own seed, the truth (the plant the simulator runs) and the machine file a user
writes for it before any log (configure.md, step 1: a copy of
machines/reference.json with what the data sheets give; the friction left
"assumed"), and its trajectory set.

Every quantity comes from numpy's Generator seeded with (study seed, index):
an axis is the same whatever the order, the worker or the number of workers.
"""
import copy
import json
import math
import os

import sys

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "firmware", "design"))
import hinf_weights  # noqa: E402  (the H-inf weights from the machine)
import machine  # noqa: E402  (the stop bound of the drive protections)

# the ranges of issue 28 (a machine file a user may bring)
LEAD_M = (2e-3, 40e-3)
MASS_KG = (1.0, 200.0)
ENC_BITS = (12, 26)
FC_N = (0.5, 200.0)
VS_MPS = (1e-5, 1e-3)
SIGMA0_NPM = (1e5, 1e8)
PERIOD_S = (0.25e-3, 2e-3)
DELAY_MAX_S = 3e-3
P_DELAY = 0.5              # probability that the axis has an actuator delay the given file does not hold
P_PRESLIDING = 0.25        # probability that the plant's presliding is Maxwell-slip (issue 30), not LuGre
GMS_N = (2, 6)             # its elements (equal shares), issue 30's drawn plants' range
GMS_D_M = (0.3e-6, 30e-6)  # their breakaway displacements at Fs, log-uniform (issue 30's range)
GMS_ZETA = (0.01, 0.8)     # each element's mode damping ratio on the moving mass, log-uniform: the span
                           # issue 30's 300-4000 N s/m gives for those elements on the reference axis
MOTOR_REV_PER_S = 50.0     # 3000 rpm: the axis's speed limit is lead x this
TRAVEL_M = 0.3             # every axis's working range from position 0 (the reference's stroke); the
                           # circles (centred on 0) reach RADIUS_M[1] below it. The stroke adds each axis's
                           # stop bound at both ends (given_file: the drive's soft limits are the range)
WORK_BELOW_M = 0.055       # the range's reach below 0: the largest circle radius and 5 mm
IDENT_ACC_MPS2 = 0.5       # the identification run's acceleration (docs/simlog.md)
FORCE_MARGIN = 3.0         # amplifier force: this times (stiction + viscous at top speed + mass x 2 m/s^2)
SIZING_ACC_MPS2 = 2.0
PF_PERIOD_RATIO = 1.5      # the PF's period over the control period (the reference's 1.5 ms / 1 ms)
# trajectory set
CIRCLES = 2                # circles at a drawn feed and radius, beside the thesis circle
FEED_MM_MIN = (100.0, 5000.0)
FEED_TOOL_MAX_MM_MIN = 3000.0   # the tools' bound (sim/lib/tool/br_tool_limits.h BR_TOOL_FEED_MAX_MM_MIN)
RADIUS_M = (1e-3, 50e-3)
MAX_REV_S = 12.0           # one revolution at most this long (the run's cost)
P2P_MOVES = 4
MOVE_ACC_MAX_MPS2 = 5.0    # the moves' (and the scaled EMPS reference's) acceleration at most (half a g)
P2P_DWELL_S = 0.2
P2P_ENDS = (0.05, 0.95)    # the moves stay between these shares of the travel
EMPS_ENDS = (0.1, 0.9)     # the scaled EMPS reference's range, shares of the travel
LIMIT_SHARE = 0.9          # the tracked references stay within this share of the speed and acceleration the
                           # drive's reference limiter accepts (docs/fleet.md, "The trajectories")
EMPS_REF = os.path.join(os.path.dirname(REPO), "shared", "data", "emps", "emps_estimation.csv")
EMPS_SPEED_SHARE = 0.8     # the scaled EMPS reference peaks at this share of the axis's speed and force limits


def loguniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def axis_seed(study_seed, i):
    """the axis's own seed: independent of scheduling"""
    return [int(study_seed), int(i)]


def draw(study_seed, i):
    """The axis i: mechanics, friction, period, noise, delay (docs/fleet.md, in this order)."""
    rng = np.random.default_rng(axis_seed(study_seed, i))
    lead = loguniform(rng, *LEAD_M)
    meff = loguniform(rng, *MASS_KG)      # the moving mass at the load, J/L^2 + M
    share = float(rng.uniform(0.2, 0.75))  # of it the motor and screw's (reference 0.71, heavy 0.43)
    # the encoder: the signed 32-bit position count must hold the working range and the following
    # limit beyond it (br_ref_t, the plant's counter, the TRAVEL fault's reach)
    reach = TRAVEL_M + 0.01 * lead * MOTOR_REV_PER_S
    top_bits = min(ENC_BITS[1], int(math.floor(math.log2(2.0 ** 31 * lead / reach))))
    bits = int(rng.integers(ENC_BITS[0], top_bits + 1))
    L = lead / (2.0 * math.pi)
    inertia, mass = share * meff * L ** 2, (1.0 - share) * meff
    fc = loguniform(rng, *FC_N)
    fs = fc * float(rng.uniform(1.0, 2.5))
    vs = loguniform(rng, *VS_MPS)
    sigma0 = loguniform(rng, *SIGMA0_NPM)
    # bristle damping: a damping ratio of the presliding mode, 2 zeta sqrt(sigma0 Meff)
    sigma1 = 2.0 * float(rng.uniform(0.05, 0.2)) * math.sqrt(sigma0 * meff)
    sigma2 = fc * loguniform(rng, 1.0, 20.0)  # viscous: 0.1-2 Fc at 0.1 m/s
    period = float(round(loguniform(rng, *PERIOD_S), 5))
    force_noise = fc * float(rng.uniform(0.0, 0.03))
    delay = float(rng.uniform(0.0, DELAY_MAX_S)) if rng.uniform() < P_DELAY else 0.0
    presliding = bool(rng.uniform() < P_PRESLIDING)
    # drawn last, and only for such a plant: every other axis draws what it drew before
    gms = None
    if presliding:
        n = int(rng.integers(GMS_N[0], GMS_N[1] + 1))
        gms = {"breakaway_m": sorted(loguniform(rng, *GMS_D_M) for _ in range(n)),
               "zeta": loguniform(rng, *GMS_ZETA)}
    vmax = lead * MOTOR_REV_PER_S
    f_max = FORCE_MARGIN * (fs + sigma2 * vmax + meff * SIZING_ACC_MPS2)
    return {"i": i, "seed": axis_seed(study_seed, i), "lead_m_per_rev": lead, "table_mass_kg": mass,
            "inertia_kgm2": inertia, "Meff_kg": meff, "counts_per_rev": 2 ** bits, "encoder_bits": bits,
            "friction": {"sigma2_Nspm": sigma2, "sigma0_Npm": sigma0, "sigma1_Nspm": sigma1, "Fc_N": fc, "Fs_N": fs,
                         "vs_mps": vs},
            "period_s": period, "force_noise_N": force_noise, "delay_s": delay, "presliding": presliding,
            "gms": gms,
            "max_speed_mps": vmax, "force_max_N": f_max, "traj": trajectories(np.random.default_rng(axis_seed(study_seed, i) + [1]), vmax)}


def gms_options(ax):
    """the plant's Maxwell-slip friction as the simulating tools' options (sim/lib/gms_args): [] for LuGre"""
    g = ax.get("gms")
    if not g:
        return []
    return ["--gms", ",".join("%.6g" % d for d in g["breakaway_m"]), "--gms-zeta", "%.6g" % g["zeta"]]


def trajectories(rng, vmax):
    """the axis's trajectory set (its own stream of the axis's seed): the thesis circle, CIRCLES
    circles, the point-to-point moves, EMPS"""
    out = [{"kind": "thesis_circle", "name": "thesis_circle"}]
    fmax = min(FEED_MM_MIN[1], FEED_TOOL_MAX_MM_MIN, vmax * 6e4)
    for k in range(CIRCLES):
        feed = loguniform(rng, FEED_MM_MIN[0], fmax)
        rmax = min(RADIUS_M[1], feed / 6e4 * MAX_REV_S / (2.0 * math.pi))
        radius = loguniform(rng, RADIUS_M[0], max(rmax, RADIUS_M[0]))
        out.append({"kind": "circle", "name": "circle%d" % k, "feed_mm_min": feed, "radius_m": radius,
                    "direction": "cw" if rng.uniform() < 0.5 else "ccw"})
    # point-to-point: P2P_MOVES moves there and back, each over a share of the room left between
    # P2P_ENDS of the travel, at a share of the speed limit
    moves = [(float(rng.uniform(0.2, 1.0)), float(rng.uniform(0.2, 1.0)) * vmax) for _ in range(P2P_MOVES)]
    out.append({"kind": "p2p", "name": "p2p", "moves": moves})
    out.append({"kind": "emps", "name": "emps"})
    return out


def reference_file():
    """machines/reference.json, which a user's first machine file starts from"""
    with open(os.path.join(REPO, "machines", "reference.json"), encoding="utf-8") as f:
        return json.load(f)


def given_file(ax, name):
    """The machine file the user writes before any log: machines/reference.json
    with the data sheets' values (lead, inertia, table mass, encoder, amplifier,
    the loop's period, the limits) and its friction kept and marked assumed."""
    m = reference_file()
    L = ax["lead_m_per_rev"] / (2.0 * math.pi)
    m["name"] = name
    m["source"] = "sim/studies/fleet.py: a drawn axis (docs/fleet.md); friction from machines/reference.json, assumed"
    m["mechanics"] = {"table_mass_kg": ax["table_mass_kg"], "inertia_kgm2": ax["inertia_kgm2"],
                      "lead_m_per_rev": ax["lead_m_per_rev"]}
    m["encoder"] = {"counts_per_rev": ax["counts_per_rev"], "counter_bits": 32}
    tau = ax["force_max_N"] * L
    m["amplifier"] = {"torque_per_duty_Nm": tau, "duty_limit": 1.0}
    m["control"]["period_s"] = ax["period_s"]
    m["control"]["torque_limit_Nm"] = tau
    m["estimator"]["pf"]["period_s"] = float(round(PF_PERIOD_RATIO * ax["period_s"], 6))
    # the drive's acceleration limit from the data sheet: half the amplifier's force on the moving
    # mass (the trajectories' move_acc stays below it)
    m["limits"] = {"max_speed_mps": ax["max_speed_mps"], "max_accel_mps2": 0.5 * ax["force_max_N"] / ax["Meff_kg"]}
    set_stroke(m)
    m["provenance"] = {"friction." + k: "assumed" for k in m["friction"]}
    return m


def scale_load_q(m, ref):
    """estimator.<est>.load of the given file m in the actuator's force squared per second
    (q_Fact2_per_s, docs/machine-file.md) where ref, the machine file m copies it from, has it in
    N^2/s: the same random walk relative to the actuator as on ref, instead of the same one in
    N^2/s on an actuator of tens or thousands of N"""
    F_ref = machine.actuator_force_N(ref)
    for est, blk in m["estimator"].items():
        ld = blk.get("load") if isinstance(blk, dict) else None
        if ld is not None and "q_N2_per_s" in ld:
            blk["load"] = {"q_Fact2_per_s": float(ld["q_N2_per_s"]) / (F_ref * F_ref)}


def use_hinf_rule(m, always=False):
    """control.hinf of the given file m from the machine (hinf_weights.py, docs/modules/hinf.md) when
    the reference's weights admit no acceptable design on it, or always: why, or None (kept)"""
    hinf, why = hinf_weights.weights_or_rule(m, always)
    if why is not None:
        m["control"]["hinf"] = hinf
        m["provenance"].update({"control.hinf." + k: "derived" for k in hinf})
    return why


def set_stroke(m):
    """The stroke of machine m: the working range [-WORK_BELOW_M, TRAVEL_M] and the stop bound of
    the drive's protections (from m's own friction) at both ends, so that the soft limits are the
    range."""
    b = machine.stop_bound_m(m)
    m["limits"].update({"travel_min_m": -WORK_BELOW_M - b, "travel_m": TRAVEL_M + WORK_BELOW_M + 2.0 * b})


def truth_file(ax, given):
    """The plant: the given file with the drawn friction and the delay no machine file knows."""
    m = copy.deepcopy(given)
    m.pop("provenance")
    m["source"] = "sim/studies/fleet.py: the truth of a drawn axis (docs/fleet.md)"
    m["friction"] = dict(ax["friction"])
    set_stroke(m)
    if ax["delay_s"] > 0.0:
        m["causes"] = {"actuator_delay": {"delay_s": ax["delay_s"]}}
    return m


def track_limits(ax, m, speed_cap):
    """What the axis's tracked references keep to on the drive of machine m (the machine file the
    tools are built for): the P2P_ENDS range's speed, the EMPS_ENDS range's speed (LIMIT_SHARE of
    speed_cap(lo, hi), the largest speed that drive's reference limiter passes untouched in [lo, hi]
    toward either end: `br_track --speed-cap` of the build for m, the limiter's own caps, max speed,
    the braking curve to the soft limits and the coast envelope, at every period the application
    runs at), the acceleration (LIMIT_SHARE of the limiter's, move_acc at most) and the
    sample step, half the control period: the control period and the PF's (PF_PERIOD_RATIO of it)
    are whole multiples of it, so br_track reads the reference at its samples, never between two
    (a 1 ms step read by linear interpolation every 0.27 ms showed the limiter 3.7 times the
    acceleration)"""
    acc = min(move_acc(ax), LIMIT_SHARE * machine.limit_defaults(m)[0])
    v = [LIMIT_SHARE * speed_cap(e[0] * TRAVEL_M, e[1] * TRAVEL_M) for e in (P2P_ENDS, EMPS_ENDS)]
    return {"p2p_mps": v[0], "emps_mps": v[1], "acc_mps2": acc, "dt_s": 0.5 * m["control"]["period_s"]}


def p2p_reference(moves, vmax, vtop, acc, dt):
    """trapezoidal moves there and back from the travel's low end, each over its share of the room
    left in its direction and followed by a dwell, each move's speed (drawn as a share of the axis's
    speed limit vmax) scaled to that share of vtop where vtop is below vmax: (t, ref)"""
    lo, hi = P2P_ENDS[0] * TRAVEL_M, P2P_ENDS[1] * TRAVEL_M
    x = lo
    xs = [x] * int(round(P2P_DWELL_S / dt))
    sign = 1.0
    for share, v in moves:
        dist = share * (hi - x if sign > 0 else x - lo)
        v = min(v, vmax) * min(1.0, vtop / vmax)
        ta = v / acc
        if acc * ta * ta > dist:  # a triangle
            ta = math.sqrt(dist / acc)
            v = acc * ta
        tc = (dist - acc * ta * ta) / v
        T = 2.0 * ta + tc
        t = np.arange(1, int(math.ceil(T / dt)) + 1) * dt
        t = np.minimum(t, T)
        s = np.where(t < ta, 0.5 * acc * t ** 2,
                     np.where(t < ta + tc, 0.5 * acc * ta ** 2 + v * (t - ta), dist - 0.5 * acc * (T - t) ** 2))
        xs += list(x + sign * s)
        x += sign * dist
        xs += [x] * int(round(P2P_DWELL_S / dt))
        sign = -sign
    return np.arange(len(xs)) * dt, np.array(xs)


def emps_reference(vmax, acc, dt):
    """the EMPS reference (../shared/data/emps/) scaled to the axis: its range to EMPS_ENDS of the
    travel, its time so that it peaks at EMPS_SPEED_SHARE of the speed vmax and of acc: (t, ref)"""
    d = np.loadtxt(EMPS_REF, delimiter=",", skiprows=1, usecols=(0, 1))
    t0, r0 = d[:, 0] - d[0, 0], d[:, 1] - d[:, 1].min()
    kx = (EMPS_ENDS[1] - EMPS_ENDS[0]) * TRAVEL_M / r0.max()
    h = t0[1] - t0[0]
    v = np.gradient(r0, h)
    a = np.gradient(v, h)
    kt = max(kx * np.abs(v).max() / (EMPS_SPEED_SHARE * vmax),
             math.sqrt(kx * np.abs(a).max() / (EMPS_SPEED_SHARE * acc)))
    t = np.arange(0.0, t0[-1] * kt, dt)
    return t, EMPS_ENDS[0] * TRAVEL_M + kx * np.interp(t / kt, t0, r0)


def move_acc(ax):
    """the acceleration of the moves: half what the amplifier leaves beyond stiction and viscous at top
    speed, at most MOVE_ACC_MAX_MPS2"""
    f = ax["friction"]
    spare = ax["force_max_N"] - f["Fs_N"] - f["sigma2_Nspm"] * ax["max_speed_mps"]
    return min(0.5 * spare / ax["Meff_kg"], MOVE_ACC_MAX_MPS2)


def write_reference(path, t, ref):
    """a reference as br_track reads it (the measured-log columns t,ref,pos,force; pos = ref, force 0)"""
    with open(path, "w", encoding="utf-8") as f:
        f.write("t,ref,pos,force\n")
        for a, b in zip(t, ref):
            f.write("%.6f,%.10e,%.10e,0\n" % (a, b, b))
