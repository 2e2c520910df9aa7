# SPDX-License-Identifier: Apache-2.0
"""make bench, numpy side: the particle filter's shared external force
(cfg.load, firmware/pf/br_pf_load.c; docs/modules/pf.md, "External force")
for pf_numpy.py, in float32 in the order of the C code, so that the numpy
PF with it stays the C one bit for bit.

One load force F_d beside the particles; the common error e = [theta,
omega, F_d] of the cloud's mean has the covariance P (upper triangle P00
P01 P02 P11 P12 P22):
  tick      P <- Phi P Phi^T + diag(0, 0, q), Phi = [1 h -g; 0 1 -a; 0 0 1],
            g = L h^2 / (2 J_eff), a = 2 g / h; F_d at the period's start kept
  torque    the particles predicted with u - L F_d
  update    on the cloud's mean innovation nu = -d (d = mean theta_j - y,
            S = P00 + var theta_j + R + rpc^2/12): a gated step re-acquired as
            a load change (P inflated by df^2 b b^T, b = [-g, -2 g / h, 1]),
            undone the next step when that one is gated too (a spike or a
            slip, the smaller |mean innovation| first); the cloud moved by the
            correction's theta and omega shares and weighed again
  comp      F_hat + F_d through the notch at the PF's Nyquist frequency
The bench's recordings have no predict-only period (br_pf_predict), so the
periods since the last measurement k are 1 throughout."""
import numpy as np

F = np.float32


def clampf(v, lo, hi):
    """br_clampf: fminf(fmaxf(v, lo), hi) (a NaN gives lo)"""
    return F(np.fmin(np.fmax(v, lo), hi))


