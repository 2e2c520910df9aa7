# SPDX-License-Identifier: Apache-2.0
"""Unscented Kalman filter for the friction of one axis (thesis sections 2.3, 4),
float64 golden reference, written from firmware/include/bristle/br_ukf.h and
docs/modules/ukf.md (not from br_ukf.c).

State x = [theta, omega, z, g_p] of the eq. 6 model (golden/ref/model.py),
n = 4, mean x and covariance P; theta relative to an integer origin.
Scaled unscented transform:
    lambda = alpha^2 (n + kappa) - n,  c = sqrt(n + lambda)
    X_0 = x, X_i = x + c S_i, X_{i+n} = x - c S_i   (P = S S^T, S lower Cholesky)
    Wm_0 = lambda / (n + lambda), Wc_0 = Wm_0 + 1 - alpha^2 + beta,
    Wm_i = Wc_i = 1 / (2 (n + lambda));  g_p of every sigma point clamped.

Priming (first measurement): origin = counts, x = [frac rpc, 0, 0, gp0],
P = diag(p0_var), no predict.
One step with y_k = (counts, frac) and u_{k-1}:
 1. sigma points of (x, P)
 2. Y_j = f_d(X_j, u); x- = sum Wm_j Y_j; P- = sum Wc_j (Y_j - x-)(Y_j - x-)^T + Q
    (the standard form here; the C evaluates the same sum expanded about Y_0)
 3. theta- -= wrapdiff(counts, origin) rpc; nu = frac rpc - theta-; S = P-_00 + R
 4. nu^2 > outlier_sigma^2 (S + rpc^2/12) (with the encoder's quantisation):
    outlier. (x, P) = the prediction in the old origin's frame, no update; from
    the reanchor_after-th consecutive outlier on: re-anchored: origin = counts, x = [frac rpc, (wrapdiff(counts,
    prev_counts) + frac - frac_prev) rpc / dt, z, g_p], P = diag(p0_var).
 5. else the linear Kalman update (h(x) = theta): K = P-[:, 0] / S,
    x = x- + K nu, P = (I - K H) P- (I - K H)^T + K R K^T, symmetrised;
    g_p of x clamped; origin = counts.
 6. F_hat = sum Wm_j f_nl(X_j) over the sigma points of the new (x, P).
A Cholesky failure (pivot <= 0 or non-finite) resets P to diag(p0_var), the
mean kept, and the step reports BR_E_NUMERIC (it otherwise completes); a
non-finite prediction, update or F_hat: BR_E_NUMERIC, the previous state kept.
A non-finite u or a frac outside [0, 1]: BR_E_INPUT, nothing changes.
"""
import math
from dataclasses import dataclass

import numpy as np

from . import model as rmodel

BR_OK = 0
BR_E_INPUT = -3
BR_E_NUMERIC = -4
BR_W_OUTLIER = 1  # a warning (positive): the step predicted only

NX = 4
NSIG = 2 * NX + 1


@dataclass(frozen=True)
class UkfCfg:
    model: rmodel.ModelParams
    dt: float
    q_var: tuple
    r_var: float
    gp0: float
    p0_var: tuple
    gp_min: float
    gp_max: float
    outlier_sigma: float
    reanchor_after: int
    rad_per_count: float
    alpha: float
    beta: float
    kappa: float


def wrapdiff(now, prev):
    d = (int(now) - int(prev)) & 0xFFFFFFFF
    return d - (1 << 32) if d >= (1 << 31) else d


def chol(A):
    """Lower Cholesky factor of a 4 x 4 matrix (element-wise loops); None on a
    pivot <= 0 or a non-finite value."""
    L = [[0.0] * NX for _ in range(NX)]
    for j in range(NX):
        s = A[j][j] - sum(L[j][k] * L[j][k] for k in range(j))
        if not (s > 0.0) or not math.isfinite(s):
            return None
        L[j][j] = math.sqrt(s)
        for i in range(j + 1, NX):
            L[i][j] = (A[i][j] - sum(L[i][k] * L[j][k] for k in range(j))) / L[j][j]
    return L


