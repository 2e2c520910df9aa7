# SPDX-License-Identifier: Apache-2.0
"""H-infinity weights from the machine (docs/modules/hinf.md, "Weights from
the machine"): control.hinf for any machine file from its periods, its
effective inertia, its torque limit, its encoder, its stiction and its
following-error limit, so that a machine whose file copies another machine's
weights still gets a stable sampled loop, stiff enough for its friction.

The design (synth_hinf.py) has B1 = L Fs B2: w enters where u does, so the
H-inf problem is an LQ problem with R scaled by (1 - 1/margin^2), and its
integral gain is exactly
    K_eps = -c_eps u / s,   s = sqrt(1 - 1/margin^2)                    (1)
Writing K_eps = -Jeff w0^3 defines the loop's frequency w0 (the geometric
mean of the closed-loop poles' radii without viscous friction). Scaling
time by w0 and the states by Jeff/u makes every design with
    c_theta = a_theta s Jeff w0^2 / u,  c_omega = a_omega s Jeff w0 / u,
    c_eps   = s Jeff w0^3 / u                                           (2)
the same normalised design (up to the viscous term L^2 sigma2 / Jeff); its
shape (a_theta, a_omega) and margin are the reference's. w0 is
    w0 = min(beta pi / h_slow, w_count)                                 (3)
beta pi / h_slow a share beta of the Nyquist frequency of the slower of the
control and PF periods (the reference's 9.47 Hz against its 1.5 ms), and
w_count the frequency at which one encoder count in the backward-difference
velocity, |K_omega| q / h_fast, is COUNT_TORQUE_SHARE of the torque limit;
then raised for the friction where (3) leaves the axis soft:
    e_step(w0) <= FOLLOWING_SHARE e_max                                 (4)
e_step the largest position error of the loop as implemented at h_slow after
a force step the size of stiction (w = 1: a breakaway), e_max the
following-error limit (where the drive brakes); w0 rises to the smallest
frequency meeting (4), but never past the largest one whose sampled loop
keeps RAISE_PM_MIN_DEG and RAISE_GM_MIN at each period and w_count.

`synth_hinf.py --machine FILE --suggest` prints the weights it gives; the
diagnosis's machine.json and the fleet's machine files take them when the
file's own weights admit no acceptable design (weights_or_rule), with a
warning where the stiction step passes e_max even at the raised w0."""
import math

import numpy as np

import loop_analysis
import machine
import synth_hinf

# the reference's design in normalised form (2): machines/reference.json's weights with
# w0 = 59.47 rad/s and h_slow = 1.5 ms give beta = 0.028396, a_theta = 1.4868,
# a_omega = 0.53054 (tests/design/test_hinf_weights.py checks the rule gives them back)
NYQUIST_SHARE = 0.02840
SHAPE = (1.487, 0.5305)
MARGIN = 2.0
# one encoder count of velocity error may ask at most this share of the torque limit
COUNT_TORQUE_SHARE = 0.1
# (4): a stiction step may move the axis at most this share of the following-error limit (a choice:
# half the error at which the drive brakes; the reference's step moves it 0.043 of its limit)
FOLLOWING_SHARE = 0.5
# the margins the friction's raise keeps at each checked period (a choice: the usual floors of
# 45 deg and 6 dB with some room for what no machine file holds, a delay, resonances)
RAISE_PM_MIN_DEG = 50.0
RAISE_GM_MIN = 10.0 ** (8.0 / 20.0)
RAISE_SPAN = 100.0      # the raise looks up to this times the w0 of (3)
REL_TOL = 1e-3          # the raise's bisections' relative resolution in w0
ENCODER_HALVINGS = 60   # the encoder bound's bisection over 1e-4 ... 1 of (3)'s w0: to the float
STEP_DECAY = 1e-3       # the stiction step's response is followed until its slowest mode falls to this
STEP_MAX_PERIODS = 100000
MARGIN_GRID = 2000      # the raise's margin search brackets its crossings on this many frequencies
SIG_DIGITS = 6


def periods(m):
    """the control period and the PF's, the slower one and the faster one"""
    h = (m["control"]["period_s"], m["estimator"]["pf"]["period_s"])
    return max(h), min(h)


