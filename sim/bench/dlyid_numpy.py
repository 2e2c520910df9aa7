# SPDX-License-Identifier: Apache-2.0
"""The PF's actuator delay for make bench's numpy PF (pf_numpy.py): the
command history and the delay identification's bank, written from
docs/modules/dlyid.md (equations dly1-dly8) and docs/modules/model.md ("the
delay is the estimators'"), in float32 like the firmware. The slots' filters
are a float32 array over the slots (each slot's operations are the same
elementwise), the common covariance a 3 x 3 float32 array whose products sum
their three terms in order, from 0, one array operation per term.

  history  u_a = (1 - f) u[k-1-m] + f u[k-2-m] for the delay (m + f) periods,
           0 for a command before the first; without a delay and without the
           identification u_a is the command itself
  bank     slots j = 0 .. N-1 at delays j step_s, slot N at the configured
           delay (the one in use at the start); per measurement:
           dly7 (the reversal rule), dly3 (covariance and gain), dly4 and dly5
           for every slot, then after the warm-up dly6 (the switch; dly8: in
           the steady phase a far one needs a far better sum), which hands the new slot's
           delay to the history from the next period on.

Used by NumpyPf.step in the order of a period: the command joins the history,
the torque of the delay in use is taken, then the bank takes the measurement."""
import math

import numpy as np

F = np.float32
NOISE_FACTOR = F(2.0)     # kappa, dly6
SETTLE_LENGTHS = F(3.0)   # s in presliding lengths, dly7


def periods(delay_s, dt_s):
    """A delay as (m whole periods, fraction f of the next), 0 <= f < 1."""
    q = F(delay_s) / F(dt_s)
    m = int(q)
    return m, q - F(m)


class DelayHistory:
    """The estimator's commands (newest first, 0 before the first; the keep newest, keep >= the
    longest delay's m + 2) and the torque of the delay in use."""

    def __init__(self, delay_s, dt_s, on, keep):
        self.m, self.f = periods(delay_s, dt_s)
        self.on = on
        self.u = np.zeros(keep, dtype=F)

    def torque(self, m, f):
        """u_a = (1 - f) u[k-1-m] + f u[k-2-m]; m and f arrays (one per slot) or scalars"""
        return (F(1.0) - f) * self.u[m] + f * self.u[m + 1]

    def apply(self, u):
        """the command u of the last period joins the history; returns the torque that reached
        the axis"""
        if not self.on:
            return u
        self.u[1:] = self.u[:-1]
        self.u[0] = u
        return self.torque(self.m, self.f)


