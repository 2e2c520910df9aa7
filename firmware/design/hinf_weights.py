# SPDX-License-Identifier: Apache-2.0
"""H-infinity weights from the machine (docs/modules/hinf.md, "Weights from
the machine"): control.hinf for any machine file from its periods, its
effective inertia, its torque limit and its encoder, so that a machine whose
file copies another machine's weights still gets a stable sampled loop.

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
velocity, |K_omega| q / h_fast, is COUNT_TORQUE_SHARE of the torque limit.

`synth_hinf.py --machine FILE --suggest` prints the weights it gives; the
diagnosis's machine.json and the fleet's machine files take them when the
file's own weights admit no acceptable design (weights_or_rule)."""
import math

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


def count_torque_share(m, hinf):
    """|K_omega| q / (h_fast u): the torque one encoder count of the velocity asks, over the limit"""
    mm = with_hinf(m, hinf)
    K = synth_hinf.gain(machine.params(mm), synth_hinf.weights(mm))[0]
    q = 2.0 * math.pi / m["encoder"]["counts_per_rev"]
    return abs(K[1]) * q / (periods(m)[1] * m["control"]["torque_limit_Nm"])


def suggest(m):
    """(control.hinf, info): eq. (3), info = {"omega0_rad_s", "bound": "period" or "encoder",
    "count_torque_share"}"""
    w_hi = NYQUIST_SHARE * math.pi / periods(m)[0]
    share = count_torque_share(m, from_omega(m, w_hi))
    if share <= COUNT_TORQUE_SHARE:
        return from_omega(m, w_hi), {"omega0_rad_s": w_hi, "bound": "period", "count_torque_share": share}
    lo, hi = math.log(w_hi) - math.log(1e4), math.log(w_hi)
    for _ in range(60):  # bisection on log w0: the share rises with w0
        mid = 0.5 * (lo + hi)
        if count_torque_share(m, from_omega(m, math.exp(mid))) > COUNT_TORQUE_SHARE:
            hi = mid
        else:
            lo = mid
    w0 = math.exp(lo)
    hinf = from_omega(m, w0)
    return hinf, {"omega0_rad_s": w0, "bound": "encoder", "count_torque_share": count_torque_share(m, hinf)}


def refusal(m):
    """None when m's own weights give an acceptable design, else synth_hinf's reason"""
    try:
        synth_hinf.design(machine.params(m), synth_hinf.weights(m))
    except synth_hinf.DesignError as e:
        return str(e)
    return None


def weights_or_rule(m, always=False):
    """(control.hinf, why): m's own weights with why None when they give an acceptable design and
    always is False; else the rule's (suggest) and why the rule was used"""
    why = "asked for" if always else refusal(m)
    if why is None:
        return m["control"]["hinf"], None
    hinf, info = suggest(m)
    reason = refusal(with_hinf(m, hinf))
    if reason is not None:
        raise synth_hinf.DesignError("the weights from the machine fail too: " + reason)
    return hinf, "%s; the weights from the machine (w0 = %.4g Hz, bound by the %s)" % (
        why, info["omega0_rad_s"] / (2.0 * math.pi), info["bound"])