def from_omega(m, w0):
    """control.hinf for the loop frequency w0 (rad/s), eq. (2)"""
    p = machine.params(m)
    k = p["Jeff_kgm2"] * math.sqrt(1.0 - 1.0 / MARGIN ** 2) / m["control"]["torque_limit_Nm"]

    def r(x):
        return float("%.*g" % (SIG_DIGITS, x))
    return {"weight_theta_per_rad": r(SHAPE[0] * k * w0 ** 2), "weight_omega_s_per_rad": r(SHAPE[1] * k * w0),
            "weight_eps_per_rad_s": r(k * w0 ** 3), "gamma_margin": MARGIN}


def with_hinf(m, hinf):
    """a copy of m's sections the design reads, with control.hinf replaced"""
    out = dict(m)
    out["control"] = dict(m["control"], hinf=hinf)
    return out


def _gain(m, hinf):
    mm = with_hinf(m, hinf)
    return machine.params(mm), synth_hinf.weights(mm), synth_hinf.gain(machine.params(mm), synth_hinf.weights(mm))[0]


def count_torque_share(m, hinf):
    """|K_omega| q / (h_fast u): the torque one encoder count of the velocity asks, over the limit"""
    K = _gain(m, hinf)[2]
    q = 2.0 * math.pi / m["encoder"]["counts_per_rev"]
    return abs(K[1]) * q / (periods(m)[1] * m["control"]["torque_limit_Nm"])


def friction_step_m(m, hinf):
    """e_step of (4): the largest |position error| at the load (m) of the loop as implemented at
    the slower period after a force step of Fs; inf when that loop is unstable"""
    p, _, K = _gain(m, hinf)
    Phi, Gw, _ = synth_hinf.sampled_loop(p, K, periods(m)[0])
    rho = float(np.max(np.abs(np.linalg.eigvals(Phi))))
    if not rho < 1.0:
        return math.inf
    x, peak = np.zeros(Phi.shape[0]), 0.0
    for _ in range(min(STEP_MAX_PERIODS, int(math.ceil(math.log(STEP_DECAY) / math.log(rho))) + 1)):
        x = Phi @ x + Gw[:, 0]
        peak = max(peak, abs(float(x[0])))
    return peak * p["L_mprad"]


def raise_holds(m, w0):
    """whether the friction's raise may go to w0: the sampled loop at each checked period stable
    with RAISE_PM_MIN_DEG and RAISE_GM_MIN, and one count asking at most COUNT_TORQUE_SHARE"""
    hinf = from_omega(m, w0)
    try:
        p, wts, K = _gain(m, hinf)
    except synth_hinf.DesignError:
        return False
    A, B2 = synth_hinf.plant(p)
    for dt in wts["check_dt_s"]:
        Phi = synth_hinf.sampled_loop(p, K, dt)[0]
        if not np.max(np.abs(np.linalg.eigvals(Phi))) < 1.0:
            return False
        r = loop_analysis.margins(loop_analysis.sampled_loop(A, B2, K, dt), 1e-2, np.pi / dt * (1 - 1e-9),
                                  MARGIN_GRID)
        if r["pm_deg"] < RAISE_PM_MIN_DEG or r["gm_up"] < RAISE_GM_MIN:
            return False
    return count_torque_share(m, hinf) <= COUNT_TORQUE_SHARE


def _edge(ok, a, b, halvings):
    """(exp(a), exp(b)) after this many halvings of [a, b] in log w0, ok(exp(a)) and not ok(exp(b))
    kept; ok is monotone"""
    for _ in range(halvings):
        mid = 0.5 * (a + b)
        if ok(math.exp(mid)):
            a = mid
        else:
            b = mid
    return math.exp(a), math.exp(b)


def _raise_edge(ok, lo, hi):
    """_edge between the frequencies lo and hi to REL_TOL"""
    a, b = math.log(lo), math.log(hi)
    return _edge(ok, a, b, max(0, int(math.ceil(math.log2((b - a) / math.log1p(REL_TOL))))))


