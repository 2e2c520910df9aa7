# SPDX-License-Identifier: Apache-2.0
"""Particle filter for the friction of one axis (thesis sections 2.3, 4),
float64 golden reference, written from the description in
firmware/include/bristle/br_pf.h (not from br_pf.c).

Particles x_j = [theta, omega, z, g_p] of the eq. 6 model (golden/ref/model.py),
j = 0..m-1, theta relative to an integer origin (the latest measured count).
The process noise is read from a standard-normal ROM table n[0..len-1]
(len a power of two): the sample for (particle j, state i) is
n[(pos + 4 j + i) & (len - 1)], and pos advances by 4 m + noise_skip after
every draw (priming and every step).

Priming (first measurement y = (counts, frac)):
    x_j   = [frac rpc, 0, 0, gp0] + x0_std * n_j,   g_p clamped to [gp_min, gp_max]
    origin = counts, estimate = the mean of the set, F_hat = mean f_nl(x_j), ESS = m.

One step with y_k = (counts, frac) and the torque u_{k-1} of the last period:
    shift = wrapdiff(counts, origin) rpc,   y = frac rpc
    1. predict  xn_j = f_d(x_j, u) + sqrt(Q) n_j;  g_p clamped;  theta -= shift.
                A particle whose model step fails or that is non-finite (or whose
                f_nl is) is invalid: it keeps its previous state and weight 0.
    2. weigh    l_j = -(theta_j - y)^2 / (2 R),  w_j = exp(l_j - max l)   (valid j)
                max l < -(outlier_sigma sqrt(R + rpc^2/12) + d)^2 / (2 R) (y further
                than outlier_sigma sqrt(R + rpc^2/12) + d, R with the encoder's
                quantisation, d the gate's transient term, from every particle;
                eq. G1): outlier, every valid particle gets w = 1.
    3. quantise W_j = floor(w_j 2^16)          (integers, the best particle 2^16)
    4. resample particle i copies j with C_{j-1} <= xi_i C_m < C_j,
                xi_i = (i + 1/2) / m, C_j = W_0 + ... + W_j (exact integers)
    5. estimate mean of the resampled set, F_hat = mean of f_nl over it (eq. 6),
                ESS = (sum w)^2 / sum w^2 of the step's weights.
    Outliers: after reanchor_after consecutive outlier steps (and on every
    further one) the cloud is re-anchored on y: theta shifted so that its mean
    is y, omega so that its mean is the measured velocity
    (shift + (frac - frac_prev) rpc) / dt, spread kept.
    No valid particle at all: BR_E_NUMERIC, the previous set (and origin) kept.
    Then origin = counts, frac_prev = frac.
A non-finite u or a frac outside [0, 1]: BR_E_INPUT, nothing changes.

Maxwell-slip elements (cfg.mslip, docs/modules/pf.md "Maxwell-slip
elements"; None: LuGre): each particle carries its own N element deflections
e_j (golden/ref/mslip.py, clamp form); z is not a state of the model (kept 0)
and its noise sample moves every element of the particle alike.
    priming:  e_j = clamp(0 + x0_std_z n_j2, +-Delta(g_pj)),  z_j = 0
    predict:  (theta, omega, e) = mslip.model_step (the trapezoidal step with
              `ms_passes` passes at the particle's g_p), then theta += q0 n0,
              omega += q1 n1, g_p = clamp(g_p + q3 n3), e = clamp(e + q2 n2,
              +-Delta(g_p)) at the new g_p; f_nl = sum k_i e_i. Valid: theta,
              omega and f_nl finite.
    resample: the elements with their particles.
    re-anchor: each particle's elements moved by L (y - mean theta), clamped
              at its g_p.
    estimate: F_hat = mean over the set of sum k_i e_ji.

External force (cfg.load, docs/modules/pf.md "External force"; None: off):
one load force F_d shared by every particle (N, load side, against +x as
friction is; 0 when priming) and the covariance P (3 x 3) of the cloud's
common error e = [dtheta, domega, dF], P0 = diag(0, 0, max_N^2).
g = L h^2 / (2 J_eff), Phi = [1 h -g; 0 1 -2g/h; 0 0 1].
    0. before the prediction:  P <- Phi P Phi^T + diag(0, 0, q_N2)
    1. the particles are predicted with the torque u - L F_d
    after 2. (the valid predicted particles, n of them, theta relative to the
    new origin): d = mean(theta_j) - y, v = max(0, mean((theta_j - mean)^2))
       gated (max l below the outlier threshold): dF = d / (g k^2), k = 1
         (the periods since the last measurement); |dF| > 2 max_N: nothing
         more, the step goes on as an outlier; otherwise P += dF^2 b b^T,
         b = [-g k^2, -2 g k / h, 1], a re-acquisition (n_load_acq + 1)
       S = P00 + v + R + rpc^2/12, K = P[:, 0] / S, nu = -d,
       theta_j += K0 nu, omega_j += K1 nu (each valid particle; f_nl and l_j
       made again), F_d <- clamp(F_d + K2 nu, +-max_N), P <- P - K P[0, :]
       The outlier decision and steps 3-5 then take the moved cloud.
       A glitch is not a load: when the last step re-acquired (its correction
       e = K nu1, nu1 its innovation, P_A the P its tick left) and this step's
       best particle is gated, the cloud is tried moved by -(Phi e)_theta
       (spike) and by that + nu1 (slip; the smaller |mean innovation| first),
       omega by -(Phi e)_omega; the first whose best particle passes is taken:
       F_d and F_d' less e2, P = Phi P_A Phi^T + diag(0, 0, q_N2), the update
       then as for any passing step (n_load_undo + 1).
    F_hat = clamp(mean f_nl + y, +-max_N) with F_d through a notch at the
    period's Nyquist frequency (pf.md, "The period-2 mode"):
    y = clamp((1 + r)/2 (F_d + F_d') - r y', +-max_N), F_d' the value at the
    step's start (before the update), y' the last step's, r = LOAD_NOTCH_R.
"""
import bisect
import math
from dataclasses import dataclass

