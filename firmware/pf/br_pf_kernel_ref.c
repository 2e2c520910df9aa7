/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's reference kernel (br_pf_kernel.h): plain C99, no
 * target specifics, one particle after the other with branches. Every other
 * kernel gives its results bit for bit (test_pf_kernels); the scalar
 * reference path (cfg.scalar_path) runs it on every target, and targets
 * without a kernel of their own run it as theirs (br_pf_kernel_port.c). The
 * equations and their bounds: docs/modules/pf.md. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "br_inline.h"
#include "br_math.h"
#include "br_pf_kernel.h"

/* g_p limited to [lo, hi] by selects (fmaxf / fminf are library calls on
 * some targets): br_clampf's result for every input, 0 < lo < hi finite
 * (br_est.c); a NaN gives lo, as fmaxf */
static inline float clamp_gp(float v, float lo, float hi)
{
    const float a = (v > lo) ? v : lo;
    return (a < hi) ? a : hi;
}

uint32_t br_pf_kref_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                            br_pf_lsum_t *ls)
{
    /* the pass's constants and sums in locals (the arrays' stores cannot
     * change them), the arrays by restrict pointers (they never overlap) */
    const br_model_kp_t kp = c->kp;
    const br_model_k_t mk = c->mk;
    const float s0L = c->s0L, q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    const int n_sub = c->n_sub;
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT zz = pf->x[BR_X_Z] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    float *BR_RESTRICT fo = pf->fnl + j0;
    float *BR_RESTRICT lo = pf->l + j0;
    const uint32_t n = j1 - j0;
    float lmax = ls->lmax, s1 = ls->s1, s2 = ls->s2;
    uint32_t left = 0u;
    for (uint32_t j = 0; j < n; j++) {
        const float *const nj = nz + BR_NX * j;
        const float x[BR_NX] = {th[j], om[j], zz[j], gg[j]};
        float xn[BR_NX];
        /* 1. predict: eq. 6 by RK4 with the particle's k_p in n_sub sub-steps
         * (br_model_kp_rk4_n); ok_rk = 0 beyond the RK4 limit a h <= 2 in any
         * sub-step (the bounded scheme: the fix-up) */
        const int ok_rk = br_model_kp_rk4_n(&kp, n_sub, x, ka[j], xn);
        /* process noise sqrt(Q) n; theta relative to the new origin */
        const float t = (xn[BR_X_THETA] + q0 * nj[0]) - shift;
        const float w = xn[BR_X_OMEGA] + q1 * nj[1];
        const float z = xn[BR_X_Z] + q2 * nj[2];
        const float g = clamp_gp(xn[BR_X_GP] + q3 * nj[3], gp_min, gp_max);
        /* the particle's one division, k_p = sigma0 L / g_p */
        const float kg = s0L / g;
        /* f_nl of the predicted particle (eqs. 3, 4) */
        const float f = br_pf_fnl_kp(&mk, w, z, kg);
        /* 2. Gaussian log-likelihood, l = -(theta - y)^2 / (2 R) (<= -0, or -inf) */
        const float e = t - y_rel;
        const float l = br_pf_loglik(e, inv_2r);
        /* cfg.adapt's sums of the innovation, every particle in order */
        s1 += e;
        s2 += e * e;
        /* validity: x - x is 0 for finite x and NaN otherwise; theta and f_nl
         * tell all four states (g_p is finite after the clamp, a non-finite
         * omega or z makes f_nl non-finite) */
        if (!ok_rk || !((t - t) + (f - f) == 0.0f)) {
            /* left for the fix-up: the state kept, f_nl = 0, l = NaN */
            fo[j] = 0.0f;
            lo[j] = NAN;
            left++;
            continue;
        }
        th[j] = t;
        om[j] = w;
        zz[j] = z;
        gg[j] = g;
        ka[j] = kg;
        fo[j] = f;
        lo[j] = l;
        lmax = (l > lmax) ? l : lmax;
    }
    ls->lmax = lmax;
    ls->n_valid += n - left;
    ls->s1 = s1;
    ls->s2 = s2;
    return left;
}