class LoadNumpy:
    def __init__(self, q, max_N, h, L, inv_jeff, notch_r, seqsum, undo_gate2):
        self.seqsum = seqsum  # pf_numpy's float32 sum, left to right like the C loops
        self.on = bool(max_N > F(0.0))  # br_pf_load_on
        self.q, self.max_N, self.h, self.L, self.r = q, max_N, h, L, notch_r
        self.undo_gate2 = undo_gate2
        # g = L h^2 / (2 J_eff): theta's change over one period under one newton on the load side
        self.g = ((F(0.5) * L) * h) * h * inv_jeff
        self.N = self.prev = self.comp_N = F(0.0)
        self.P = np.zeros(6, dtype=F)
        self.alt = False
        self.alt_e = np.zeros(3, dtype=F)
        self.alt_nu1 = F(0.0)
        self.alt_P = np.zeros(6, dtype=F)
        self.n_acq = self.n_undo = 0
        if self.on:
            self._reset()

    def _reset(self):
        self.P = np.zeros(6, dtype=F)
        self.P[5] = self.max_N * self.max_N

    def _cov_predict(self, P):
        h, g = self.h, self.g
        a = (F(2.0) * g) / h
        p00, p01, p02, p11, p12, p22 = (F(v) for v in P)
        r00 = (p00 + h * p01) - g * p02
        r01 = (p01 + h * p11) - g * p12
        r02 = (p02 + h * p12) - g * p22
        r11 = p11 - a * p12
        r12 = p12 - a * p22
        return np.array([(r00 + h * r01) - g * r02, r01 - a * r02, r02, r11 - a * r12, r12, p22 + self.q], dtype=F)

    def tick(self):
        if not self.on:
            return
        self.P = self._cov_predict(self.P)
        self.prev = self.N
        if not np.all(np.isfinite(self.P)):
            self._reset()

    def torque(self, u):
        return u - self.L * self.N if self.on else u

    def _move(self, pf, y_rel, dth, dom, xp, fnl, valid):
        """move_cloud: theta by dth, omega by dom, f_nl and the log-weights made again;
        (lmax, xp, fnl, l, valid, sums)"""
        th = xp[0] + dth
        om = xp[1] + dom
        with np.errstate(invalid="ignore", over="ignore"):
            f2 = pf._fnl(om, xp[2], xp[3])
            bad = valid & ~(np.isfinite(th) & np.isfinite(f2))
        ok = valid & ~bad
        xp = xp.copy()
        xp[0] = np.where(ok, th, xp[0])
        xp[1] = np.where(ok, om, xp[1])
        fnl = np.where(ok, f2, np.where(bad, F(0.0), fnl))
        e = th - y_rel
        l = np.where(ok, -(e * e) * pf.inv_2r, F(-np.inf))
        lmax = F(l.max()) if ok.any() else F(-np.inf)
        d = np.where(ok, e, F(0.0))
        return lmax, xp, fnl, l, ok, [self.seqsum(d), self.seqsum(d * d)]

    def _probe(self, pf, y_rel, dth, xp, valid):
        """probe_lmax: the best log-weight of the valid particles with theta moved by dth"""
        if not valid.any():
            return F(-np.inf)
        emin = F(np.min(np.abs((xp[0][valid] + dth) - y_rel)))
        return -(emin * emin) * pf.inv_2r

    def _undo(self, pf, y_rel, lmax, sums, n_valid, state):
        h, g = self.h, self.g
        a = (F(2.0) * g) / h
        e = self.alt_e
        s_th = (e[0] + h * e[1]) - g * e[2]
        s_om = e[1] - a * e[2]
        d = sums[0] / F(n_valid)
        dth_spike = -s_th
        dth_slip = -s_th + self.alt_nu1
        slip_first = abs(d + dth_slip) < abs(d + dth_spike)
        order = (dth_slip, dth_spike) if slip_first else (dth_spike, dth_slip)
        xp, fnl, l, valid = state
        for dth in order:
            if not (self._probe(pf, y_rel, dth, xp, valid) >= self.undo_gate2 * pf.outlier_l):
                continue
            P = self._cov_predict(self.alt_P)
            if not np.all(np.isfinite(P)):
                return lmax, state, sums
            self.P = P
            self.N = clampf(self.N - e[2], -self.max_N, self.max_N)
            self.prev = clampf(self.prev - e[2], -self.max_N, self.max_N)
            self.n_undo += 1
            lmax, xp, fnl, l, valid, sums = self._move(pf, y_rel, dth, -s_om, xp, fnl, valid)
            return lmax, (xp, fnl, l, valid), sums
        return lmax, state, sums

    def update(self, pf, y_rel, lmax, sums, n_valid, xp, fnl, l, valid):
        """br_pf_load_update; sums (a list) made again in place. Returns (lmax, xp, fnl, l, valid)."""
        state = (xp, fnl, l, valid)
        if self.alt and not (lmax >= pf.outlier_l):
            lmax, state, new = self._undo(pf, y_rel, lmax, sums, n_valid, state)
            sums[:] = new
        self.alt = False
        xp, fnl, l, valid = state
        max_N, P = self.max_N, self.P
        n = F(n_valid)
        d = sums[0] / n
        v = sums[1] / n - d * d
        s0 = (v if v > F(0.0) else F(0.0)) + pf.r_gate
        acq = False
        if not (lmax >= pf.outlier_l):
            k = F(1.0)
            df_raw = d / ((self.g * k) * k)
            if not (abs(df_raw) <= F(2.0) * max_N):
                return lmax, xp, fnl, l, valid
            P_pred = P.copy()
            b = (((-self.g) * k) * k, ((F(-2.0) * self.g) * k) / self.h, F(1.0))
            dv = df_raw * df_raw
            P = P.copy()
            P[0] += (dv * b[0]) * b[0]
            P[1] += (dv * b[0]) * b[1]
            P[2] += (dv * b[0]) * b[2]
            P[3] += (dv * b[1]) * b[1]
            P[4] += (dv * b[1]) * b[2]
            P[5] += dv
            self.P = P
            self.n_acq += 1
            acq = True
        s = P[0] + s0
        k0, k1, k2 = P[0] / s, P[1] / s, P[2] / s
        nu = -d
        dF = k2 * nu
        p00, p01, p02, p11, p12, p22 = P
        new_P = np.array([p00 - k0 * p00, p01 - k0 * p01, p02 - k0 * p02,
                          p11 - k1 * p01, p12 - k1 * p02, p22 - k2 * p02], dtype=F)
        if not (np.isfinite(dF) and np.isfinite(k0 * nu) and np.isfinite(k1 * nu) and np.all(np.isfinite(new_P))):
            return lmax, xp, fnl, l, valid
        self.P = new_P
        f = clampf(self.N + dF, -max_N, max_N)
        if acq:
            self.alt = True
            self.alt_e = np.array([k0 * nu, k1 * nu, f - self.N], dtype=F)
            self.alt_nu1 = nu
            self.alt_P = P_pred
        self.N = f
        lmax, xp, fnl, l, valid, new = self._move(pf, y_rel, k0 * nu, k1 * nu, xp, fnl, valid)
        sums[:] = new
        return lmax, xp, fnl, l, valid

    def comp(self, F_N):
        """br_pf_load_comp_N: (L1) F_d through the notch, (L2) added to the mean f_nl"""
        if not self.on:
            return F_N
        r = self.r
        c = F(0.5) * (F(1.0) + r)
        y = c * (self.N + self.prev) - r * self.comp_N
        self.comp_N = clampf(y, -self.max_N, self.max_N)
        return clampf(F_N + self.comp_N, -self.max_N, self.max_N)

