/* SPDX-License-Identifier: Apache-2.0 */
/* Inline kernel of the eq. 6 model's RK4 step (private to the firmware).
 *
 * br_model_step and the particle filter's prediction loop both step through
 * these functions. The model's constants are copied once into a local
 * br_model_k_t, so that after inlining they sit in FPU registers for the whole
 * particle loop (a pointer into br_model_t would be reloaded after every store
 * to the particle arrays, both being float). The operations and their order
 * are those of eqs. 3, 4 and 6 as documented in docs/modules/model.md; with
 * -ffp-contract=off every caller gets bit-identical results.
 * Only the RK4 path lives here; the bounded scheme stays out of line. */
#ifndef BR_MODEL_KERNEL_H
#define BR_MODEL_KERNEL_H

#include <math.h>

#include "bristle/br_model.h"
#include "br_cause_terms.h"
#include "br_inline.h"
#include "br_lugre_kernel.h"
#include "br_mslip_kernel.h"

typedef struct {
    float L;        /* lead, m/rad */
    float s0;       /* sigma0, N/m */
    float s1;       /* sigma1, N s/m */
    float s0Lh;     /* sigma0 L h, for the a h test */
    float visc;     /* L^2 sigma2, N m s/rad */
    float inv_Jeff; /* 1 / (J + L^2 M) */
    float h;        /* step, s */
    float h_half;   /* h / 2 */
    float h_6;      /* h / 6 */
} br_model_k_t;

static inline br_model_k_t br_model_k(const br_model_t *m)
{
    const br_model_k_t k = {m->cfg.lead_mprad,
                            m->cfg.lugre.sigma0_Npm,
                            m->cfg.lugre.sigma1_Nspm,
                            m->cfg.lugre.sigma0_Npm * m->cfg.lead_mprad * m->h_sub_s,
                            m->visc_Nmsprad,
                            m->inv_Jeff,
                            m->h_sub_s,
                            0.5f * m->h_sub_s,
                            m->h_sub_s / 6.0f};
    return k;
}

/* eq. 4 with g = g_p: dz/dt = v - sigma0 |v| z / g_p, v = L omega */
static inline float br_model_k_zdot(const br_model_k_t *k, float omega, float z, float gp)
{
    return br_lk_zdot_mps(k->s0, k->L * omega, z, gp);
}

/* eq. 3: f_nl = sigma0 z + sigma1 dz/dt */
static inline float br_model_k_fnl(const br_model_k_t *k, float z, float zdot)
{
    return br_lk_force_N(k->s0, k->s1, z, zdot);
}

/* eq. 6: domega/dt = (u - L^2 sigma2 omega - L f_nl) / Jeff */
static inline float br_model_k_omega_dot(const br_model_k_t *k, float omega, float fnl, float u)
{
    return (u - k->visc * omega - k->L * fnl) * k->inv_Jeff;
}

/* a h = sigma0 L |omega| h / g_p <= BR_MODEL_RK4_AH_MAX, without a division */
static inline int br_model_k_rk4_ok(const br_model_k_t *k, float omega, float gp)
{
    return k->s0Lh * fabsf(omega) <= BR_MODEL_RK4_AH_MAX * gp;
}

/* Classic RK4 on eq. 6 over h with u held (br_model_step's). theta does not
 * enter the right-hand side and g_p' = 0, so the stages carry (omega, z) only:
 * theta' of a stage is its omega, and g_p comes out unchanged.
 * Returns 1 when a h is inside the RK4 limit at both ends of the step and
 * at its stages (the result is then the step), 0 when the caller must use
 * the bounded scheme instead: a step from rest under a large torque passes
 * through speeds far beyond the limit, where RK4 diverges, and can still
 * end at a small omega (docs/modules/model.md). */