uint32_t br_pf_kref_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                               br_pf_lsum_t *ls)
{
    const br_model_km_t km = c->km;
    const float uh = c->uh;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    const uint32_t m = pf->cfg.n_particles;
    float *const th = pf->x[BR_X_THETA], *const om = pf->x[BR_X_OMEGA], *const gg = pf->x[BR_X_GP];
    float *const ka = pf->kgp, *const ms = pf->ms;
    float lmax = ls->lmax, s1 = ls->s1, s2 = ls->s2;
    uint32_t left = 0u;
    for (uint32_t j = j0; j < j1; j++) {
        const float *const nj = nz + BR_NX * (j - j0);
        float e[BR_MSLIP_MAX], e1[BR_MSLIP_MAX];
        for (int i = 0; i < km.n; i++) {
            e[i] = ms[(uint32_t)i * m + j];
        }
        /* 1. predict: the trapezoidal step of eq. 6 with the elements (eqs. MS1, MS2) */
        float t = th[j], w = om[j];
        br_pf_ms_det(&km, uh, &t, &w, gg[j], ka[j], e, e1);
        /* process noise sqrt(Q) n; theta relative to the new origin */
        t = (t + q0 * nj[0]) - shift;
        w = w + q1 * nj[1];
        const float g = clamp_gp(gg[j] + q3 * nj[3], gp_min, gp_max);
        /* z's sample moves every element, clamped at the new g_p; f_nl = sum k_i e_i (eqs. MS1, MS2) */
        const float f = br_pf_ms_noise(&km, e1, q2 * nj[2], g);
        /* 2. Gaussian log-likelihood, l = -(theta - y)^2 / (2 R) */
        const float e_th = t - y_rel;
        const float l = br_pf_loglik(e_th, inv_2r);
        s1 += e_th;
        s2 += e_th * e_th;
        /* validity: theta, omega and f_nl finite (f_nl does not depend on
         * omega here; the elements are finite after the clamps) */
        if (!((t - t) + (w - w) + (f - f) == 0.0f)) {
            pf->fnl[j] = 0.0f;
            pf->l[j] = NAN;
            left++;
            continue;
        }
        th[j] = t;
        om[j] = w;
        gg[j] = g;
        ka[j] = f;
        for (int i = 0; i < km.n; i++) {
            ms[(uint32_t)i * m + j] = e1[i];
        }
        pf->fnl[j] = f;
        pf->l[j] = l;
        lmax = (l > lmax) ? l : lmax;
    }
    ls->lmax = lmax;
    ls->n_valid += (j1 - j0) - left;
    ls->s1 = s1;
    ls->s2 = s2;
    return left;
}

uint32_t br_pf_kref_weights(br_pf_t *pf, float lmax, int outlier)
{
    const uint32_t m = pf->cfg.n_particles;
    uint32_t total = 0u;
    if (outlier) {
        /* every valid particle w = 1 */
        for (uint32_t j = 0; j < m; j++) {
            pf->W[j] = (uint32_t)(br_pf_valid_weight(pf->l[j]) * (float)BR_PF_W_ONE);
            total += pf->W[j];
        }
    } else {
        /* 3. w_j = e^(l_j - lmax) (0 for l_j = NaN), W_j = floor(w_j 2^16):
         * the scale 2^16 built into the exponent (br_exp_neg_w16_k) */
        const br_exp_k_t k = br_exp_k();
        for (uint32_t j = 0; j < m; j++) {
            pf->W[j] = (uint32_t)br_exp_neg_w16_k(pf->l[j] - lmax, k);
            total += pf->W[j];
        }
    }
    return total;
}

/* 4. the copy in place: particle i becomes the predicted particle idx_i. The
 * indices never decrease, so a forward pass takes every particle from a
 * later one (not yet overwritten) and a backward pass every particle from an
 * earlier one (idx_k <= k there, so the forward pass left its source alone);
 * a particle with idx_i = i stays. The values move as bit patterns
 * (memcpy), the five arrays are parameters of a function of its own. */
static inline void move_particle(uint32_t i, uint32_t k, float *th, float *om, float *zz, float *gg, float *ia)
{
    memcpy(&th[i], &th[k], sizeof th[i]);
    memcpy(&om[i], &om[k], sizeof om[i]);
    memcpy(&zz[i], &zz[k], sizeof zz[i]);
    memcpy(&gg[i], &gg[k], sizeof gg[i]);
    memcpy(&ia[i], &ia[k], sizeof ia[i]);
}

/* the forward pass: i = 0 .. m - 2 (particle m - 1 has no later one) */
BR_NO_IVOPTS static void copy_fwd_soa(const uint16_t *BR_RESTRICT idx, uint32_t m, float *th, float *om,
                                           float *zz, float *gg, float *ia)
{
    const uint32_t last = m - 1u; /* m >= 1 */
    for (uint32_t i = 0u; i < last; i++) {
        const uint32_t k = idx[i];
        if (k > i) {
            move_particle(i, k, th, om, zz, gg, ia);
        }
    }
}