class Ukf:
    def __init__(self, cfg):
        self.cfg = cfg
        n = NX
        lam = cfg.alpha ** 2 * (n + cfg.kappa) - n
        self.c = math.sqrt(n + lam)
        self.wm = [lam / (n + lam)] + [1.0 / (2.0 * (n + lam))] * (2 * n)
        self.wc = [lam / (n + lam) + 1.0 - cfg.alpha ** 2 + cfg.beta] + self.wm[1:]
        self.x = [0.0, 0.0, 0.0, cfg.gp0]
        self.P = self._P0()
        self.origin = 0
        self.prev_counts = 0
        self.prev_frac = 0.0
        self.n_outliers = 0
        self.n_recover = 0
        self.primed = False
        self.F_hat = 0.0
        self.nu = 0.0
        self.S = 0.0
        self.Pm_diag = list(cfg.p0_var)   # diag of the last prediction's P- (P0 when priming)
        self.reanchored = False

    def _P0(self):
        return [[self.cfg.p0_var[i] if i == j else 0.0 for j in range(NX)] for i in range(NX)]

    def _clamp_gp(self, v):
        return min(max(v, self.cfg.gp_min), self.cfg.gp_max)

    def _sigma(self, x, P):
        """Sigma points of (x, P); (points, P used, Cholesky ok)."""
        L = chol(P)
        ok = L is not None
        if not ok:
            P = self._P0()
            L = chol(P)
        X = [list(x)]
        for sgn in (1.0, -1.0):
            for i in range(NX):
                X.append([x[r] + sgn * self.c * L[r][i] for r in range(NX)])
        for Xj in X:
            Xj[3] = self._clamp_gp(Xj[3])
        return X, P, ok

    def _fhat(self, X):
        return sum(w * rmodel.fnl(self.cfg.model, np.array(Xj)) for w, Xj in zip(self.wm, X))

    def step(self, counts, frac, u):
        c = self.cfg
        if not math.isfinite(u) or not math.isfinite(frac) or not 0.0 <= frac <= 1.0:
            return BR_E_INPUT
        rpc = c.rad_per_count
        self.reanchored = False
        if not self.primed:
            self.origin = self.prev_counts = int(counts)
            self.prev_frac = frac
            self.x = [frac * rpc, 0.0, 0.0, c.gp0]
            self.P = self._P0()
            X, self.P, _ = self._sigma(self.x, self.P)
            self.F_hat = self._fhat(X)
            self.nu = self.S = 0.0
            self.Pm_diag = list(c.p0_var)
            self.primed = True
            return BR_OK
        status = BR_OK
        # 1. sigma points
        X, P, ok = self._sigma(self.x, self.P)
        if not ok:
            status = BR_E_NUMERIC
            self.n_recover += 1
        # 2. predict
        Y = []
        for Xj in X:
            st, y1, _ = rmodel.step(c.model, np.array(Xj), u, c.dt)
            if st != rmodel.BR_OK:
                return BR_E_NUMERIC
            Y.append([float(v) for v in y1])
        xm = [sum(self.wm[j] * Y[j][r] for j in range(NSIG)) for r in range(NX)]
        Pm = [[sum(self.wc[j] * (Y[j][r] - xm[r]) * (Y[j][s] - xm[s]) for j in range(NSIG))
               + (c.q_var[r] if r == s else 0.0) for s in range(NX)] for r in range(NX)]
        if not all(math.isfinite(v) for v in xm) or not all(math.isfinite(v) for row in Pm for v in row):
            return BR_E_NUMERIC
        # 3. origin and innovation
        delta = wrapdiff(counts, self.origin)
        th_new = xm[0] - delta * rpc
        nu = frac * rpc - th_new
        S = Pm[0][0] + c.r_var
        # the gate: the innovation's variance with the encoder's quantisation rpc^2/12
        if nu * nu > c.outlier_sigma ** 2 * (S + rpc * rpc / 12.0):
            # 4. outlier: the prediction, old frame; re-anchoring after a run
            status_o = BR_W_OUTLIER
            x_new, P_new, origin_new = xm, Pm, self.origin
            n_out = self.n_outliers + 1
            if n_out >= c.reanchor_after:
                w_meas = (wrapdiff(counts, self.prev_counts) + frac - self.prev_frac) * rpc / c.dt
                x_new = [frac * rpc, w_meas, xm[2], xm[3]]
                P_new = self._P0()
                origin_new = int(counts)
                self.reanchored = True
        else:
            # 5. update
            status_o = BR_OK
            n_out = 0
            xm = [th_new] + xm[1:]
            K = [Pm[r][0] / S for r in range(NX)]
            x_new = [xm[r] + K[r] * nu for r in range(NX)]
            x_new[3] = self._clamp_gp(x_new[3])
            # A = I - K H (H = e_0^T): A[r][s] = delta_rs - K[r] (s == 0)
            A = [[(1.0 if r == s else 0.0) - (K[r] if s == 0 else 0.0) for s in range(NX)] for r in range(NX)]
            AP = [[sum(A[r][t] * Pm[t][s] for t in range(NX)) for s in range(NX)] for r in range(NX)]
            Pj = [[sum(AP[r][t] * A[s][t] for t in range(NX)) + K[r] * c.r_var * K[s]
                   for s in range(NX)] for r in range(NX)]
            P_new = [[0.5 * (Pj[r][s] + Pj[s][r]) for s in range(NX)] for r in range(NX)]
            origin_new = int(counts)
        if not all(math.isfinite(v) for v in x_new) or not all(math.isfinite(v) for row in P_new for v in row):
            return BR_E_NUMERIC
        # 6. estimate over the sigma points of the new (x, P)
        X, P_new, ok = self._sigma(x_new, P_new)
        if not ok:
            status = BR_E_NUMERIC
            self.n_recover += 1
        F = self._fhat(X)
        if not math.isfinite(F):
            return BR_E_NUMERIC
        self.x, self.P, self.origin, self.F_hat = x_new, P_new, origin_new, F
        self.nu, self.S = nu, S
        self.Pm_diag = [Pm[i][i] for i in range(NX)]
        self.prev_counts, self.prev_frac = int(counts), frac
        self.n_outliers = n_out
        return status if status != BR_OK else status_o