BR_INLINE int br_model_k_rk4(const br_model_k_t *k, const float x[BR_NX], float u, float out[BR_NX])
{
    const float w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    /* stage 1 at x */
    const float zd1 = br_model_k_zdot(k, w0, z0, gp);
    const float wd1 = br_model_k_omega_dot(k, w0, br_model_k_fnl(k, z0, zd1), u);
    /* stage 2 at x + h/2 k1 */
    const float w2 = w0 + k->h_half * wd1, z2 = z0 + k->h_half * zd1;
    const float zd2 = br_model_k_zdot(k, w2, z2, gp);
    const float wd2 = br_model_k_omega_dot(k, w2, br_model_k_fnl(k, z2, zd2), u);
    /* stage 3 at x + h/2 k2 */
    const float w3 = w0 + k->h_half * wd2, z3 = z0 + k->h_half * zd2;
    const float zd3 = br_model_k_zdot(k, w3, z3, gp);
    const float wd3 = br_model_k_omega_dot(k, w3, br_model_k_fnl(k, z3, zd3), u);
    /* stage 4 at x + h k3 */
    const float w4 = w0 + k->h * wd3, z4 = z0 + k->h * zd3;
    const float zd4 = br_model_k_zdot(k, w4, z4, gp);
    const float wd4 = br_model_k_omega_dot(k, w4, br_model_k_fnl(k, z4, zd4), u);
    /* x + h/6 (k1 + 2 k2 + 2 k3 + k4) */
    out[BR_X_THETA] = x[BR_X_THETA] + k->h_6 * (w0 + 2.0f * w2 + 2.0f * w3 + w4);
    out[BR_X_OMEGA] = w0 + k->h_6 * (wd1 + 2.0f * wd2 + 2.0f * wd3 + wd4);
    out[BR_X_Z] = z0 + k->h_6 * (zd1 + 2.0f * zd2 + 2.0f * zd3 + zd4);
    out[BR_X_GP] = gp;
    /* the ends and the stages; & rather than &&: no branch */
    return br_model_k_rk4_ok(k, w0, gp) & br_model_k_rk4_ok(k, w2, gp) & br_model_k_rk4_ok(k, w3, gp) &
           br_model_k_rk4_ok(k, w4, gp) & br_model_k_rk4_ok(k, out[BR_X_OMEGA], gp);
}

/* ---- The particle filter's RK4 with k_p ----
 * The same classic RK4 of eq. 6 over h with u held, in the form with the
 * fewest operations per stage: each particle carries k_p = sigma0 L / g_p
 * (its one division, made when g_p changes), and the constants are folded:
 *   eq. 4:          dz/dt     = L omega - k_p |omega| z            (L > 0)
 *   eqs. 3, 6:      domega/dt = u/Jeff - (L^2 sigma2/Jeff) omega
 *                               - (L sigma0/Jeff) z - (L sigma1/Jeff) dz/dt
 *   combination:    x + (h/6 (k1 + k4) + h/3 (k2 + k3))
 *   RK4 limit:      a h = k_p |omega| h <= 2  <=>  k_p |omega| <= 2 / h.
 * It rounds differently from br_model_k_rk4 (an ulp or so per operation), so
 * the PF's tuned variances belong to it (docs/modules/pf.md). */
typedef struct {
    float L;      /* lead, m/rad */
    float a;      /* u / Jeff */
    float cw;     /* L^2 sigma2 / Jeff */
    float cz;     /* L sigma0 / Jeff */
    float czd;    /* L sigma1 / Jeff */
    float h, h_half, h_6, h_3;
    float ah_lim; /* BR_MODEL_RK4_AH_MAX / h */
} br_model_kp_t;

/* the constants for a step with torque u */
static inline br_model_kp_t br_model_kp(const br_model_t *m, float u)
{
    const float L = m->cfg.lead_mprad, ij = m->inv_Jeff, h = m->h_sub_s;
    const br_model_kp_t k = {L,
                             u * ij,
                             m->visc_Nmsprad * ij,
                             (L * m->cfg.lugre.sigma0_Npm) * ij,
                             (L * m->cfg.lugre.sigma1_Nspm) * ij,
                             h,
                             0.5f * h,
                             h / 6.0f,
                             h / 3.0f,
                             BR_MODEL_RK4_AH_MAX / h};
    return k;
}

