#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""H-infinity state-feedback synthesis for one axis with integral action
(thesis eq. 7); writes bristle_gen/ctrl/br_hinf_gains.h (default into firmware/gen/).

Augmented model, x = [e_theta, e_omega, eps] (motor side, eps = int e_theta dt):
    dx/dt = A x + B1 w + B2 u,   z = [Cz x; Dz u]
    A  = [[0, 1, 0], [0, -L^2 sigma2 / Jeff, 0], [1, 0, 0]]
    B2 = [0, 1/Jeff, 0]^T,  B1 = (L Fs) B2  (friction torque, w = 1 <-> stiction)
    Cz = diag(c_theta, c_omega, c_eps),  Dz = 1/u_norm
with the weights c_*, the margin and u_norm (the torque limit) of the machine
description's "control" section (docs/machine-file.md).
For a given gamma the stabilising solution X >= 0 of
    A'X + XA + X (B1 B1'/gamma^2 - B2 R^-1 B2') X + Cz'Cz = 0,  R = Dz'Dz
exists iff gamma > gamma_min; it is found from the stable invariant subspace
of the Hamiltonian. gamma_min is found by bisection (the gamma-iteration), the
design uses gamma = margin * gamma_min, and K = -R^-1 B2' X (u = K x).
The closed-loop H-infinity norm from w to z is then computed independently
(Hamiltonian bisection) and checked to be below gamma; the sampled loop
(ZOH plant, rectangular integral, backward-difference velocity) is checked
at the control period and at the PF's period.
A machine for which this fails (no stabilising design, a sampled loop that is
unstable) ends the script with "FILE: field control.hinf: problem", exit status 1.

With --report it also prints the design report: the gains, gamma, the
closed-loop norm and poles, and the loop's gain and phase margins and
closed-loop bandwidth, continuous and sampled (loop_analysis.py).
With --suggest it writes no header: it prints the weights the machine's
periods, inertia, torque limit, encoder, stiction and following-error limit
give (hinf_weights.py), as the file's control.hinf block, and the design they
give (exit 1 if it fails; a warning where a stiction step passes the
following-error limit even so).

