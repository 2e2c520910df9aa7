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
 4. |nu| > outlier_sigma sqrt(S + rpc^2/12) + d (with the encoder's quantisation,
    d the gate's transient term; eq. G1):
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

External force (cfg.load, docs/modules/ukf.md "External force"; None: the
four states above): x = [theta, omega, z, g_p, F_d], n = 5, F_d in N on the
load side, against +x as friction is:
    J_eff omega' = u - L (sigma2 L omega + f_nl(x) + F_d)
      (step 2: each sigma point stepped by the eq. 6 model with torque u - L F_d_j),
    F_d' = 0, Q_dd = load.q_N2, P0_dd = load.p0_N2, F_d = 0 when priming,
    |F_d| <= load.max_N: the mean clamped after each update;
    F_hat = sum Wm_j (f_nl(X_j) + F_d_j), clamped to +-load.max_N.
Re-acquisition: a gated innovation nu (step 4) over k = 1 period since the
last measurement is explained by a force change dF = nu / (g k^2),
g = L dt^2 / (2 J_eff) (theta's response to a constant force over one
period from rest: (L F / J_eff) dt^2 / 2). If |dF| <= 2 load.max_N, the last
posterior's P_dd is increased by dF^2, step 2 is repeated from it and the gate
applied to the new innovation; passing, it is an ordinary update (BR_OK,
counted in n_load_acq) of that prediction. Failing, the step is the outlier
of the first prediction (P_dd not inflated).
Undo (docs/modules/ukf.md, "A glitch is not a load"): a step that
re-acquired holds its alternative A = (the first prediction's mean and
covariance, its elements clipped as an outlier's, the step's origin, the
gated innovation nu_1). At the next step only (a predict-only period or any
error drops it), if the innovation of the ordinary prediction is gated, step
2 is repeated from A (as if the last step had been an outlier) and gated:
as it is (a spike) and with theta- + nu_1 (a slip: the counter stays off by
nu_1). The passing one, the smaller |nu| when both pass (one S for both), is
the step's prediction (an ordinary update, BR_OK, counted in n_load_undo;
origin = counts as always). Neither:
the ordinary prediction stands and the re-acquisition rule follows.