/* k_p = sigma0 L / g_p of a particle: the step's one division */
static inline float br_model_kp_of(const br_model_t *m, float gp)
{
    return (m->cfg.lugre.sigma0_Npm * m->cfg.lead_mprad) / gp;
}

/* eq. 4 with k_p: L omega - k_p |omega| z */
static inline float br_model_kp_zdot(float L, float kp, float omega, float z)
{
    return L * omega - (kp * fabsf(omega)) * z;
}

/* RK4 of the particle (theta, omega, z, g_p) with its k_p, without the
 * a h test: *ah0, *ah1 get k_p |omega| at both ends of the step (the test's
 * products, a h / h; br_model_kp_rk4 makes the test) */
static inline void br_model_kp_rk4_step(const br_model_kp_t *k, const float x[BR_NX], float kp, float out[BR_NX],
                                    float *ah0, float *ah1)
{
    const float L = k->L, hh = k->h_half;
    const float w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z];
    /* stage 1 at x */
    const float kw1 = kp * fabsf(w0);
    const float zd1 = L * w0 - kw1 * z0;
    const float wd1 = ((k->a - k->cw * w0) - k->cz * z0) - k->czd * zd1;
    /* stage 2 at x + h/2 k1 */
    const float w2 = w0 + hh * wd1, z2 = z0 + hh * zd1;
    const float zd2 = br_model_kp_zdot(L, kp, w2, z2);
    const float wd2 = ((k->a - k->cw * w2) - k->cz * z2) - k->czd * zd2;
    /* stage 3 at x + h/2 k2 */
    const float w3 = w0 + hh * wd2, z3 = z0 + hh * zd2;
    const float zd3 = br_model_kp_zdot(L, kp, w3, z3);
    const float wd3 = ((k->a - k->cw * w3) - k->cz * z3) - k->czd * zd3;
    /* stage 4 at x + h k3 */
    const float w4 = w0 + k->h * wd3, z4 = z0 + k->h * zd3;
    const float zd4 = br_model_kp_zdot(L, kp, w4, z4);
    const float wd4 = ((k->a - k->cw * w4) - k->cz * z4) - k->czd * zd4;
    /* x + (h/6 (k1 + k4) + h/3 (k2 + k3)) */
    out[BR_X_THETA] = x[BR_X_THETA] + (k->h_6 * (w0 + w4) + k->h_3 * (w2 + w3));
    out[BR_X_OMEGA] = w0 + (k->h_6 * (wd1 + wd4) + k->h_3 * (wd2 + wd3));
    out[BR_X_Z] = z0 + (k->h_6 * (zd1 + zd4) + k->h_3 * (zd2 + zd3));
    out[BR_X_GP] = x[BR_X_GP];
    *ah0 = kw1;
    *ah1 = kp * fabsf(out[BR_X_OMEGA]);
}

/* RK4 of the particle (theta, omega, z, g_p) with its k_p; returns 1 when
 * a h is inside the RK4 limit at both ends of the step (the particle
 * filter's test: the ends only, its kernels and tuned variances are its own;
 * br_model_k_rk4 tests the stages too) */
static inline int br_model_kp_rk4(const br_model_kp_t *k, const float x[BR_NX], float kp, float out[BR_NX])
{
    float ah0, ah1;
    br_model_kp_rk4_step(k, x, kp, out, &ah0, &ah1);
    return (ah0 <= k->ah_lim) && (ah1 <= k->ah_lim);
}

/* n sub-steps of br_model_kp_rk4 (n = the model's n_sub; docs/modules/model.md,
 * "Sub-steps"); returns 1 when every sub-step is inside the RK4 limit. x may
 * not be out. */