Usage: synth_hinf.py [--machine FILE] [--out FILE] [--report] [--suggest]"""
import json
import argparse
import os
import sys

import numpy as np

import loop_analysis
import machine


class DesignError(Exception):
    """The machine admits no acceptable design with its weights."""


def weights(m):
    """The design inputs of the machine description: Cz diagonal, u_norm (the
    controller's torque limit, Dz = 1/u_norm), gamma margin, and the periods at
    which the sampled loop is checked (the control period, the PF's period)."""
    h = m["control"]["hinf"]
    dts = [m["control"]["period_s"]]
    if m["estimator"]["pf"]["period_s"] != dts[0]:
        dts.append(m["estimator"]["pf"]["period_s"])
    return dict(Cz_diag=[h["weight_theta_per_rad"], h["weight_omega_s_per_rad"], h["weight_eps_per_rad_s"]],
                u_norm_Nm=m["control"]["torque_limit_Nm"], gamma_margin=h["gamma_margin"], check_dt_s=dts)


def plant(p):
    L, J = p["L_mprad"], p["Jeff_kgm2"]
    A = np.array([[0.0, 1.0, 0.0], [0.0, -L * L * p["sigma2_Nspm"] / J, 0.0], [1.0, 0.0, 0.0]])
    B2 = np.array([[0.0], [1.0 / J], [0.0]])
    return A, B2


def riccati(A, B1, B2, C, R, gamma):
    """Stabilising X of the H-inf ARE, or None when gamma is not achievable."""
    n = A.shape[0]
    S = B1 @ B1.T / gamma**2 - B2 @ np.linalg.solve(R, B2.T)
    H = np.block([[A, S], [-C.T @ C, -A.T]])
    ev, V = np.linalg.eig(H)
    scale = max(1.0, np.max(np.abs(ev)))
    if np.min(np.abs(ev.real)) < 1e-9 * scale:
        return None  # eigenvalues on the imaginary axis
    stable = ev.real < 0
    if np.count_nonzero(stable) != n:
        return None
    V1, V2 = V[:n, stable], V[n:, stable]
    if np.linalg.cond(V1) > 1e12:
        return None
    X = np.real(V2 @ np.linalg.inv(V1))
    X = 0.5 * (X + X.T)
    if np.min(np.linalg.eigvalsh(X)) < -1e-9 * np.max(np.abs(X)):
        return None  # not positive semidefinite
    return X


def hinf_norm(A, B, C, D, tol=1e-7):
    """H-infinity norm of a stable continuous system by Hamiltonian bisection."""
    w = np.logspace(-3, 6, 2000)
    lo = max(np.linalg.norm(C @ np.linalg.solve(1j * wi * np.eye(A.shape[0]) - A, B) + D, 2) for wi in w)
    hi = 10.0 * lo + 1e-12
    while (hi - lo) > tol * hi:
        g = 0.5 * (lo + hi)
        # no imaginary-axis eigenvalue <=> norm < g (D = 0 here)
        Hm = np.block([[A, B @ B.T / g**2], [-C.T @ C, -A.T]])
        ev = np.linalg.eigvals(Hm)
        if np.any(np.abs(ev.real) < 1e-8 * max(1.0, np.max(np.abs(ev)))):
            lo = g
        else:
            hi = g
    return hi


def sampled_loop(p, K, dt):
    """Discrete closed loop as implemented: ZOH plant, eps += e dt, omega = dtheta/dt.
    State [theta_k, omega_k, eps_k, theta_{k-1}]; returns (Phi, Gamma_w, Cd)."""
    A, B2 = plant(p)
    Phi0, Gu, Ku = loop_analysis.sampled_open_loop(A, B2, K, dt)
    # u_k = Ku x_k closes the loop
    Phi = Phi0 + Gu @ Ku
    Gw = Gu * (p["L_mprad"] * p["Fs_N"])
    return Phi, Gw, Ku


def problem(p, wts):
    """A, B1, B2, Cz, R = Dz'Dz of the design (the module's docstring)"""
    A, B2 = plant(p)
    B1 = B2 * (p["L_mprad"] * p["Fs_N"])
    C = np.diag(wts["Cz_diag"])
    R = np.array([[1.0 / wts["u_norm_Nm"] ** 2]])
    return A, B1, B2, C, R


def gain(p, wts):
    """The gamma-iteration and the state feedback, unchecked: (K, gamma_min, gamma), or DesignError."""
    A, B1, B2, C, R = problem(p, wts)
    lo, hi = 1e-9, 1e9
    if riccati(A, B1, B2, C, R, hi) is None:
        raise DesignError("the weights admit no stabilising design (no gamma up to %g)" % hi)
    for _ in range(200):  # gamma-iteration: bisection on log(gamma)
        g = np.sqrt(lo * hi)
        if riccati(A, B1, B2, C, R, g) is None:
            lo = g
        else:
            hi = g
        if hi / lo < 1.0 + 1e-9:
            break
    gamma_min = hi
    gamma = wts["gamma_margin"] * gamma_min
    X = riccati(A, B1, B2, C, R, gamma)
    if X is None:
        raise DesignError("no stabilising solution at gamma = %g * gamma_min" % wts["gamma_margin"])
    K = (-np.linalg.solve(R, B2.T @ X)).ravel()
    return K, gamma_min, gamma


def design(p, wts):
    """The design and its checks (the closed-loop norm, the sampled loop at each period), or DesignError."""
    K, gamma_min, gamma = gain(p, wts)
    A, B1, B2, C, R = problem(p, wts)
    Acl = A + B2 @ K[None, :]
    Ccl = np.vstack([C, (np.sqrt(R) @ K[None, :])])
    norm = hinf_norm(Acl, B1, Ccl, np.zeros((4, 1)))
    if not np.all(np.linalg.eigvals(Acl).real < 0):
        raise DesignError("the continuous closed loop is unstable")
    if not norm <= gamma * (1 + 1e-6):
        raise DesignError("closed-loop norm %g exceeds gamma %g" % (norm, gamma))
    checks = []
    for dt in wts["check_dt_s"]:
        Phi, Gw, Ku = sampled_loop(p, K, dt)
        rho = np.max(np.abs(np.linalg.eigvals(Phi)))
        if not rho < 1.0:
            raise DesignError("the sampled loop is unstable at %g s (spectral radius %.6f): "
                              "lower the weights or the period (synth_hinf.py --suggest)" % (dt, rho))
        Cd = np.vstack([np.hstack([C, np.zeros((3, 1))]), np.sqrt(R) @ Ku])
        th = np.linspace(1e-4, np.pi, 4000)
        dnorm = max(np.linalg.norm(Cd @ np.linalg.solve(np.exp(1j * t) * np.eye(4) - Phi, Gw), 2) for t in th)
        checks.append((dt, rho, dnorm))
    return dict(K=K, gamma_min=gamma_min, gamma=gamma, norm=norm,
                poles=np.linalg.eigvals(Acl), checks=checks)


def render(d, wts):
    poles = ", ".join("%.2f%+.2fj" % (z.real / (2 * np.pi), z.imag / (2 * np.pi)) for z in sorted(d["poles"], key=lambda z: (z.real, z.imag)))
    lines = [
        "/* generated by firmware/design/synth_hinf.py from %s" % machine.c_comment_text(d["machine_file"]),
        " * (its control section) -- do not edit; regenerate with `make regen` */",
        "/* SPDX-License-Identifier: Apache-2.0 */",
        "/* H-infinity state feedback with integral action (thesis eq. 7), u = K x,",
        " * x = [e_theta (rad), e_omega (rad/s), eps (rad s)], torque in N m.",
        " * weights Cz = diag(%s), Dz = 1/%s N m" % (", ".join(repr(c) for c in wts["Cz_diag"]), repr(wts["u_norm_Nm"])),
        " * gamma_min = %.6g, gamma = %.6g, closed-loop norm = %.6g" % (d["gamma_min"], d["gamma"], d["norm"]),
        " * continuous closed-loop poles (Hz): %s" % poles,
    ]
    for dt, rho, dn in d["checks"]:
        lines.append(" * sampled at %g ms: spectral radius %.6f, norm %.6g" % (dt * 1e3, rho, dn))
    lines += [" */", "#ifndef BR_GEN_HINF_GAINS_H", "#define BR_GEN_HINF_GAINS_H", "",
              "/* initializer for br_ctrl_cfg_t.K */",
              "#define BR_HINF_K { %s, %s, %s }" % tuple(machine.c_float(k) for k in d["K"]),
              "", "#endif", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--machine", default=machine.REFERENCE_MACHINE, help="machine description (JSON)")
    ap.add_argument("--out", default=os.path.join(machine.GEN_DIR, "bristle_gen", "ctrl", "br_hinf_gains.h"),
                    help="the gains header to write (default: firmware/gen/bristle_gen/ctrl/br_hinf_gains.h)")
    ap.add_argument("--report", action="store_true",
                    help="also print the design report: gains, gamma, poles, gain and phase margins and the "
                         "closed-loop bandwidth, continuous and sampled at the checked periods")
    ap.add_argument("--suggest", action="store_true",
                    help="write no header: print the weights from the machine's periods, inertia, torque limit, "
                         "encoder, stiction and following-error limit (docs/modules/hinf.md, \"Weights from the "
                         "machine\") and their design")
    a = ap.parse_args()
    m = machine.load_or_exit(a.machine)
    if a.suggest:
        import hinf_weights
        hinf, info = hinf_weights.suggest(m)
        m = hinf_weights.with_hinf(m, hinf)
        sys.stdout.write(json.dumps({"control": {"hinf": hinf}}, indent=1) + "\n")
        sys.stdout.write("w0 = %.4g Hz (bound by the %s); one encoder count of velocity asks %.3g of the torque "
                         "limit; a stiction step moves the axis %.4g mm (following-error limit %.4g mm)\n" % (
                             info["omega0_rad_s"] / (2.0 * np.pi), info["bound"], info["count_torque_share"],
                             info["friction_step_m"] * 1e3, info["following_m"] * 1e3))
        short = hinf_weights.friction_shortfall(info)
        if short is not None:
            sys.stdout.write("warning: %s\n" % short)
    wts = weights(m)
    try:
        d = design(machine.params(m), wts)
    except DesignError as e:
        sys.stderr.write("%s: field control.hinf: %s\n" % (m["file"], e))
        sys.exit(1)
    d["machine_file"] = m["file"]
    if not a.suggest:
        machine.write_atomic(a.out, render(d, wts))  # a failed run leaves the old header
    sys.stdout.write("K = %s\ngamma_min = %.6g, gamma = %.6g, closed-loop norm = %.6g\n" % (
        d["K"], d["gamma_min"], d["gamma"], d["norm"]))
    if a.report:
        sys.stdout.write(report(machine.params(m), wts, d))


def report(p, wts, d):
    """The design report (--report): the design's figures, then its margins and bandwidth."""
    A, B2 = plant(p)
    lines = ["design report: %s" % d["machine_file"],
             "  K = [%.6g, %.6g, %.6g] (N m/rad, N m s/rad, N m/(rad s))" % tuple(d["K"]),
             "  gamma_min = %.6g, gamma = %.6g, closed-loop H-inf norm (w -> z) = %.6g"
             % (d["gamma_min"], d["gamma"], d["norm"]),
             "  continuous closed-loop poles (Hz): " + ", ".join(
                 "%.3f%+.3fj" % (z.real / (2 * np.pi), z.imag / (2 * np.pi))
                 for z in sorted(d["poles"], key=lambda z: (z.real, z.imag)))]
    for dt, rho, dn in d["checks"]:
        lines.append("  sampled at %g ms: spectral radius %.6f, norm %.6g" % (dt * 1e3, rho, dn))
    lines += ["  " + x for x in loop_analysis.render(loop_analysis.analyse(A, B2, d["K"], wts["check_dt_s"]))]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