Maxwell-slip elements (cfg.mslip, docs/modules/ukf.md "Maxwell-slip
elements"; None: LuGre): the friction is that of element deflections e
(golden/ref/mslip.py, clamp form) carried beside x, and z is the elements'
common error (an error state, its mean 0 between steps):
    step 2: each sigma point stepped by the Maxwell-slip model
      (mslip.model_step) from the elements e + X_j[z], giving Y_j and E_j;
      e- = sum Wm_j E_j; Y_j's z = X_j's;
    step 5: e- += x+[z], x+[z] = 0; a re-anchoring moves e- by L nu (the
      position's jump to the measurement);
    step 6: e = clip(e-, -Delta(g_p), Delta(g_p)) at the new mean's g_p,
      F_hat = sum k_i e_i (+ F_d as above);
    priming: e = 0.
"""
import math
from dataclasses import dataclass

import numpy as np

from . import model as rmodel
from . import mslip as rmslip

BR_OK = 0
BR_E_INPUT = -3
BR_E_NUMERIC = -4
BR_W_OUTLIER = 1  # a warning (positive): the step predicted only

NX = 4          # the thesis's states


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
    load: object = None   # LoadCfg: the external-force state F_d; None: off (n = 4)
    mslip: object = None  # mslip.MslipParams (sigma2 0): the Maxwell-slip elements; None: LuGre
    ms_passes: int = 2    # the Maxwell-slip step's fixed-point passes (BR_MODEL_MS_PASSES)
    outlier_transient: float = 0.0  # the gate's transient term d, rad (eq. G1); 0: the thesis gate


@dataclass(frozen=True)
class LoadCfg:
    q_N2: float    # random walk of F_d per step, N^2
    p0_N2: float   # P0 of F_d, N^2
    max_N: float   # |F_d| and |F_hat| bound, N; re-acquisition up to |dF| <= 2 max_N


def wrapdiff(now, prev):
    d = (int(now) - int(prev)) & 0xFFFFFFFF
    return d - (1 << 32) if d >= (1 << 31) else d


def chol(A):
    """Lower Cholesky factor of an n x n matrix (element-wise loops); None on a
    pivot <= 0 or a non-finite value."""
    n = len(A)
    L = [[0.0] * n for _ in range(n)]
    for j in range(n):
        s = A[j][j] - sum(L[j][k] * L[j][k] for k in range(j))
        if not (s > 0.0) or not math.isfinite(s):
            return None
        L[j][j] = math.sqrt(s)
        for i in range(j + 1, n):
            L[i][j] = (A[i][j] - sum(L[i][k] * L[j][k] for k in range(j))) / L[j][j]
    return L


class Ukf:
    def __init__(self, cfg):
        self.cfg = cfg
        self.n = n = NX if cfg.load is None else NX + 1
        self.nsig = 2 * n + 1
        lam = cfg.alpha ** 2 * (n + cfg.kappa) - n
        self.c = math.sqrt(n + lam)
        self.wm = [lam / (n + lam)] + [1.0 / (2.0 * (n + lam))] * (2 * n)
        self.wc = [lam / (n + lam) + 1.0 - cfg.alpha ** 2 + cfg.beta] + self.wm[1:]
        self.p0 = list(cfg.p0_var) + ([] if cfg.load is None else [cfg.load.p0_N2])
        self.q = list(cfg.q_var) + ([] if cfg.load is None else [cfg.load.q_N2])
        m = cfg.model
        # theta's response to a constant force over one period: L dt^2 / (2 J_eff)
        self.g_load = m.L * cfg.dt * cfg.dt / (2.0 * (m.J + m.L * m.L * m.M))
        self.x = [0.0, 0.0, 0.0, cfg.gp0] + [0.0] * (n - NX)
        self.P = self._P0()
        self.origin = 0
        self.prev_counts = 0
        self.prev_frac = 0.0
        self.n_outliers = 0
        self.n_recover = 0
        self.n_load_acq = 0
        self.n_load_undo = 0
        self.alt = None                # the last re-acquisition's alternative (dict) or None
        self.load_undo = False         # this step undid the last one's re-acquisition
        self.primed = False
        self.F_hat = 0.0
        self.nu = 0.0
        self.S = 0.0
        self.Pm_diag = list(self.p0)   # diag of the last prediction's P- (P0 when priming)
        self.reanchored = False
        self.load_acq = False          # this step re-acquired a load
        self.el = np.zeros(0 if cfg.mslip is None else len(cfg.mslip.k))   # the elements e

    def _P0(self):
        return [[self.p0[i] if i == j else 0.0 for j in range(self.n)] for i in range(self.n)]

    def _clamp_gp(self, v):
        return min(max(v, self.cfg.gp_min), self.cfg.gp_max)

    def _clamp_mean(self, x):
        """g_p of the mean in [gp_min, gp_max]; F_d in [-max_N, max_N]."""
        x[3] = self._clamp_gp(x[3])
        if self.cfg.load is not None:
            x[NX] = min(max(x[NX], -self.cfg.load.max_N), self.cfg.load.max_N)

    def _sigma(self, x, P):
        """Sigma points of (x, P); (points, P used, Cholesky ok)."""
        n = self.n
        L = chol(P)
        ok = L is not None
        if not ok:
            P = self._P0()
            L = chol(P)
        X = [list(x)]
        for sgn in (1.0, -1.0):
            for i in range(n):
                X.append([x[r] + sgn * self.c * L[r][i] for r in range(n)])
        for Xj in X:
            Xj[3] = self._clamp_gp(Xj[3])
        return X, P, ok

    def _fhat(self, X, el):
        if self.cfg.mslip is None:
            F = sum(w * rmodel.fnl(self.cfg.model, np.array(Xj[:NX])) for w, Xj in zip(self.wm, X))
        else:
            F = rmslip.force(self.cfg.mslip, el, 0.0)    # sum k_i e_i
        if self.cfg.load is None:
            return F
        # friction + the external force's unscented mean, within the actuator's force
        F = F + sum(w * Xj[NX] for w, Xj in zip(self.wm, X))
        return min(max(F, -self.cfg.load.max_N), self.cfg.load.max_N)

    def _predict(self, x, P, u, el=None):
        """Steps 1-2 from (x, P) and the elements el (None: self.el): (xm, Pm,
        Cholesky ok, e-), or None when a model step fails or the prediction is
        not finite (e-: the elements' prediction, empty for LuGre)."""
        c, n = self.cfg, self.n
        el = self.el if el is None else el
        X, P, ok = self._sigma(x, P)
        Y, E = [], []
        for Xj in X:
            # the torque on the axis: u, less L F_d with the external force (eq. 1 with the load)
            uj = u if c.load is None else u - c.model.L * Xj[NX]
            if c.mslip is None:
                st, y1, _ = rmodel.step(c.model, np.array(Xj[:NX]), uj, c.dt)
                if st != rmodel.BR_OK:
                    return None
            else:
                # the Maxwell-slip step from the elements offset by the point's z
                th1, om1, e1 = rmslip.model_step(c.model, c.mslip, Xj[0], Xj[1], Xj[3], el + Xj[2], uj,
                                                 c.dt, c.ms_passes)
                y1 = [th1, om1, Xj[2], Xj[3]]
                E.append(e1)
            # F_d' = 0: carried over (its random walk is Q_dd)
            Y.append([float(v) for v in y1] + Xj[NX:])
        em = sum(self.wm[j] * E[j] for j in range(self.nsig)) if E else np.zeros(0)
        xm = [sum(self.wm[j] * Y[j][r] for j in range(self.nsig)) for r in range(n)]
        Pm = [[sum(self.wc[j] * (Y[j][r] - xm[r]) * (Y[j][s] - xm[s]) for j in range(self.nsig))
               + (self.q[r] if r == s else 0.0) for s in range(n)] for r in range(n)]
        if not all(math.isfinite(v) for v in xm) or not all(math.isfinite(v) for row in Pm for v in row) \
                or not np.all(np.isfinite(em)):
            return None
        return xm, Pm, ok, em

    def _innovate(self, xm, Pm, counts, frac, origin=None):
        """Step 3 and the gate, theta- relative to origin (None: self.origin):
        (theta- in the new origin's frame, nu, S, passes)."""
        c = self.cfg
        rpc = c.rad_per_count
        origin = self.origin if origin is None else origin
        th_new = xm[0] - wrapdiff(counts, origin) * rpc
        nu = frac * rpc - th_new
        S = Pm[0][0] + c.r_var
        # the gate: the innovation's variance with the encoder's quantisation rpc^2/12
        # eq. G1: beyond g sqrt(S + rpc^2/12) + d
        gate = c.outlier_sigma * math.sqrt(S + rpc * rpc / 12.0) + c.outlier_transient
        return th_new, nu, S, not (abs(nu) > gate)

    def _reacquire(self, nu, u, counts, frac):
        """Load re-acquisition of a gated nu: the prediction from the posterior
        with P_dd + dF^2 and its innovation, or None when no force change
        within 2 max_N explains nu or the new innovation is gated too."""
        c = self.cfg
        if c.load is None:
            return None
        dF = nu / (self.g_load * 1.0 * 1.0)    # k = 1 period since the last measurement
        if not abs(dF) <= 2.0 * c.load.max_N:
            return None
        P = [list(row) for row in self.P]
        P[NX][NX] = P[NX][NX] + dF * dF
        pred = self._predict(self.x, P, u)
        if pred is None:
            return None
        inn = self._innovate(pred[0], pred[1], counts, frac)
        return (pred, inn, P) if inn[3] else None

    def _bounded(self, em, gp):
        """The elements e- clipped to their slip bounds at g_p (LuGre: as they are)."""
        if self.cfg.mslip is None:
            return em
        return np.clip(em, -rmslip.bounds(self.cfg.mslip, gp), rmslip.bounds(self.cfg.mslip, gp))

    def _undo(self, alt, u, counts, frac):
        """The last step's re-acquisition undone: the prediction from its
        alternative alt and the innovation of a spike (as it is) or of a slip
        (theta- + nu_1), the one that passes, the smaller |nu| when both do;
        None when neither does."""
        pred = self._predict(alt["x"], alt["P"], u, alt["el"])
        if pred is None:
            return None
        xa, Pa, ok, em = pred
        cands = []
        for shift in (0.0, alt["nu"]):
            xs = [xa[0] + shift] + xa[1:]
            inn = self._innovate(xs, Pa, counts, frac, alt["origin"])
            if inn[3]:
                cands.append((abs(inn[1]), (xs, Pa, ok, em), inn))
        if not cands:
            return None
        # the spike on a tie (min keeps the first of equal keys)
        _, pred, inn = min(cands, key=lambda cand: cand[0])
        return pred, inn

    def step(self, counts, frac, u):
        c, n = self.cfg, self.n
        if not math.isfinite(u) or not math.isfinite(frac) or not 0.0 <= frac <= 1.0:
            return BR_E_INPUT
        rpc = c.rad_per_count
        self.reanchored = False
        self.load_acq = False
        self.load_undo = False
        if not self.primed:
            self.origin = self.prev_counts = int(counts)
            self.prev_frac = frac
            self.x = [frac * rpc, 0.0, 0.0, c.gp0] + [0.0] * (n - NX)
            self.P = self._P0()
            X, self.P, _ = self._sigma(self.x, self.P)
            self.el = np.zeros(len(self.el))   # the elements relaxed
            self.F_hat = self._fhat(X, self.el)
            self.nu = self.S = 0.0
            self.Pm_diag = list(self.p0)
            self.primed = True
            return BR_OK
        status = BR_OK
        # the last step's re-acquisition's alternative, for this step only
        alt, self.alt, alt_new = self.alt, None, None
        # 1.-2. sigma points and prediction
        pred = self._predict(self.x, self.P, u)
        if pred is None:
            return BR_E_NUMERIC
        xm, Pm, ok, em = pred
        if not ok:
            status = BR_E_NUMERIC
            self.n_recover += 1
        # 3. origin, innovation, gate
        th_new, nu, S, passes = self._innovate(xm, Pm, counts, frac)
        if not passes and alt is not None:
            und = self._undo(alt, u, counts, frac)
            if und is not None:
                (xm, Pm, ok2, em), (th_new, nu, S, passes) = und
                self.load_undo = True
                self.n_load_undo += 1
                if not ok2 and status == BR_OK:
                    status = BR_E_NUMERIC
                    self.n_recover += 1
        if not passes:
            acq = self._reacquire(nu, u, counts, frac)
            if acq is not None:
                # the alternative: the first prediction as an outlier commits it
                alt_new = {"x": list(xm), "P": [list(r) for r in Pm], "el": self._bounded(em, xm[3]),
                           "origin": self.origin, "nu": nu}
                (xm, Pm, ok, em), (th_new, nu, S, passes), self.P = acq
                self.load_acq = True
                self.n_load_acq += 1
                if not ok and status == BR_OK:
                    status = BR_E_NUMERIC
                    self.n_recover += 1
        if not passes:
            # 4. outlier: the prediction, old frame; re-anchoring after a run
            status_o = BR_W_OUTLIER
            x_new, P_new, origin_new = xm, Pm, self.origin
            n_out = self.n_outliers + 1
            if n_out >= c.reanchor_after:
                w_meas = (wrapdiff(counts, self.prev_counts) + frac - self.prev_frac) * rpc / c.dt
                x_new = [frac * rpc, w_meas] + xm[2:]
                P_new = self._P0()
                origin_new = int(counts)
                self.reanchored = True
                em = em + c.model.L * nu   # the elements with the position's jump to the measurement
        else:
            # 5. update
            status_o = BR_OK
            n_out = 0
            xm = [th_new] + xm[1:]
            K = [Pm[r][0] / S for r in range(n)]
            x_new = [xm[r] + K[r] * nu for r in range(n)]
            self._clamp_mean(x_new)
            # A = I - K H (H = e_0^T): A[r][s] = delta_rs - K[r] (s == 0)
            A = [[(1.0 if r == s else 0.0) - (K[r] if s == 0 else 0.0) for s in range(n)] for r in range(n)]
            AP = [[sum(A[r][t] * Pm[t][s] for t in range(n)) for s in range(n)] for r in range(n)]
            Pj = [[sum(AP[r][t] * A[s][t] for t in range(n)) + K[r] * c.r_var * K[s]
                   for s in range(n)] for r in range(n)]
            P_new = [[0.5 * (Pj[r][s] + Pj[s][r]) for s in range(n)] for r in range(n)]
            origin_new = int(counts)
            if c.mslip is not None:
                # the elements' common error into the elements, its mean back to 0
                em = em + x_new[2]
                x_new[2] = 0.0
        if not all(math.isfinite(v) for v in x_new) or not all(math.isfinite(v) for row in P_new for v in row):
            return BR_E_NUMERIC
        # 6. estimate over the sigma points of the new (x, P)
        X, P_new, ok = self._sigma(x_new, P_new)
        if not ok:
            status = BR_E_NUMERIC
            self.n_recover += 1
        # the elements within their slip bounds at the new mean's g_p
        el = self._bounded(em, x_new[3])
        F = self._fhat(X, el)
        if not math.isfinite(F):
            return BR_E_NUMERIC
        self.x, self.P, self.origin, self.F_hat, self.el = x_new, P_new, origin_new, F, el
        self.nu, self.S = nu, S
        self.Pm_diag = [Pm[i][i] for i in range(n)]
        self.prev_counts, self.prev_frac = int(counts), frac
        self.n_outliers = n_out
        self.alt = alt_new
        return status if status != BR_OK else status_o