import numpy as np

from . import model as rmodel
from . import mslip as rmslip

BR_OK = 0
BR_E_INPUT = -3
BR_E_NUMERIC = -4
BR_W_OUTLIER = 1  # a warning (positive): the step predicted only

W_BITS = 16
LOAD_NOTCH_R = 0.2  # the compensation's notch: its pole at -r (pf.md, "The period-2 mode")
LOAD_UNDO_GATE2 = 4.0  # a glitch's hypotheses at twice the gate's distance (pf.md, "A glitch is not a load")
NX = 4


@dataclass(frozen=True)
class PfCfg:
    model: rmodel.ModelParams
    dt: float
    m: int
    q_var: tuple          # per-step process noise variances (4)
    r_var: float          # measurement variance, rad^2
    gp0: float
    x0_std: tuple         # initial spread (4)
    gp_min: float
    gp_max: float
    outlier_sigma: float
    reanchor_after: int
    rad_per_count: float
    noise: tuple          # the ROM table, float values
    noise_skip: int
    load: object = None   # LoadCfg: the shared external force F_d; None: off
    mslip: object = None  # mslip.MslipParams (sigma2 0): the particles' elements; None: LuGre
    ms_passes: int = 2    # the trapezoidal step's fixed-point passes
    outlier_transient: float = 0.0  # the gate's transient term d, rad (eq. G1); 0: the thesis gate


@dataclass(frozen=True)
class LoadCfg:
    q_N2: float    # random walk of F_d per step, N^2
    max_N: float   # |F_d| and |F_hat| bound (and sqrt P0 of F_d), N; re-acquisition up to |dF| <= 2 max_N


def wrapdiff(now, prev):
    """now - prev modulo 2^32, read as a signed 32-bit integer."""
    d = (int(now) - int(prev)) & 0xFFFFFFFF
    return d - (1 << 32) if d >= (1 << 31) else d