static inline int br_model_kp_rk4_n(const br_model_kp_t *k, int n, const float x[BR_NX], float kp, float out[BR_NX])
{
    int ok = br_model_kp_rk4(k, x, kp, out);
    for (int s = 1; s < n; s++) {
        const float xs[BR_NX] = {out[0], out[1], out[2], out[3]};
        ok &= br_model_kp_rk4(k, xs, kp, out);
    }
    return ok;
}

/* ---- The extended model (causes on; docs/modules/model.md, "Extended model") ----
 * Its own constants and stages, so that the thesis model's kernel above keeps
 * its operations (and its results, bit for bit) when no cause is on. theta is
 * relative to an origin at load position p0 (the estimators' integer count
 * origin); the ripple's sine is taken once per step at p0 and expanded to
 * third order in the phase advance d = 2 pi L theta / P of each stage
 * (|error| <= d^4 / 24 of A: 4e-4 A for a move of 5 % of the period from the
 * origin, far more than a particle moves between two measurements). */
typedef struct {
    br_model_k_t n;  /* the thesis model's constants */
    float p0;        /* load position of theta = 0, m */
    float c_neg;     /* Stribeck level factor in -x, (Fc + dFc_neg) / Fc */
    float c_min;     /* min(c_neg, 1): the a h test's smallest level per g_p */
    float s2;        /* sigma2 */
    float s2_neg;    /* sigma2 + dsigma2_neg */
    float off;       /* offset, N */
    float grad;      /* gradient, 1/m */
    float ks;        /* friction_drift: s(t) = max(0, 1 + drift t) at the model's clock (1 without) */
    float kL;        /* 2 pi L / P: ripple phase per radian of theta (0 without ripple) */
    float rs, rc;    /* A sin(phi0), A cos(phi0), phi0 = 2 pi p0 / P + phase */
} br_model_kx_t;

static inline br_model_kx_t br_model_kx(const br_model_t *m, float p0_m)
{
    const br_causes_t *c = &m->cfg.causes;
    br_model_kx_t k;
    k.n = br_model_k(m);
    k.p0 = p0_m;
    k.c_neg = m->c_neg;
    k.c_min = fminf(m->c_neg, 1.0f);
    k.s2 = m->cfg.sigma2_Nspm;
    k.s2_neg = m->sigma2_neg_Nspm;
    k.off = c->offset_N;
    k.grad = c->grad_per_m;
    k.ks = m->drift_k;
    k.kL = m->ripple_k_radpm * m->cfg.lead_mprad;
    k.rs = 0.0f;
    k.rc = 0.0f;
    if (c->ripple_amp_N != 0.0f) {
        /* the phase at p0 */
        const float phi0 = br_ct_ripple_phase_rad(m->ripple_k_radpm, c->ripple_period_m, c->ripple_phase_rad, p0_m);
        k.rs = br_ct_ripple_N(c->ripple_amp_N, phi0);
        k.rc = c->ripple_amp_N * cosf(phi0);
    }
    return k;
}

/* ripple A sin(phi0 + d), d = 2 pi L theta / P: sin(phi0) (1 - d^2/2) + cos(phi0) d (1 - d^2/6) */
static inline float br_model_kx_ripple_N(const br_model_kx_t *k, float th)
{
    const float d = k->kL * th;
    const float d2 = d * d;
    return k->rs * (1.0f - 0.5f * d2) + k->rc * d * (1.0f - 0.166666672f * d2);
}

/* The load force of the extended model at (theta, omega, z, g_p), N, and the
 * bristle rate in *zd: eq. 4 with the level c g_p moving towards -x (v < 0),
 * eq. 3, then
 * k(p) s(t) (sigma2_d v + f_nl) + offset + ripple, k(p) = max(0, 1 + grad p),
 * s(t) = max(0, 1 + drift t) held over the step (the model's clock). */