/* the backward pass: i = m - 1 down to 1 (particle 0 has no earlier one) */
BR_NO_IVOPTS static void copy_back_soa(const uint16_t *BR_RESTRICT idx, uint32_t m, float *th, float *om,
                                            float *zz, float *gg, float *ia)
{
    for (uint32_t i = m - 1u; i > 0u; i--) {
        const uint32_t k = idx[i];
        if (k < i) {
            move_particle(i, k, th, om, zz, gg, ia);
        }
    }
}

/* With elements: the same passes moving each particle's elements with it
 * (a[e][j]: element e of particle j); states = 0: the elements alone. Four
 * elements (the common set) moved written out, any other number by a loop. */
static inline void move_elements(uint32_t i, uint32_t k, float *const a[BR_MSLIP_MAX], int ne)
{
    if (ne == 4) {
        memcpy(&a[0][i], &a[0][k], sizeof a[0][i]);
        memcpy(&a[1][i], &a[1][k], sizeof a[1][i]);
        memcpy(&a[2][i], &a[2][k], sizeof a[2][i]);
        memcpy(&a[3][i], &a[3][k], sizeof a[3][i]);
        return;
    }
    for (int e = 0; e < ne; e++) {
        memcpy(&a[e][i], &a[e][k], sizeof a[e][i]);
    }
}

static void ms_arrays(br_pf_t *pf, float *a[BR_MSLIP_MAX])
{
    for (int e = 0; e < pf->model.cfg.mslip.n; e++) {
        a[e] = pf->ms + (uint32_t)e * pf->cfg.n_particles;
    }
}

/* the forward pass with the elements: i = 0 .. m - 2 */
BR_NO_IVOPTS static void copy_fwd_ms(br_pf_t *pf, int states)
{
    const uint32_t last = pf->cfg.n_particles - 1u;
    const int ne = pf->model.cfg.mslip.n;
    const uint16_t *BR_RESTRICT idx = pf->idx;
    float *a[BR_MSLIP_MAX];
    ms_arrays(pf, a);
    float *th = pf->x[BR_X_THETA], *om = pf->x[BR_X_OMEGA], *zz = pf->x[BR_X_Z], *gg = pf->x[BR_X_GP];
    for (uint32_t i = 0u; i < last; i++) {
        const uint32_t k = idx[i];
        if (k > i) {
            if (states) {
                move_particle(i, k, th, om, zz, gg, pf->kgp);
            }
            move_elements(i, k, a, ne);
        }
    }
}

/* the backward pass with the elements: i = m - 1 down to 1 */
BR_NO_IVOPTS static void copy_back_ms(br_pf_t *pf)
{
    const int ne = pf->model.cfg.mslip.n;
    const uint16_t *BR_RESTRICT idx = pf->idx;
    float *a[BR_MSLIP_MAX];
    ms_arrays(pf, a);
    float *th = pf->x[BR_X_THETA], *om = pf->x[BR_X_OMEGA], *zz = pf->x[BR_X_Z], *gg = pf->x[BR_X_GP];
    for (uint32_t i = pf->cfg.n_particles - 1u; i > 0u; i--) {
        const uint32_t k = idx[i];
        if (k < i) {
            move_particle(i, k, th, om, zz, gg, pf->kgp);
            move_elements(i, k, a, ne);
        }
    }
}

void br_pf_kref_copy_fwd(br_pf_t *pf)
{
    if (pf->model.cfg.mslip.n > 0) {
        copy_fwd_ms(pf, 1);
        return;
    }
    copy_fwd_soa(pf->idx, pf->cfg.n_particles, pf->x[BR_X_THETA], pf->x[BR_X_OMEGA], pf->x[BR_X_Z],
                 pf->x[BR_X_GP], pf->kgp);
}

void br_pf_kref_copy_back(br_pf_t *pf)
{
    if (pf->model.cfg.mslip.n > 0) {
        copy_back_ms(pf);
        return;
    }
    copy_back_soa(pf->idx, pf->cfg.n_particles, pf->x[BR_X_THETA], pf->x[BR_X_OMEGA], pf->x[BR_X_Z],
                  pf->x[BR_X_GP], pf->kgp);
}

void br_pf_kref_copy_ms_fwd(br_pf_t *pf) { copy_fwd_ms(pf, 0); }

float br_pf_kref_resample(br_pf_t *pf, float lmax, int outlier)
{
    const uint32_t total = br_pf_kref_weights(pf, lmax, outlier);
    const float sf = br_pf_select(pf, total);
    br_pf_kref_copy_fwd(pf);
    br_pf_kref_copy_back(pf);
    return sf;
}