def resample_idx(W):
    """Systematic resampling on integer weights: for i = 0..m-1 the j with
    C_{j-1} <= (i + 1/2) C_m / m < C_j. Since the C_j are integers this is
    C_{j-1} <= floor((2 i + 1) C_m / (2 m)) < C_j: the first j with C_j > t_i."""
    m = len(W)
    C = []
    c = 0
    for w in W:
        c += int(w)
        C.append(c)
    total = C[-1]
    if total <= 0:
        raise ValueError("all weights zero")
    return [bisect.bisect_right(C, ((2 * i + 1) * total) // (2 * m)) for i in range(m)]


class Pf:
    def __init__(self, cfg):
        self.cfg = cfg
        self.q_std = [math.sqrt(v) for v in cfg.q_var]
        self.noise_pos = 0
        self.origin = 0
        self.prev_frac = 0.0
        self.n_outliers = 0
        self.primed = False
        self.x = [np.zeros(NX) for _ in range(cfg.m)]
        n_el = 0 if cfg.mslip is None else len(cfg.mslip.k)
        assert cfg.mslip is None or cfg.load is None, "elements with the external force: not in this reference"
        self.e = [np.zeros(n_el) for _ in range(cfg.m)]   # each particle's element deflections
        # outputs of the last step
        self.xp = None          # predicted set (before resampling)
        self.W = None           # quantised weights
        self.idx = None         # resampling indices
        self.mean = np.array([0.0, 0.0, 0.0, cfg.gp0])
        self.F_hat = 0.0
        self.F_hat_pred = 0.0
        self.ess = float(cfg.m)
        self.reanchored = False
        self.l = None           # log-weights of the last step
        # cfg.load: F_d, the common error's covariance, re-acquisitions
        self.Fd = 0.0
        self.Fd_start = 0.0     # F_d at the last step's start, before its update
        self.Fd_comp = 0.0      # F_d through the compensation's notch
        self.n_load_acq = 0
        self.load_acq = False   # the last step re-acquired
        self.d = 0.0            # the last step's mean innovation mean(theta_j) - y (before the move)
        self.v = 0.0            # and the spread var(theta_j)
        self.Pm = None          # P before the last update (after the tick and any inflation)
        # the last step's re-acquisition for its undo: (e, P as predicted, nu1) or None
        self.alt = None
        self.n_load_undo = 0
        self.load_undo = False  # the last step undid the re-acquisition before it
        if cfg.load is not None:
            h = cfg.dt
            self.g = cfg.model.L * h * h / (2.0 * cfg.model.Jeff)
            self.Phi = np.array([[1.0, h, -self.g], [0.0, 1.0, -2.0 * self.g / h], [0.0, 0.0, 1.0]])
            self.P = np.diag([0.0, 0.0, cfg.load.max_N ** 2])

    def _n(self, j, i):
        c = self.cfg
        return c.noise[(self.noise_pos + NX * j + i) & (len(c.noise) - 1)]

    def _advance(self):
        c = self.cfg
        self.noise_pos = (self.noise_pos + NX * c.m + c.noise_skip) & (len(c.noise) - 1)

    def _clamp_gp(self, v):
        return min(max(v, self.cfg.gp_min), self.cfg.gp_max)

    def _estimate(self):
        """Mean state and mean f_nl (eq. 6) of the current set."""
        c = self.cfg
        s = np.zeros(NX)
        sf = 0.0
        for xj, ej in zip(self.x, self.e):
            s = s + xj
            sf += rmodel.fnl(c.model, xj) if c.mslip is None else rmslip.force(c.mslip, ej, 0.0)
        self.mean = s / c.m
        self.F_hat = sf / c.m
        if c.load is not None:
            r = LOAD_NOTCH_R
            y = 0.5 * (1.0 + r) * (self.Fd + self.Fd_start) - r * self.Fd_comp
            self.Fd_comp = min(max(y, -c.load.max_N), c.load.max_N)
            self.F_hat = min(max(self.F_hat + self.Fd_comp, -c.load.max_N), c.load.max_N)

    def _prime(self, counts, frac):
        c = self.cfg
        mu = [frac * c.rad_per_count, 0.0, 0.0, c.gp0]
        for j in range(c.m):
            xj = np.array([mu[i] + c.x0_std[i] * self._n(j, i) for i in range(NX)])
            xj[3] = self._clamp_gp(xj[3])
            if c.mslip is not None:
                # the elements relaxed but for z's draw, their common deflection
                self.e[j] = rmslip.move(c.mslip, np.zeros(len(c.mslip.k)), xj[2], xj[3])
                xj[2] = 0.0
            self.x[j] = xj
        self._advance()
        self.origin = int(counts)
        self.prev_frac = frac
        self.primed = True
        self._estimate()
        self.ess = float(c.m)
        self.F_hat_pred = self.F_hat
        return BR_OK

    def step(self, counts, frac, u):
        """One filter step; returns the status."""
        if not math.isfinite(u) or not math.isfinite(frac) or not 0.0 <= frac <= 1.0:
            return BR_E_INPUT
        if not self.primed:
            return self._prime(counts, frac)
        c = self.cfg
        rpc = c.rad_per_count
        shift = wrapdiff(counts, self.origin) * rpc
        y = frac * rpc
        if c.load is not None:
            # the common error's covariance over the period; the torque with the load
            self.P = self.Phi @ self.P @ self.Phi.T + np.diag([0.0, 0.0, c.load.q_N2])
            self.Fd_start = self.Fd
            u = u - c.model.L * self.Fd
        xp, ep, fn, l = [], [], [], []
        for j in range(c.m):
            if c.mslip is None:
                st, xn, _ = rmodel.step(c.model, self.x[j], u, c.dt, stages=False)
                xn = np.array([xn[i] + self.q_std[i] * self._n(j, i) for i in range(NX)])
                xn[3] = self._clamp_gp(xn[3])
                en = self.e[j]
            else:
                x0 = self.x[j]
                th1, om1, e1 = rmslip.model_step(c.model, c.mslip, x0[0], x0[1], x0[3], self.e[j], u, c.dt,
                                                 c.ms_passes)
                st = rmodel.BR_OK
                xn = np.array([th1 + self.q_std[0] * self._n(j, 0), om1 + self.q_std[1] * self._n(j, 1), x0[2],
                               self._clamp_gp(x0[3] + self.q_std[3] * self._n(j, 3))])
                # z's sample moves every element; each clamped at the new g_p
                en = rmslip.move(c.mslip, e1, self.q_std[2] * self._n(j, 2), xn[3])
            xn[0] -= shift
            valid = st == rmodel.BR_OK and all(math.isfinite(v) for v in xn)
            if c.mslip is None:
                f = rmodel.fnl(c.model, xn) if valid else 0.0
            else:
                f = rmslip.force(c.mslip, en, 0.0) if valid else 0.0
            valid = valid and math.isfinite(f)
            xp.append(xn if valid else self.x[j].copy())
            ep.append(en if valid else self.e[j].copy())
            fn.append(f)
            l.append(-((xn[0] - y) ** 2) / (2.0 * c.r_var) if valid else -math.inf)
        self._advance()
        self.xp, self.fnl_pred, self.l = xp, fn, l
        lmax = max(l)
        if lmax == -math.inf:
            self.W = self.idx = None
            return BR_E_NUMERIC
        # eq. G1: the gate g sqrt(R + rpc^2/12) + d in log-weight units
        l_gate = -((c.outlier_sigma * math.sqrt(c.r_var + rpc * rpc / 12.0) + c.outlier_transient) ** 2) / (2.0 * c.r_var)
        if c.load is not None:
            lmax = self._load_update(xp, fn, l, y, l_gate)
        outlier = lmax < l_gate
        w = [0.0 if lj == -math.inf else (1.0 if outlier else math.exp(lj - lmax)) for lj in l]
        W = [int(math.floor(wj * 2.0 ** W_BITS)) for wj in w]
        idx = resample_idx(W)
        self.W, self.idx = W, idx
        self.x = [xp[k].copy() for k in idx]
        self.e = [ep[k].copy() for k in idx]
        # mean f_nl over the resampled set before any re-anchoring (a diagnostic
        # column of the trace: F_hat differs from it only on re-anchoring steps)
        self.F_hat_pred = sum(fn[k] for k in idx) / c.m
        self.n_outliers = self.n_outliers + 1 if outlier else 0
        self.reanchored = self.n_outliers >= c.reanchor_after
        if self.reanchored:
            self.alt = None  # a re-acquisition is not undone on a re-anchored cloud
            w_meas = (shift + (frac - self.prev_frac) * rpc) / c.dt
            th = sum(xj[0] for xj in self.x) / c.m
            om = sum(xj[1] for xj in self.x) / c.m
            for j, xj in enumerate(self.x):
                xj[0] += y - th
                xj[1] += w_meas - om
                if c.mslip is not None:
                    # the elements moved by the position's jump
                    self.e[j] = rmslip.move(c.mslip, self.e[j], c.model.L * (y - th), xj[3])
        self.origin = int(counts)
        self.prev_frac = frac
        self._estimate()
        self.ess = sum(w) ** 2 / sum(wj * wj for wj in w)
        return BR_W_OUTLIER if outlier else BR_OK

    def _load_undo(self, xp, fn, l, y, l_gate, valid):
        """A glitch is not a load (pf.md): the last step re-acquired and this
        step's innovation is gated. The re-acquisition's correction e carried
        over the period is Phi e; spike: the cloud moved back by it; slip: and
        on by the last innovation nu1 (the counter stays off). The smaller
        |mean innovation| first; the first whose best particle is within twice
        the gate's distance (l >= LOAD_UNDO_GATE2 x the gate's l) is taken (F_d and F_d' without e2, P = Phi P_A Phi^T + Q, the cloud
        moved). Returns whether one was taken."""
        c = self.cfg
        e, P_A, nu1 = self.alt
        h, g = c.dt, self.g
        s_th = e[0] + h * e[1] - g * e[2]
        s_om = e[1] - 2.0 * g / h * e[2]
        d = float(np.mean([xp[j][0] for j in valid])) - y
        hyp = [-s_th, -s_th + nu1]  # spike, slip
        if abs(d + hyp[1]) < abs(d + hyp[0]):
            hyp.reverse()
        for dth in hyp:
            best = max(-((xp[j][0] + dth - y) ** 2) / (2.0 * c.r_var) for j in valid)
            if not best >= LOAD_UNDO_GATE2 * l_gate:
                continue
            self.P = self.Phi @ P_A @ self.Phi.T + np.diag([0.0, 0.0, c.load.q_N2])
            mx = c.load.max_N
            self.Fd = min(max(self.Fd - e[2], -mx), mx)
            self.Fd_start = min(max(self.Fd_start - e[2], -mx), mx)
            for j in valid:
                xj = xp[j]
                xj[0] += dth
                xj[1] -= s_om
                fn[j] = rmodel.fnl(c.model, xj)
                l[j] = -((xj[0] - y) ** 2) / (2.0 * c.r_var)
            self.n_load_undo += 1
            return True
        return False

    def _load_update(self, xp, fn, l, y, l_gate):
        """cfg.load after the weighing: the last step's re-acquisition undone
        when it explains a gated innovation as a glitch, then F_d's Kalman
        update on the cloud's mean innovation (a re-acquisition when gated and
        explained by a load), the valid particles of xp moved, fn and l made
        again in place. Returns the largest log-weight."""
        c = self.cfg
        ld = c.load
        valid = [j for j in range(c.m) if l[j] != -math.inf]
        alt, self.alt = self.alt, None
        self.load_undo = False
        if alt is not None and max(l) < l_gate:
            self.alt = alt
            self.load_undo = self._load_undo(xp, fn, l, y, l_gate, valid)
            self.alt = None
        gated = max(l) < l_gate
        th = np.array([xp[j][0] for j in valid])
        self.d = float(np.mean(th)) - y
        self.v = float(np.mean((th - np.mean(th)) ** 2))
        self.load_acq = False
        P_pred = self.P.copy()
        if gated:
            k = 1.0  # periods since the last measurement (this reference measures every period)
            dF = self.d / (self.g * k * k)
            if not abs(dF) <= 2.0 * ld.max_N:
                self.Pm = self.P.copy()
                return max(l)
            b = np.array([-self.g * k * k, -2.0 * self.g * k / c.dt, 1.0])
            self.P = self.P + dF * dF * np.outer(b, b)
            self.load_acq = True
            self.n_load_acq += 1
        self.Pm = self.P.copy()
        S = self.P[0, 0] + self.v + c.r_var + c.rad_per_count ** 2 / 12.0
        K = self.P[:, 0] / S
        nu = -self.d
        self.P = self.P - np.outer(K, self.P[0, :])
        Fd = min(max(self.Fd + K[2] * nu, -ld.max_N), ld.max_N)
        if self.load_acq:
            # kept for the next step's undo: the correction as applied, P as predicted, nu1
            self.alt = (np.array([K[0] * nu, K[1] * nu, Fd - self.Fd]), P_pred, nu)
        self.Fd = Fd
        for j in valid:
            xj = xp[j]
            xj[0] += K[0] * nu
            xj[1] += K[1] * nu
            fn[j] = rmodel.fnl(c.model, xj)
            l[j] = -((xj[0] - y) ** 2) / (2.0 * c.r_var)
        return max(l)