static inline float br_model_kx_load_N(const br_model_kx_t *k, float th, float w, float z, float gp, float *zd)
{
    const float v = k->n.L * w;
    const int neg = v < 0.0f;
    /* the level by the direction of motion, as the Stribeck curve g(v) of
     * eq. 5 and the plant: continuous through a reversal, where v crosses 0
     * and the level's term sigma0 |v| z / g vanishes */
    *zd = br_lk_zdot_mps(k->n.s0, v, z, br_ct_asym_level_N(gp, k->c_neg, neg));
    const float f = br_lk_force_N(k->n.s0, k->n.s1, z, *zd);
    const float kp = br_ct_lin_scale(k->grad, k->p0 + k->n.L * th) * k->ks;
    return br_ct_scaled_load_N(kp, br_ct_asym_sigma2_Nspm(k->s2, k->s2_neg, neg) * v + f, k->off) +
           br_model_kx_ripple_N(k, th);
}

/* The force to compensate: the load force without the nominal viscous term */
static inline float br_model_kx_fcomp_N(const br_model_kx_t *k, const float x[BR_NX])
{
    float zd;
    const float F = br_model_kx_load_N(k, x[BR_X_THETA], x[BR_X_OMEGA], x[BR_X_Z], x[BR_X_GP], &zd);
    return F - k->s2 * (k->n.L * x[BR_X_OMEGA]);
}

/* a h <= BR_MODEL_RK4_AH_MAX with the smaller of the two direction levels */
static inline int br_model_kx_rk4_ok(const br_model_kx_t *k, float omega, float gp)
{
    return k->n.s0Lh * fabsf(omega) <= BR_MODEL_RK4_AH_MAX * (k->c_min * gp);
}

/* Classic RK4 of the extended model over h with u held; theta enters the
 * right-hand side (ripple, gradient), so the stages carry it. Returns 1 when
 * a h is inside the RK4 limit at both ends and at the stages (as
 * br_model_k_rk4). */
static inline int br_model_kx_rk4(const br_model_kx_t *k, const float x[BR_NX], float u, float out[BR_NX])
{
    const float L = k->n.L, ij = k->n.inv_Jeff, hh = k->n.h_half;
    const float t0 = x[BR_X_THETA], w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    float zd1, zd2, zd3, zd4;
    /* stage 1 at x */
    const float wd1 = (u - L * br_model_kx_load_N(k, t0, w0, z0, gp, &zd1)) * ij;
    /* stage 2 at x + h/2 k1 */
    const float t2 = t0 + hh * w0, w2 = w0 + hh * wd1, z2 = z0 + hh * zd1;
    const float wd2 = (u - L * br_model_kx_load_N(k, t2, w2, z2, gp, &zd2)) * ij;
    /* stage 3 at x + h/2 k2 */
    const float t3 = t0 + hh * w2, w3 = w0 + hh * wd2, z3 = z0 + hh * zd2;
    const float wd3 = (u - L * br_model_kx_load_N(k, t3, w3, z3, gp, &zd3)) * ij;
    /* stage 4 at x + h k3 */
    const float t4 = t0 + k->n.h * w3, w4 = w0 + k->n.h * wd3, z4 = z0 + k->n.h * zd3;
    const float wd4 = (u - L * br_model_kx_load_N(k, t4, w4, z4, gp, &zd4)) * ij;
    /* x + h/6 (k1 + 2 k2 + 2 k3 + k4) */
    out[BR_X_THETA] = t0 + k->n.h_6 * (w0 + 2.0f * w2 + 2.0f * w3 + w4);
    out[BR_X_OMEGA] = w0 + k->n.h_6 * (wd1 + 2.0f * wd2 + 2.0f * wd3 + wd4);
    out[BR_X_Z] = z0 + k->n.h_6 * (zd1 + 2.0f * zd2 + 2.0f * zd3 + zd4);
    out[BR_X_GP] = gp;
    return br_model_kx_rk4_ok(k, w0, gp) && br_model_kx_rk4_ok(k, w2, gp) && br_model_kx_rk4_ok(k, w3, gp) &&
           br_model_kx_rk4_ok(k, w4, gp) && br_model_kx_rk4_ok(k, out[BR_X_OMEGA], gp);
}

