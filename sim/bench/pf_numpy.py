#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""make bench, numpy side: the particle filter of firmware/pf/br_pf.c written
in numpy, vectorised over the particles, timed on the recording br_bench made
(br_bench --record FILE), and compared with the C filter.

Same model and algorithm as br_pf.c, in float32 throughout (as the firmware):
  delay     the torque u_a the command history gives for the delay in use, and
            the delay identification's bank (dly1-dly8, dlyid_numpy.py), whose
            switch changes the delay from the next period on
  predict   eq. 6 by the PF's RK4 (br_model_kp_rk4) on every particle,
            then, per particle (a mask on the a h <= 2 test at both ends of
            the step), the bounded
            displacement-exact scheme with 3 fixed-point passes (br_model.c),
            evaluated on the masked particles only and scattered back (as C
            computes it only where needed); process noise from the same ROM table
            (firmware/design/gen_noise.py table(), checked against the C table's
            hash), indexed (pos + 4 j + i) & (len - 1), pos += 4 m + noise_skip
  weigh     l_j = -(theta_j - y)^2 / (2 R), w_j = br_exp_neg(l_j - max l) (the
            firmware's deterministic exp, vectorised), outlier rule as in C
  quantise  W_j = floor(w_j 2^16) (uint32)
  resample  integer systematic: C = cumsum(W) (int64), t_i = floor((2 i + 1) C_m / (2 m)),
            idx = searchsorted(C, t, side="right")
  estimate  mean state, F_hat = mean f_nl over the resampled set, ESS,
            re-anchoring after reanchor_after outliers
Every operation is a float32 numpy ufunc in the order of the C code, and the
sums run left to right (cumsum) as the C loops do, so the numpy filter
reproduces the C one bit for bit: its F_hat equals the C F_hat (recorded by
br_bench) at every step, which pf_numpy.py checks.

Timing: one untimed warm-up over the first 200 steps, then --reps replays of
the whole recording into a fresh filter, every step k >= 1 timed with
time.perf_counter_ns (the priming step excluded, as in br_bench). Reported:
ns per particle-step of each replay (sum of its step times / (steps m)), the
median over replays (min, max), the same in thread CPU time
(time.thread_time_ns around the loop: stops while the process is descheduled),
and the per-step latency p50 / p99 / max pooled over replays. The per-step
clock reads (~0.1 us) are negligible against a step of ~0.5 ms.

Usage: pf_numpy.py RECORDING [--reps N] [--c-json FILE] [--out FILE] [--particles-json FILE]
  --c-json  br_bench's JSON: prints the summary table (C, numpy, ratio, UKF,
            memory) and, with --out, writes both and the ratio to one JSON.
  --particles-json  pf_particles.py's JSON (the particles library's PF): its
            column in the table, "pf_particles" in the JSON."""
import argparse
import json
import os
import platform
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "firmware", "design"))
import gen_noise  # noqa: E402
from dlyid_numpy import DelayBank, DelayHistory  # noqa: E402
from pf_load_numpy import LoadNumpy  # noqa: E402

F = np.float32
# constants of the C code
RK4_AH_MAX = F(2.0)          # BR_MODEL_RK4_AH_MAX, br_model.h
BOUNDED_PASSES = 3           # BR_MODEL_BOUNDED_PASSES, br_model.c
W_ONE = F(1 << 16)           # 2^BR_PF_W_BITS, br_pf.h
LOAD_NOTCH_R = F(0.2)        # BR_PF_LOAD_NOTCH_R, br_pf_load.h
LOAD_UNDO_GATE2 = F(4.0)     # BR_PF_LOAD_UNDO_GATE2, br_pf_load.h
BR_OK, BR_E_NUMERIC, BR_W_OUTLIER = 0, -4, 1


def fnv1a64(b):
    h = 14695981039346656037
    for c in b:
        h = ((h ^ c) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    return h


def seqsum(a):
    """Sum over the last axis in float32, left to right like the C loops
    (np.sum's pairwise summation would round differently)."""
    return np.cumsum(a, axis=-1, dtype=F)[..., -1]


def exp_neg(x):
    """br_exp_neg (firmware/private/br_math.h) on a float32 array: e^x for x <= 0,
    2^n times a degree-6 Taylor polynomial, 0 below -87 and for NaN."""
    zero = ~(x > F(-87.0))
    x = np.where(zero, F(0.0), np.minimum(x, F(0.0)))
    t = x * F(1.44269504)
    n = (t - F(0.5)).astype(np.int32)
    f = t - n.astype(F)
    up = f > F(0.5)
    n = n + up
    f = np.where(up, f - F(1.0), f)
    y = f * F(0.693147181)
    p = y * (F(1.0) / F(720.0)) + F(1.0) / F(120.0)
    p = p * y + F(1.0) / F(24.0)
    p = p * y + F(1.0) / F(6.0)
    p = p * y + F(0.5)
    p = p * y + F(1.0)
    p = p * y + F(1.0)
    scale = ((n + 127) << 23).astype(np.uint32).view(F)
    return np.where(zero, F(0.0), p * scale)


class NumpyPf:
    """br_pf_t in numpy: particles as a (4, m) float32 array [theta, omega, z, g_p]."""

    def __init__(self, cfg, noise):
        self.m = m = int(cfg["n_particles"])
        self.h = F(cfg["dt_s"])
        self.L = F(cfg["lead_mprad"])
        self.s0 = F(cfg["sigma0_Npm"])
        self.s1 = F(cfg["sigma1_Nspm"])
        J, M, s2 = F(cfg["J_kgm2"]), F(cfg["M_kg"]), F(cfg["sigma2_Nspm"])
        self.inv_jeff = F(1.0) / (J + self.L * self.L * M)   # br_model_init
        self.visc = self.L * self.L * s2
        self.s0L = self.s0 * self.L
        # the PF's RK4 form (br_model_kp_rk4): each
        # particle's k_p = sigma0 L / g_p (recomputed here from g_p: the same
        # float the C filter carries) and folded constants
        self.kp_cw = self.visc * self.inv_jeff
        self.kp_cz = (self.L * self.s0) * self.inv_jeff
        self.kp_czd = (self.L * self.s1) * self.inv_jeff
        self.ah_lim = RK4_AH_MAX / self.h
        self.q_std = np.sqrt(np.array(cfg["q_var"], dtype=F)).reshape(4, 1)
        # cfg.adapt, the innovation-driven noise of omega, z and g_p (adapt_update)
        ad = cfg.get("adapt", {})
        self.nis_ref = F(ad.get("nis_ref", 0.0))
        self.alpha, self.max_scale = F(ad.get("alpha", 0.0)), F(ad.get("max_scale", 1.0))
        self.r_gate = F(cfg["r_var_rad2"]) + F(cfg["rad_per_count"]) * F(cfg["rad_per_count"]) * F(1.0 / 12.0)
        self.nis_avg = F(0.0)
        self.q_scale = F(1.0)
        self.inv_2r = F(0.5) / F(cfg["r_var_rad2"])
        # the gate with the encoder's quantisation and the transient term d (eq. G1, as br_pf_init
        # and br_est_gate_f2): -g^2 (R + rpc^2 / 12) f^2 / (2 R), f = 1 + d / (g sqrt(R + rpc^2 / 12));
        # cfg.adapt's NIS cap g^2 f^2 (eq. G2)
        rpc = F(cfg["rad_per_count"])
        g = F(cfg["outlier_sigma"])
        f = F(1.0) + F(cfg.get("outlier_transient_rad", 0.0)) / (g * np.sqrt(self.r_gate))
        f2 = f * f
        self.nis_max = g * g * f2
        self.outlier_l = F(-0.5) * g * g * (F(1.0) + rpc * rpc * F(1.0 / 12.0) / F(cfg["r_var_rad2"])) * f2
        self.reanchor_after = int(cfg["reanchor_after"])
        self.rpc = F(cfg["rad_per_count"])
        self.gp0 = F(cfg["gp0_N"])
        self.gp_min, self.gp_max = F(cfg["gp_min_N"]), F(cfg["gp_max_N"])
        self.x0_std = np.array(cfg["x0_std"], dtype=F).reshape(4, 1)
        # the actuator delay and its identification (dlyid_numpy.py, docs/modules/dlyid.md)
        self.bank = DelayBank(cfg)
        self.hist = DelayHistory(cfg["delay_s"], cfg["dt_s"], F(cfg["delay_s"]) > F(0.0) or self.bank.n > 0,
                                 self.bank.keep())
        # cfg.load, the shared external force F_d (br_pf_load.c; absent or 0, 0: off)
        ld = cfg.get("load", {})
        self.load = LoadNumpy(F(ld.get("q_N2", 0.0)), F(ld.get("max_N", 0.0)), self.h, self.L, self.inv_jeff,
                              LOAD_NOTCH_R, seqsum, LOAD_UNDO_GATE2)
        self.noise = noise
        self.mask = len(noise) - 1
        self.skip = int(cfg["noise_skip"])
        self.base = (4 * np.arange(m)[None, :] + np.arange(4)[:, None]).astype(np.int64)  # [i, j] = 4 j + i
        self.two_i1 = 2 * np.arange(m, dtype=np.int64) + 1
        self.inv_m = F(1.0) / F(m)
        self.pos = 0
        self.origin = 0
        self.prev_frac = F(0.0)
        self.n_outliers = 0
        self.reanchored = False
        self.primed = False
        self.x = np.zeros((4, m), dtype=F)
        self.mean = np.zeros(4, dtype=F)
        self.F_hat = F(0.0)
        self.ess = F(m)

    def _noise(self):
        n = self.noise[(self.pos + self.base) & self.mask]
        self.pos = (self.pos + 4 * self.m + self.skip) & self.mask
        return n

    def _fnl(self, om, z, gp, div=False):
        """f_nl (eqs. 3, 4): divided by g_p (div, br_model_fcomp_N), or with k_p as the C filter's prediction"""
        if not div:
            zdot = self.L * om - (self.s0L / gp * np.abs(om)) * z
        else:
            v = self.L * om
            zdot = v - self.s0 * np.abs(v) * z / gp
        return self.s0 * z + self.s1 * zdot

    def _model_step_kp(self, th, om, z, gp, u):
        """br_model_kp_rk4 on every particle, the bounded scheme where a h > 2"""
        L, h, hh = self.L, self.h, F(0.5) * self.h
        h6, h3 = h / F(6.0), h / F(3.0)
        a, cw, cz, czd = u * self.inv_jeff, self.kp_cw, self.kp_cz, self.kp_czd
        kp = self.s0L / gp

        def stage(w, zz):
            kw = kp * np.abs(w)
            zd = L * w - kw * zz
            return ((a - cw * w) - cz * zz) - czd * zd, zd, kw

        k1w, k1z, kw1 = stage(om, z)
        om2, z2 = om + hh * k1w, z + hh * k1z
        k2w, k2z, _ = stage(om2, z2)
        om3, z3 = om + hh * k2w, z + hh * k2z
        k3w, k3z, _ = stage(om3, z3)
        om4, z4 = om + h * k3w, z + h * k3z
        k4w, k4z, _ = stage(om4, z4)
        th1 = th + (h6 * (om + om4) + h3 * (om2 + om3))
        om1 = om + (h6 * (k1w + k4w) + h3 * (k2w + k3w))
        z1 = z + (h6 * (k1z + k4z) + h3 * (k2z + k3z))
        rk4 = (kw1 <= self.ah_lim) & (kp * np.abs(om1) <= self.ah_lim)
        b = np.flatnonzero(~rk4)
        if b.size:
            th1[b], om1[b], z1[b] = self._bounded(th[b], om[b], z[b], gp[b], u)
        return th1, om1, z1

    def _bounded(self, th, w0, z0, gp, u):
        """br_model.c bounded_step: z exact over the displacement, trapezoidal rigid body."""
        h, L, s0, s1 = self.h, self.L, self.s0, self.s1
        wm = w0
        with np.errstate(divide="ignore", invalid="ignore"):
            for _ in range(BOUNDED_PASSES):
                dth = wm * h
                dx = L * dth
                zss = np.copysign(gp / s0, dx)
                r = s0 * np.abs(dx) / gp
                ome = -np.expm1(-r)
                q = np.where(r > F(1e-6), ome / r, F(1.0) - F(0.5) * r)
                moving = dx != F(0.0)
                z1 = np.where(moving, z0 + (zss - z0) * ome, z0)
                zint = np.where(moving, h * (zss + (z0 - zss) * q), z0 * h)
                w1 = w0 + (u * h - self.visc * dth - L * (s0 * zint + s1 * (z1 - z0))) * self.inv_jeff
                wm = F(0.5) * (w0 + w1)
        return th + dth, w1, z1

    def _prime(self, counts, frac):
        mean = np.array([frac * self.rpc, 0.0, 0.0, self.gp0], dtype=F).reshape(4, 1)
        x = mean + self.x0_std * self._noise()
        x[3] = np.fmin(np.fmax(x[3], self.gp_min), self.gp_max)
        self.x = x
        self.origin = counts
        self.prev_frac = frac
        self.primed = True
        self.mean = seqsum(x) * self.inv_m
        self.F_hat = seqsum(self._fnl(x[1], x[2], x[3], div=True)) * self.inv_m  # br_model_fcomp_N
        self.ess = F(self.m)
        return BR_OK

    def _adapt(self, s1, s2, n_valid):
        """adapt_update: the NIS of the predicted cloud from the sums of d_j =
        theta_j - y (0 for an invalid particle) and d_j^2 in particle order"""
        n = F(n_valid)
        mean = s1 / n
        var = s2 / n - mean * mean
        nis = (mean * mean) / ((var if var > F(0.0) else F(0.0)) + self.r_gate)
        nis = nis if nis <= self.nis_max else self.nis_max
        self.nis_avg = self.nis_avg + self.alpha * (nis - self.nis_avg)
        sc = self.nis_avg / self.nis_ref
        self.q_scale = np.sqrt(sc if sc < self.max_scale else self.max_scale) if sc > F(1.0) else F(1.0)

    def step(self, counts, frac, u):
        """br_pf_step; counts a Python int, frac and u np.float32. Returns the status."""
        # the torque that reached the axis over the last period: u with the delay in use; then the
        # delay identification takes the measurement, its switch acting from the next period on
        u = self.hist.apply(u)
        if self.bank.step(counts, frac, self.hist):
            self.hist.m, self.hist.f = self.bank.cm[self.bank.cur], self.bank.cf[self.bank.cur]
        if not self.primed:
            return self._prime(counts, frac)
        m, rpc = self.m, self.rpc
        d = ((counts - self.origin + (1 << 31)) & 0xFFFFFFFF) - (1 << 31)   # br_counts_delta
        shift = F(d) * rpc
        y_rel = frac * rpc
        x = self.x
        ld = self.load
        # cfg.load: P over the period, F_d at its start; the particles predicted with u - L F_d
        ld.tick()
        u = ld.torque(u)
        # 1. predict
        th, om, z = self._model_step_kp(x[0], x[1], x[2], x[3], u)
        n = self._noise()
        th = th + self.q_std[0] * n[0]
        om = om + (self.q_std[1] * self.q_scale) * n[1]
        z = z + (self.q_std[2] * self.q_scale) * n[2]
        gp = np.fmin(np.fmax(x[3] + (self.q_std[3] * self.q_scale) * n[3], self.gp_min), self.gp_max)
        th = th - shift
        fnl = self._fnl(om, z, gp)
        valid = np.isfinite(th) & np.isfinite(om) & np.isfinite(z) & np.isfinite(gp) & np.isfinite(fnl)
        # 2. log-likelihood
        e = th - y_rel
        l = -(e * e) * self.inv_2r
        xp = np.stack((th, om, z, gp))
        n_valid = int(np.count_nonzero(valid))
        if n_valid < m:
            xp = np.where(valid, xp, x)
            fnl = np.where(valid, fnl, F(0.0))
            l = np.where(valid, l, F(-np.inf))
        if n_valid == 0:
            return BR_E_NUMERIC
        d = e * valid.astype(F)
        sums = [seqsum(d), seqsum(d * d)]
        lmax = l.max()
        if ld.on:
            # cfg.load: F_d's update on the cloud's innovation, the cloud moved by its change
            lmax, xp, fnl, l, valid = ld.update(self, y_rel, lmax, sums, n_valid, xp, fnl, l, valid)
        if self.nis_ref > F(0.0):
            self._adapt(sums[0], sums[1], n_valid)
        outlier = lmax < self.outlier_l
        # 3. weights, quantised
        w = valid.astype(F) if outlier else exp_neg(l - lmax)
        W = (w * W_ONE).astype(np.uint32)
        sw, sw2 = seqsum(w), seqsum(w * w)
        # 4. integer systematic resampling
        C = np.cumsum(W, dtype=np.int64)
        idx = np.searchsorted(C, (self.two_i1 * C[-1]) // (2 * m), side="right")
        # 5. estimate over the resampled set
        x = xp[:, idx]
        s = seqsum(x)
        sf = seqsum(fnl[idx])
        self.n_outliers = self.n_outliers + 1 if outlier else 0
        self.reanchored = self.n_outliers >= self.reanchor_after
        if self.reanchored:
            ld.alt = False  # a re-acquisition of this step is not undone on a re-anchored cloud
            omega_meas = (shift + (frac - self.prev_frac) * rpc) / self.h
            d_th, d_om = y_rel - s[0] * self.inv_m, omega_meas - s[1] * self.inv_m
            x[0] += d_th
            x[1] += d_om
            # f_nl depends on omega: the estimate is that of the moved cloud (br_model_fcomp_N)
            sf = seqsum(self._fnl(x[1], x[2], x[3], div=True))
            s[0] += d_th * F(m)
            s[1] += d_om * F(m)
        self.x = x
        self.origin = counts
        self.prev_frac = frac
        self.mean = s * self.inv_m
        self.F_hat = ld.comp(sf * self.inv_m)
        self.ess = sw * sw / sw2
        return BR_W_OUTLIER if outlier else BR_OK


def pf_cfg_load_on(cfg):
    ld = cfg.get("load", {})
    return ld.get("q_N2", 0.0) != 0.0 or ld.get("max_N", 0.0) != 0.0


def load_recording(path):
    """(configuration, {column: array}) of a br_bench --record file."""
    cfg, names, skip = None, None, 0
    with open(path) as f:
        for line in f:
            skip += 1
            if line.startswith("# pf_cfg "):
                cfg = json.loads(line[len("# pf_cfg "):])
            elif not line.startswith("#"):
                names = line.strip().split(",")
                break
    if cfg is None or names is None:
        sys.exit("pf_numpy: %s is not a br_bench --record file" % path)
    d = np.loadtxt(path, delimiter=",", skiprows=skip, ndmin=2)
    return cfg, {k: d[:, i] for i, k in enumerate(names)}


def replay(cfg, noise, rec, n_steps=None):
    """A fresh filter over the recording; returns (F_hat per step, wall ns of each
    step k >= 1, thread CPU ns of steps 1.. together, statuses, {"adapt_active_steps":
    steps after which cfg.adapt's noise factor is above 1, "reanchor_steps": steps
    that re-anchored the cloud, "delay_switches": the delay identification's switches,
    "delay_switches_steady": those of its steady phase, "load_acquisitions" and
    "load_undos": cfg.load's re-acquisitions and those undone})."""
    pf = NumpyPf(cfg, noise)
    counts = [int(c) for c in rec["counts"]]
    frac = rec["frac"].astype(F)
    u = rec["u_prev_Nm"].astype(F)
    n = len(counts) if n_steps is None else n_steps
    fhat = np.zeros(n)
    st = np.zeros(n, dtype=int)
    adapt = np.zeros(n, dtype=bool)   # cfg.adapt's factor above 1 after the step
    anchor = np.zeros(n, dtype=bool)  # the cloud re-anchored at the step
    st[0] = pf.step(counts[0], frac[0], u[0])
    fhat[0] = pf.F_hat
    ns = np.zeros(n - 1)
    clock = time.perf_counter_ns
    c0 = time.thread_time_ns()
    for k in range(1, n):
        t0 = clock()
        s = pf.step(counts[k], frac[k], u[k])
        ns[k - 1] = clock() - t0
        st[k] = s
        adapt[k] = pf.q_scale > F(1.0)
        anchor[k] = s == BR_W_OUTLIER and pf.reanchored
        if s == BR_OK or s == BR_W_OUTLIER:
            fhat[k] = pf.F_hat
        else:
            fhat[k] = fhat[k - 1]
    cpu = time.thread_time_ns() - c0
    return fhat, ns, cpu, st, {"adapt_active_steps": int(np.count_nonzero(adapt)),
                               "reanchor_steps": int(np.count_nonzero(anchor)),
                               "delay_switches": pf.bank.n_switch,
                               "delay_switches_steady": pf.bank.n_switch_steady,
                               "load_acquisitions": pf.load.n_acq, "load_undos": pf.load.n_undo}


def rms(a):
    return float(np.sqrt(np.mean(np.square(a))))


def summary_table(c, npy, ratio, prt=None):
    """The table of make bench; prt: pf_particles.py's figures (the particles library's PF) or None."""
    pf, ukf, mem = c["pf"], c["ukf"], c["memory_host"]
    cn, nn = pf["ns_per_particle_step"], npy["ns_per_particle_step"]
    m = pf["n_particles"]
    cc = pf["cpu_ns_per_particle_step"]["median"]
    pn = prt["ns_per_particle_step"] if prt else None
    pc = prt["cpu_ns_per_particle_step"] if prt else None
    rows = [
        ("", "C", "numpy", "particles", "ratio"),
        ("PF ns / particle-step, wall, median", "%.1f" % cn["median"], "%.1f" % nn["median"],
         "%.1f" % pn["median"] if prt else "-", "numpy / C %.2f x" % ratio
         + (", particles / C %.1f x" % (pn["median"] / cn["median"]) if prt else "")),
        ("  min .. max over replays", "%.1f .. %.1f" % (cn["min"], cn["max"]),
         "%.1f .. %.1f" % (nn["min"], nn["max"]), "%.1f .. %.1f" % (pn["min"], pn["max"]) if prt else "-",
         "%d / %d / %s replays" % (pf["reps"], npy["reps"], prt["reps"] if prt else "-")),
        ("  in thread CPU time, median", "%.1f" % cc, "%.1f" % npy["cpu_ns_per_particle_step"]["median"],
         "%.1f" % pc["median"] if prt else "-",
         "numpy / C %.2f x" % (npy["cpu_ns_per_particle_step"]["median"] / cc)
         + (", particles / C %.1f x" % (pc["median"] / cc) if prt else "")),
        ("C scalar path (pf_scalar), thread CPU", "%.1f" % c["pf_scalar"]["cpu_ns_per_particle_step"]["median"], "",
         "", "scalar / vector %.2f x" % c["ratio_pf_scalar_over_pf_cpu"]),
        ("  numpy / C scalar path, thread CPU", "", "", "",
         "%.2f x" % (npy["cpu_ns_per_particle_step"]["median"] / c["pf_scalar"]["cpu_ns_per_particle_step"]["median"])),
        ("PF step us (m = %d), per-step p50" % m, "%.1f" % pf["step_us"]["p50"], "%.1f" % npy["step_us"]["p50"], "",
         "%.2f x" % (npy["step_us"]["p50"] / pf["step_us"]["p50"])),
        ("  share of the %.1f ms period" % (pf["dt_s"] * 1e3), "%.1f %%" % (pf["step_us"]["p50"] * 1e-4 / pf["dt_s"]),
         "%.1f %%" % (npy["step_us"]["p50"] * 1e-4 / pf["dt_s"]), "", ""),
        ("PF F_hat RMS error vs true", "%.4f N" % pf["fhat_rms_err_N"], "%.4f N" % npy["fhat_rms_err_N"],
         "%.4f N" % prt["fhat_rms_err_N"] if prt else "-",
         "numpy identical to C %d/%d" % (npy["fhat_identical_to_c_steps"], npy["steps"])),
        ("UKF us / step, wall, median", "%.3f" % ukf["us_per_step"]["median"], "", "", ""),
        ("  min .. max over replays", "%.3f .. %.3f" % (ukf["us_per_step"]["min"], ukf["us_per_step"]["max"]), "", "",
         "%d replays" % ukf["reps"]),
        ("  in thread CPU time, median", "%.3f" % ukf["cpu_us_per_step"]["median"], "", "", ""),
        ("PF RAM, br_pf_t (host sizeof)", "%d B" % mem["pf_t_bytes"], "", "",
         "at %d particles max" % mem["pf_max_particles"]),
        ("  of which m = %d uses" % m, "%d B" % mem["pf_used_bytes_at_m"], "", "",
         "%d B/particle + %d" % (mem["pf_bytes_per_particle"], mem["pf_fixed_bytes"])),
        ("UKF RAM, br_ukf_t (host sizeof)", "%d B" % mem["ukf_t_bytes"], "", "", ""),
        ("PF ROM, noise table", "%d B" % mem["noise_table_rom_bytes"], "", "", "%d float32" % mem["noise_len"]),
    ]
    rows += [("PF cost vs m: m = %d, CPU ns / particle-step" % r["m"], "%.1f" % r["pf"], "", "",
              "scalar %.1f" % r["pf_scalar"]) for r in c["pf_scaling"]["rows"]]
    rows += [("demo run (two axes, 8 s), CPU s: %s" % k, "%.3f" % v, "", "", "") for k, v in c["demo_cpu_s"].items()]
    w = [max(len(r[i]) for r in rows) for i in range(5)]
    print("== bench summary: %s, %d CPUs; C %s; numpy %s float32%s"
          % (c["machine"]["cpu_model"], c["machine"]["cpus_online"], c["machine"]["build"], npy["numpy"],
             "; %s float64" % prt["library"] if prt else ""))
    for r in rows:
        print("  %-*s  %*s  %*s  %*s  %s" % (w[0], r[0], w[1], r[1], w[2], r[2], w[3], r[3], r[4]))
    print("  load average (1 min) at start / end: C %.2f / %.2f, numpy %.2f / %.2f%s (%d CPUs: above ~0.5 the host "
          "is shared and the timings are noisy)" % (c["machine"]["loadavg1_start"], c["machine"]["loadavg1_end"],
                                                     npy["loadavg1_start"], npy["loadavg1_end"],
                                                     ", particles %.2f / %.2f" % (prt["loadavg1_start"],
                                                                                  prt["loadavg1_end"]) if prt else "",
                                                     c["machine"]["cpus_online"]))


def write_json(path, obj):
    """The bench's JSON outputs: indented, one trailing newline."""
    with open(path, "w") as f:
        json.dump(obj, f, indent=2)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("recording")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--c-json")
    ap.add_argument("--out")
    ap.add_argument("--particles-json")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 unless F_hat equals the C filter's at every step (bit for bit)")
    a = ap.parse_args()
    if a.reps < 1:
        ap.error("--reps must be >= 1")

    cfg, rec = load_recording(a.recording)
    noise = gen_noise.table(int(cfg["noise_len"]))
    h = "%016x" % fnv1a64(noise.astype("<f4").tobytes())
    if h != cfg["noise_fnv1a64"]:
        sys.exit("pf_numpy: gen_noise.table() (hash %s) differs from the C table (%s)" % (h, cfg["noise_fnv1a64"]))
    m = int(cfg["n_particles"])
    n = len(rec["k"])

    load0 = os.getloadavg()[0]
    replay(cfg, noise, rec, n_steps=min(200, n))   # warm-up
    per_rep, per_rep_cpu, lat, fhat = [], [], [], None
    for _ in range(a.reps):
        fhat, ns, cpu, st, paths = replay(cfg, noise, rec)
        per_rep.append(float(ns.sum()) / ((n - 1) * m))
        per_rep_cpu.append(cpu / ((n - 1) * m))
        lat.append(ns)
    med = statistics.median(per_rep)
    lat = np.concatenate(lat)
    true, fc = rec["fnl_true_N"], rec["fhat_c_N"]
    diff = fhat[1:].astype(F).astype(float) - fc[1:].astype(F).astype(float)
    same = int(np.count_nonzero(fhat.astype(F) == fc.astype(F)))
    res = {
        "dtype": "float32",
        "numpy": np.__version__,
        "python": platform.python_version(),
        "loadavg1_start": load0,
        "loadavg1_end": os.getloadavg()[0],
        "steps_timed": n - 1,
        "n_particles": m,
        "reps": a.reps,
        "ns_per_particle_step": {"median": med, "min": min(per_rep), "max": max(per_rep), "per_rep": per_rep},
        "cpu_ns_per_particle_step": {"median": statistics.median(per_rep_cpu), "min": min(per_rep_cpu),
                                     "max": max(per_rep_cpu)},
        "step_us": {"median_rep_mean": med * m * 1e-3, "p50": float(np.percentile(lat, 50)) * 1e-3,
                    "p99": float(np.percentile(lat, 99)) * 1e-3, "max": float(lat.max()) * 1e-3},
        "fhat_rms_err_N": rms(fhat[1:] - true[1:]),
        "fhat_c_rms_err_N": rms(fc[1:] - true[1:]),
        "fhat_vs_c_rms_N": rms(diff),
        "fhat_vs_c_max_N": float(np.max(np.abs(diff))),
        "fhat_identical_to_c_steps": same,
        "steps": n,
        "outlier_steps": int(np.count_nonzero(st == BR_W_OUTLIER)),
        "adapt_active_steps": paths["adapt_active_steps"],
        "reanchor_steps": paths["reanchor_steps"],
        "delay_switches": paths["delay_switches"],
        "delay_switches_steady": paths["delay_switches_steady"],
        "delay_id_steady_phase": cfg["delay_id"]["steady_after_s"] > 0.0,
        "load_acquisitions": paths["load_acquisitions"],
        "load_undos": paths["load_undos"],
        "error_steps": int(np.count_nonzero((st != BR_OK) & (st != BR_W_OUTLIER))),
    }
    print("PF  numpy (float32, vectorised over particles, numpy %s): %.1f ns per particle-step "
          "(median of %d replays of %d steps; min %.1f, max %.1f)"
          % (np.__version__, med, a.reps, n - 1, min(per_rep), max(per_rep)))
    cc = res["cpu_ns_per_particle_step"]
    print("    in thread CPU time: %.1f ns per particle-step (min %.1f, max %.1f)" % (cc["median"], cc["min"], cc["max"]))
    print("    one step %.1f us (median replay); per-step p50 %.1f us, p99 %.1f us, max %.1f us"
          % (res["step_us"]["median_rep_mean"], res["step_us"]["p50"], res["step_us"]["p99"], res["step_us"]["max"]))
    print("    tracks: F_hat RMS error vs true friction %.4f N (C: %.4f N); %d outlier, %d error steps"
          % (res["fhat_rms_err_N"], res["fhat_c_rms_err_N"], res["outlier_steps"], res["error_steps"]))
    print("    F_hat identical to the C filter's (bit for bit) at %d of %d steps; numpy - C: RMS %.2e N, max %.2e N"
          % (same, n, res["fhat_vs_c_rms_N"], res["fhat_vs_c_max_N"]))
    print("    cfg.adapt's noise factor above 1 after %d of %d steps; %d re-anchoring steps; %d switches of the "
          "identified delay (%d in its steady phase)" % (paths["adapt_active_steps"], n, paths["reanchor_steps"],
                                                         paths["delay_switches"], paths["delay_switches_steady"]))
    if pf_cfg_load_on(cfg):
        print("    cfg.load: %d re-acquisitions as a load change, %d of them undone"
              % (paths["load_acquisitions"], paths["load_undos"]))
    if same != n:
        print("pf_numpy: %s: the numpy PF is not bit-identical to the C one%s"
              % (("error", "") if a.check else ("warning", " (timing still valid if it tracks)")), file=sys.stderr)
    # a filter that does not track is not worth timing
    tracks = res["error_steps"] == 0 and res["fhat_rms_err_N"] < 2.0 * res["fhat_c_rms_err_N"] + 0.05
    if not tracks:
        print("pf_numpy: the numpy PF does not track like the C one", file=sys.stderr)
    ok = tracks and (same == n or not a.check)

    if a.c_json:
        with open(a.c_json) as f:
            c = json.load(f)
        ratio = med / c["pf"]["ns_per_particle_step"]["median"]
        prt = None
        if a.particles_json:
            with open(a.particles_json) as f:
                prt = json.load(f)
        summary_table(c, res, ratio, prt)
        if a.out:
            out = dict(c)
            out["pf_numpy"] = res
            out["ratio_numpy_over_c"] = ratio
            out["ratio_numpy_over_c_cpu"] = (res["cpu_ns_per_particle_step"]["median"]
                                             / c["pf"]["cpu_ns_per_particle_step"]["median"])
            if prt:
                out["pf_particles"] = prt
                out["ratio_particles_over_c_cpu"] = (prt["cpu_ns_per_particle_step"]["median"]
                                                     / c["pf"]["cpu_ns_per_particle_step"]["median"])
            write_json(a.out, out)
    elif a.out:
        write_json(a.out, res)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