def suggest(m):
    """(control.hinf, info): eqs. (3)-(4), info = {"omega0_rad_s", "bound": "period", "encoder",
    "friction" (raised to meet (4)) or "margins" (raised as far as the margins and the encoder allow,
    short of (4)), "count_torque_share", "friction_step_m" (e_step at w0), "following_m" (e_max),
    "omega_friction_rad_s" (the w0 that meets (4), estimated from e_step ~ 1/w0^2 when out of reach),
    "nyquist_rad_s" (pi / h_slow)}"""
    h_slow = periods(m)[0]
    w_hi = NYQUIST_SHARE * math.pi / h_slow
    target = FOLLOWING_SHARE * machine.following_m(m)
    w0, bound = w_hi, "period"
    if count_torque_share(m, from_omega(m, w_hi)) > COUNT_TORQUE_SHARE:
        w0, bound = _edge(lambda w: count_torque_share(m, from_omega(m, w)) <= COUNT_TORQUE_SHARE,
                          math.log(w_hi) - math.log(1e4), math.log(w_hi), ENCODER_HALVINGS)[0], "encoder"
    step = friction_step_m(m, from_omega(m, w0))
    w_fric = w0
    if step > target:
        w_cap = w0
        if raise_holds(m, w0):
            w_top = RAISE_SPAN * w0
            w_cap = w_top if raise_holds(m, w_top) else _raise_edge(lambda w: raise_holds(m, w), w0, w_top)[0]
        step_cap = friction_step_m(m, from_omega(m, w_cap))
        if step_cap <= target:
            w0, bound = _raise_edge(lambda w: friction_step_m(m, from_omega(m, w)) > target, w0, w_cap)[1], "friction"
            w_fric = w0
        else:
            # e_step falls as 1 / w0^2 (the normalised design, eq. 2): the w0 it would need
            w_fric = w_cap * math.sqrt(step_cap / target)
            w0, bound = w_cap, "margins" if w_cap > w0 else bound
    hinf = from_omega(m, w0)
    return hinf, {"omega0_rad_s": w0, "bound": bound, "count_torque_share": count_torque_share(m, hinf),
                  "friction_step_m": friction_step_m(m, hinf), "following_m": machine.following_m(m),
                  "omega_friction_rad_s": w_fric, "nyquist_rad_s": math.pi / h_slow}


def refusal(m):
    """None when m's own weights give an acceptable design, else synth_hinf's reason"""
    try:
        synth_hinf.design(machine.params(m), synth_hinf.weights(m))
    except synth_hinf.DesignError as e:
        return str(e)
    return None


def friction_shortfall(info):
    """None when the rule's stiction step stays within the following-error limit, else a warning:
    H-inf alone cannot keep a breakaway within it at this period"""
    if info["friction_step_m"] <= info["following_m"]:
        return None
    hz = 1.0 / (2.0 * math.pi)
    return ("a stiction step moves the axis %.3g mm, beyond the following-error limit %.3g mm: (4) needs "
            "w0 = %.4g Hz (%.3g of the Nyquist frequency %.4g Hz), the sampled loop's margins and the encoder "
            "allow %.4g Hz: H-inf alone may brake the axis at a breakaway; a shorter period holds it" % (
                info["friction_step_m"] * 1e3, info["following_m"] * 1e3, info["omega_friction_rad_s"] * hz,
                info["omega_friction_rad_s"] / info["nyquist_rad_s"], info["nyquist_rad_s"] * hz,
                info["omega0_rad_s"] * hz))


def weights_or_rule(m, always=False, reason="asked for"):
    """(control.hinf, why): m's own weights with why None when they give an acceptable design and
    always is False; else the rule's (suggest) and why the rule was used (reason when always), with
    friction_shortfall's warning where there is one; DesignError when the rule's weights fail
    synth_hinf's checks too"""
    why = reason if always else refusal(m)
    if why is None:
        return m["control"]["hinf"], None
    hinf, info = suggest(m)
    fail = refusal(with_hinf(m, hinf))
    if fail is not None:
        raise synth_hinf.DesignError("the weights from the machine fail too: " + fail)
    short = friction_shortfall(info)
    return hinf, "%s; the weights from the machine (w0 = %.4g Hz, bound by the %s)%s" % (
        why, info["omega0_rad_s"] / (2.0 * math.pi), info["bound"], "; " + short if short else "")