/* The bounded schemes of br_model_step (out of line: not reached at circle
 * speeds), for the thesis model and for the extended one. */
void br_model_bounded_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float out[BR_NX]);
void br_model_bounded_step_x(const br_model_kx_t *k, const float x[BR_NX], float u_Nm, float out[BR_NX]);

/* One step of dt_s as m->n_sub sub-steps of h_sub_s (docs/modules/model.md,
 * "Sub-steps"), each by RK4 inside its a h limit, else by the bounded scheme:
 * the extended model's (kx) when kx is given, else the PF's form with k_p
 * (kp, the particle's kp_p) when kp is given, else br_model_k_rk4's. out
 * must not be x. */
void br_model_sub_steps(const br_model_t *m, const br_model_kx_t *kx, const br_model_kp_t *kp, float kp_p,
                        const float x[BR_NX], float u_Nm, float out[BR_NX]);

/* ---- The Maxwell-slip model's step (docs/modules/model.md, "Maxwell-slip model") ----
 * x = [theta, omega, (unused), g_p] and the element deflections z[0..n-1]:
 *   f0 = sum k_i z_i
 *   pass p = 1..BR_MODEL_MS_PASSES (from omega_m = omega0):
 *     dtheta = omega_m h;  z1_i = clamp(z_i + L dtheta, -c_i g_p, c_i g_p);  f1 = sum k_i z1_i
 *     eq. 6 by the trapezoidal rule: Jeff (omega1 - omega0) = u h - L^2 sigma2 dtheta - L h (f0 + f1) / 2
 *     omega_m = (omega0 + omega1) / 2
 * z1 must not be z (the passes read z). */
typedef struct {
    float L;        /* lead, m/rad */
    float visc;     /* L^2 sigma2 */
    float inv_Jeff; /* 1 / (J + L^2 M) */
    float h;        /* step, s */
    float Lh_half;  /* L h / 2 */
    int n;          /* elements */
    const float *k; /* stiffness, N/m */
    const float *c; /* share / k, m/N */
} br_model_km_t;

static inline br_model_km_t br_model_km(const br_model_t *m)
{
    const br_model_km_t k = {m->cfg.lead_mprad, m->visc_Nmsprad, m->inv_Jeff, m->cfg.dt_s,
                             0.5f * m->cfg.lead_mprad * m->cfg.dt_s, m->cfg.mslip.n, m->cfg.mslip.k_Npm,
                             m->ms_c_mpN};
    return k;
}

BR_INLINE void br_model_km_step(const br_model_km_t *k, const float x[BR_NX], const float z[], float u,
                                float out[BR_NX], float z1[])
{
    const float w0 = x[BR_X_OMEGA], gp = x[BR_X_GP];
    const float f0 = br_msk_force(k->n, k->k, z);
    const float uh = u * k->h;
    float wm = w0, w1 = w0, dth = 0.0f;
    int pass;
    for (pass = 0; pass < BR_MODEL_MS_PASSES; pass++) {
        dth = wm * k->h;
        /* the elements along the travel L dtheta, clamped at c_i g_p */
        const float f1 = br_msk_move(k->n, k->k, k->c, z, z1, k->L * dth, gp);
        /* eq. 6, trapezoidal: Jeff (w1 - w0) = u h - L^2 sigma2 dtheta - L h (f0 + f1) / 2 */
        w1 = w0 + (uh - k->visc * dth - k->Lh_half * (f0 + f1)) * k->inv_Jeff;
        wm = 0.5f * (w0 + w1);
    }
    out[BR_X_THETA] = x[BR_X_THETA] + dth;
    out[BR_X_OMEGA] = w1;
    out[BR_X_Z] = x[BR_X_Z];
    out[BR_X_GP] = gp;
}

#endif