class DelayBank:
    """The bank of dly1-dly8: one Kalman filter of the rigid axis per slot."""

    def __init__(self, cfg):
        d = cfg["delay_id"]
        self.n = n = int(d["n_cand"])
        T, L = F(cfg["dt_s"]), F(cfg["lead_mprad"])
        self.T = T
        self.step_s = F(d["step_s"])
        self.rpc = F(cfg["rad_per_count"])
        self.gp_max = F(cfg["gp_max_N"])
        # dly1: the rigid body over a period with u - L F held
        inv_j = F(1.0) / (F(cfg["J_kgm2"]) + L * L * F(cfg["M_kg"]))
        self.b0 = F(0.5) * T * T * inv_j
        self.b1 = T * inv_j
        self.a02 = -L * self.b0
        self.a12 = -L * self.b1
        self.q_force = F(d["q_force_N2ps"]) * T
        self.r = F(cfg["r_var_rad2"]) + self.rpc * self.rpc * F(1.0 / 12.0)
        # e^(-T / tau) (rounded once from double, as the C library's expf)
        self.forget = F(math.exp(float(-T / F(d["memory_s"]))))
        self.settle = SETTLE_LENGTHS * self.gp_max / (F(cfg["sigma0_Npm"]) * L)
        self.ratio = F(d["switch_ratio"])
        self.warmup = int(F(d["warmup_s"]) / T + F(0.5))
        # the steady phase from self.steady periods on (br_dlyid_cfg_t.steady_*; absent or 0: one phase)
        after = F(d.get("steady_after_s", 0.0))
        self.steady = int(after / T + F(0.5)) if after > F(0.0) else None
        self.forget_steady = F(math.exp(float(-T / F(d["steady_memory_s"])))) if self.steady is not None else self.forget
        self.ratio_steady = F(d["steady_switch_ratio"]) if self.steady is not None else self.ratio
        # the slots' delays: the candidates j step_s, then the configured delay
        mf = [periods(F(j) * F(d["step_s"]), T) for j in range(n)] + [periods(cfg.get("delay_s", 0.0), T)]
        self.cm = np.array([p[0] for p in mf])
        self.cf = np.array([p[1] for p in mf], dtype=F)
        self.diag = np.diag_indices(3)
        self.A = np.array([[1.0, T, self.a02], [0.0, 1.0, self.a12], [0.0, 0.0, 1.0]], dtype=F)
        self.cur = n
        self.n_switch = 0
        self.n_switch_steady = 0  # of them, in the steady phase
        self.primed = False

    def keep(self):
        """commands the history must keep for the longest slot"""
        return int(self.cm.max()) + 2

    def _prime(self, counts, frac):
        """dly2: every filter at theta = frac rpc, at rest, F = 0; P0 diagonal"""
        s = self.n + 1
        self.x = np.zeros((3, s), dtype=F)
        self.x[0] = frac * self.rpc
        self.J = np.zeros(s, dtype=F)
        w = self.rpc / self.T
        self.P = np.diag(np.array([self.r, w * w, self.gp_max * self.gp_max], dtype=F))
        self.origin = counts
        self.k = 0
        self.dir = 0
        self.settle_left = F(0.0)
        self.run = F(0.0)
        self.primed = True

    def _reversal(self):
        """dly7: a reversal of the velocity in use (beyond a count per period) after a run of
        at least the settle travel stops the scoring until the axis has travelled it again"""
        w_min = self.rpc / self.T
        w = self.x[1, self.cur]
        s = 1 if w > w_min else (-1 if w < -w_min else 0)
        step = np.abs(w) * self.T
        if s != 0 and self.dir != 0 and s != self.dir:
            if self.run >= self.settle:
                self.settle_left = self.settle
            self.run = F(0.0)
        else:
            self.settle_left = self.settle_left - step
            self.run = self.run + step
        if s != 0:
            self.dir = s

    def _covariance(self):
        """dly3: P- = A P A^T + diag(0, 0, q_F T), K = P-[:, 0] / S, S = P-_00 + R', P+ = P- - K P-[0, :],
        symmetrised; the products summed over l = 0, 1, 2 in order. Returns K."""
        A, P = self.A, self.P
        AP = np.zeros((3, 3), dtype=F)
        for l in range(3):
            AP = AP + A[:, l:l + 1] * P[l:l + 1, :]    # AP[i, j] += A[i, l] P[l, j]
        Pm = np.zeros((3, 3), dtype=F)
        for l in range(3):
            Pm = Pm + AP[:, l:l + 1] * A[:, l]          # Pm[i, j] += AP[i, l] A[j, l]
        Pm[2, 2] += self.q_force
        S = Pm[0, 0] + self.r
        K = Pm[:, 0] / S
        P = Pm - K[:, None] * Pm[0, :]
        # (P + P^T) / 2 off the diagonal (symmetric as computed), the diagonal kept
        Ps = F(0.5) * (P + P.T)
        Ps[self.diag] = P[self.diag]
        self.P = Ps
        return K

    def step(self, counts, frac, hist):
        """One measurement with the commands of hist (a DelayHistory); returns 1 when the slot in
        use changed (the history then models its delay from the next period on)"""
        if self.n == 0:
            return 0
        if not self.primed:
            self._prime(counts, frac)
            return 0
        T = self.T
        self._reversal()
        scored = not (self.settle_left > F(0.0))
        K = self._covariance()
        d = ((counts - self.origin + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)
        shift = F(d) * self.rpc
        y_rel = frac * self.rpc
        # dly4: each slot's prediction with the torque its delay brings
        u = hist.torque(self.cm, self.cf)
        x0, x1, x2 = self.x
        th = (((x0 + T * x1) + self.a02 * x2) + self.b0 * u) - shift
        om = (x1 + self.a12 * x2) + self.b1 * u
        # dly5: innovation, update, the forgotten sums
        nu = y_rel - th
        steady = self.steady is not None and self.k >= self.steady
        forget = self.forget_steady if steady else self.forget
        ratio = self.ratio_steady if steady else self.ratio
        with np.errstate(over="ignore", invalid="ignore"):
            self.x = np.stack((th + K[0] * nu, om + K[1] * nu, x2 + K[2] * nu))
            if scored:
                self.J = forget * self.J + nu * nu
        self.origin = counts
        if not (np.isfinite(self.x).all() and np.isfinite(self.J).all()):
            self.primed = False
            return 0
        self.k += 1
        if self.k < self.warmup:
            return 0
        # dly6: the best slot (the first of equal sums), decisively better than the one in use,
        # which explains the motion worse than the noise allows
        best = self.cur
        if not steady:
            for j in range(self.n + 1):
                if self.J[j] < self.J[best]:
                    best = j
            if not (self.J[best] < ratio * self.J[self.cur]):
                return 0
        else:
            # dly8: a candidate d steps along the grid from the delay in use (the configured one:
            # from its nearest candidate, d = 0 for that one) below rho^d times its sum; the best
            # of J_j / rho^d
            at = self.cur
            if at == self.n:
                g = (F(self.cm[self.n]) + self.cf[self.n]) * self.T / self.step_s + F(0.5)
                at = int(g) if g < F(self.n - 1) else self.n - 1
            w_best = F(1.0)
            for j in range(self.n):
                w = F(1.0)
                for _ in range(abs(j - at)):
                    w = F(w * ratio)
                if j != self.cur and F(self.J[j] * w_best) < F(self.J[best] * w):
                    best, w_best = j, w
            if best == self.cur:
                return 0
        j_noise = NOISE_FACTOR * (self.r + self.P[0, 0]) / (F(1.0) - forget)
        if not (self.J[self.cur] > j_noise):
            return 0
        self.cur = best
        self.n_switch += 1
        self.n_switch_steady += int(steady)
        return 1
