/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's kernel for hosts with float SIMD (x86-64 SSE2 and
 * up, AArch64 NEON; br_pf_kernel.h): the reference kernel's operations in
 * loops without branches, which GCC vectorises (firmware/CMakeLists.txt:
 * -ftree-vectorize -fvect-cost-model=dynamic), and a resampling that counts
 * instead of searching. The equations, the bounds of the counting and the
 * assumptions it rests on: docs/modules/pf.md, "Kernels". Same results as
 * the reference, bit for bit (test_pf_kernels). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "br_inline.h"
#include "br_math.h"
#include "br_pf_kernel.h"

uint32_t br_pf_kernel_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                              br_pf_lsum_t *ls)
{
    const br_model_kp_t kp = c->kp;
    /* f_nl's L taken from kp (the same value) */
    br_model_k_t mk = c->mk;
    mk.L = kp.L;
    const float s0L = c->s0L;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT zz = pf->x[BR_X_Z] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    float *BR_RESTRICT fo = pf->fnl + j0;
    float *BR_RESTRICT lo = pf->l + j0;
    const float *BR_RESTRICT nn = nz;
    const size_t n = j1 - j0;
    /* the largest log-weight as the smallest int32 key (below) */
    int32_t kmin = INT32_MAX;
    uint32_t n_ok = 0u;
    float s1 = ls->s1, s2 = ls->s2;
    for (size_t j = 0; j < n; j++) {
        const float x[BR_NX] = {th[j], om[j], zz[j], gg[j]};
        float xn[BR_NX];
        /* 1. predict: RK4 of eq. 6 with the particle's k_p; ok_rk = 0 beyond
         * the RK4 limit (& rather than &&: no branch) */
        const float kg0 = ka[j];
        float ah0, ah1;
        br_model_kp_rk4_step(&kp, x, kg0, xn, &ah0, &ah1);
        const int ok_rk = (ah0 <= kp.ah_lim) & (ah1 <= kp.ah_lim);
        /* process noise sqrt(Q) n */
        const float *const nj = nn + BR_NX * j;
        const float t = (xn[BR_X_THETA] + q0 * nj[0]) - shift;
        const float w = xn[BR_X_OMEGA] + q1 * nj[1];
        const float z = xn[BR_X_Z] + q2 * nj[2];
        /* g_p's clamp by selects (a NaN gives gp_min, as fmaxf) */
        const float ga = xn[BR_X_GP] + q3 * nj[3];
        const float gl = (ga > gp_min) ? ga : gp_min;
        const float g = (gl < gp_max) ? gl : gp_max;
        /* the particle's one division, k_p = sigma0 L / g_p */
        const float kg = s0L / g;
        /* f_nl of the predicted particle (eqs. 3, 4) */
        const float f = br_pf_fnl_kp(&mk, w, z, kg);
        /* 2. Gaussian log-likelihood, l = -(theta - y)^2 / (2 R) */
        const float e = t - y_rel;
        const float l = br_pf_loglik(e, inv_2r);
        s1 += e;
        s2 += e * e;
        /* validity as the reference's; a particle that fails keeps its state
         * (selects: f_nl = 0, l = NaN) and is left for the fix-up */
        const int ok = ok_rk & ((t - t) + (f - f) == 0.0f);
        th[j] = ok ? t : x[BR_X_THETA];
        om[j] = ok ? w : x[BR_X_OMEGA];
        zz[j] = ok ? z : x[BR_X_Z];
        gg[j] = ok ? g : x[BR_X_GP];
        ka[j] = ok ? kg : kg0;
        const float lk = ok ? l : NAN;
        fo[j] = ok ? f : 0.0f;
        lo[j] = lk;
        /* the largest l by an integer min (vectorises where fmaxf does not):
         * a valid l is <= -0 (docs/modules/pf.md, "The largest log-weight"),
         * so its bit pattern as int32 is negative and orders the other way
         * round; NAN is a positive NaN, its key above every valid one */
        int32_t key;
        memcpy(&key, &lk, sizeof key);
        kmin = (key < kmin) ? key : kmin;
        n_ok += (uint32_t)ok;
    }
    ls->s1 = s1;
    ls->s2 = s2;
    if (n_ok > 0u) {
        float lm;
        memcpy(&lm, &kmin, sizeof lm);
        ls->lmax = (lm > ls->lmax) ? lm : ls->lmax;
        ls->n_valid += n_ok;
    }
    return (uint32_t)n - n_ok;
}

/* w_j = e^(l_j - lmax) for j < m, stored as their bit patterns in W */
static void exp_vec(const float *BR_RESTRICT l, uint32_t *BR_RESTRICT W, float lmax, uint32_t m)
{
    const br_exp_k_t k = br_exp_k();
    for (uint32_t j = 0; j < m; j++) {
        const float w = br_exp_neg_kb_mask(l[j] - lmax, k, 127);
        memcpy(&W[j], &w, sizeof w);
    }
}

/* The quantised weights' total: W_j = floor(w_j 2^16) of the w_j parked in
 * W as bit patterns by exp_vec (any order: an integer sum) */
static uint32_t quant_total(const uint32_t *BR_RESTRICT W, uint32_t m)
{
    uint32_t total = 0u;
    for (uint32_t j = 0; j < m; j++) {
        float w;
        memcpy(&w, &W[j], sizeof w);
        total += (uint32_t)(w * (float)BR_PF_W_ONE);
    }
    return total;
}

/* N(C) = #{i < m : t_i < C}, the number of resampling points below the
 * cumulative weight C, as a float estimate made exact by one 64-bit
 * comparison (docs/modules/pf.md, "Resampling by counting") */
static inline uint32_t n_below(uint32_t c, uint64_t two_m, uint64_t cm, float m_over_cm)
{
    const float y = (float)(int32_t)c * m_over_cm + (0.5f - 1.0f / 512.0f);
    const uint32_t e = (uint32_t)(int32_t)y;
    return e + (uint32_t)((uint64_t)(2u * e + 1u) * cm < two_m * (uint64_t)c);
}

/* The counting resampling's writes: idx[N(C_{j-1})] = j for every j with
 * copies, 0 elsewhere. floats != 0: W holds the w_j as bit patterns
 * (exp_vec), quantised here in place; otherwise the integer weights.
 * total: the sum of the W_j. */
static void resample_count(uint32_t *BR_RESTRICT W, uint32_t m, uint32_t total, uint16_t *BR_RESTRICT idx,
                           const int floats)
{
    const uint64_t two_m = 2u * (uint64_t)m, cm = total;
    const float m_over_cm = (float)m / (float)total;
    uint16_t spare = 0u; /* the write of a particle whose N(C_{j-1}) = m (no copies) */
    for (uint32_t i = 0; i < m; i++) {
        idx[i] = 0u;
    }
    uint32_t c = 0u;
    if (floats) {
        for (uint32_t j = 0; j < m; j++) {
            const uint32_t n = n_below(c, two_m, cm, m_over_cm);
            uint16_t *const dst = (n < m) ? &idx[n] : &spare;
            *dst = (uint16_t)j;
            float w;
            memcpy(&w, &W[j], sizeof w);
            const uint32_t q = (uint32_t)(w * (float)BR_PF_W_ONE);
            W[j] = q;
            c += q;
        }
    } else {
        for (uint32_t j = 0; j < m; j++) {
            const uint32_t n = n_below(c, two_m, cm, m_over_cm);
            uint16_t *const dst = (n < m) ? &idx[n] : &spare;
            *dst = (uint16_t)j;
            c += W[j];
        }
    }
}

/* After resample_count: the running maximum that makes idx, fused with the
 * forward pass of the in-place copy (the reference's backward pass follows)
 * and with step 5's sum of f_nl over the resampled set in particle order.
 * Reading x[k] at i gives the predicted value: for k >= i, position k is
 * written only at i' = k; for k < i it is never written in this pass. The
 * copies branch on the sign of idx_i - i, which changes in long runs, so the
 * branch predicts well. */
static float resample_forward(br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    uint16_t *BR_RESTRICT idx = pf->idx;
    float *BR_RESTRICT th = pf->x[BR_X_THETA];
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA];
    float *BR_RESTRICT zz = pf->x[BR_X_Z];
    float *BR_RESTRICT gg = pf->x[BR_X_GP];
    float *BR_RESTRICT ia = pf->kgp;
    const float *BR_RESTRICT fnl = pf->fnl;
    float sf = 0.0f;
    uint32_t run = 0u;
    for (uint32_t i = 0; i < m; i++) {
        const uint32_t w = idx[i];
        const uint32_t k = (w > run) ? w : run;
        run = k;
        idx[i] = (uint16_t)k;
        const float a0 = th[k], a1 = om[k], a2 = zz[k], a3 = gg[k];
        sf += fnl[k];
        if (k > i) {
            th[i] = a0;
            om[i] = a1;
            zz[i] = a2;
            gg[i] = a3;
            ia[i] = ia[k];
        }
    }
    return sf;
}

float br_pf_kernel_resample(br_pf_t *pf, float lmax, int outlier)
{
    const uint32_t m = pf->cfg.n_particles;
    if (outlier) {
        const uint32_t total = br_pf_kref_weights(pf, lmax, 1);
        resample_count(pf->W, m, total, pf->idx, 0);
    } else {
        /* the exponentials in a loop of their own (vectorised), w parked in
         * W's storage as its bit pattern; the quantised weights' total
         * (vectorised); then the quantisation in place, in the counting loop */
        exp_vec(pf->l, pf->W, lmax, m);
        const uint32_t total = quant_total(pf->W, m);
        resample_count(pf->W, m, total, pf->idx, 1);
    }
    const float sf = resample_forward(pf);
    if (pf->model.cfg.mslip.n > 0) {
        /* the elements' forward pass (the states' is resample_forward's) */
        br_pf_kref_copy_ms_fwd(pf);
    }
    br_pf_kref_copy_back(pf);
    return sf;
}

/* Particles per block of the element path: its locals (about 1.3 KiB per
 * element) stay on the stack */
#define MS_BLOCK 64u

/* Steps 1 and 2 with elements for the particles j0 .. j0 + n - 1 (n <=
 * MS_BLOCK), the reference's operations in the same order per particle,
 * arranged as loops over the block's particles (vectorised) inside loops
 * over the elements, the particle-dependent values in block arrays. */
static uint32_t predict_ms_block(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t n, const float *nz,
                                 int32_t *kmin, float *s1p, float *s2p)
{
    const br_model_km_t km = c->km;
    const uint32_t m = pf->cfg.n_particles;
    const float uh = c->uh, h = km.h, L = km.L, visc = km.visc, Lh_half = km.Lh_half, inv_Jeff = km.inv_Jeff;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    float *BR_RESTRICT fo = pf->fnl + j0;
    float *BR_RESTRICT lo = pf->l + j0;
    const float *BR_RESTRICT nn = nz;
    float w1[MS_BLOCK], wm[MS_BLOCK], dth[MS_BLOCK], dx[MS_BLOCK], fs[MS_BLOCK], gn[MS_BLOCK], dz[MS_BLOCK];
    int ok[MS_BLOCK];
    float e1[BR_MSLIP_MAX][MS_BLOCK];
    for (uint32_t j = 0; j < n; j++) {
        wm[j] = om[j];
    }
    /* 1. predict: the trapezoidal step (eqs. MS1, MS2, 6), pass by pass */
    for (int pass = 0; pass < BR_MODEL_MS_PASSES; pass++) {
        for (uint32_t j = 0; j < n; j++) {
            dth[j] = wm[j] * h; /* dtheta = omega_m h, the travel L dtheta */
            dx[j] = L * dth[j];
            fs[j] = 0.0f;
        }
        for (int i = 0; i < km.n; i++) {
            const float ki = km.k[i], ci = km.c[i];
            const float *BR_RESTRICT e = pf->ms + (uint32_t)i * m + j0;
            float *BR_RESTRICT z1 = e1[i];
            for (uint32_t j = 0; j < n; j++) {
                /* e1_i = clamp(e_i + L dtheta, +-c_i g_p) (eq. MS1); f1 += k_i e1_i (eq. MS2) */
                z1[j] = br_pf_ms_clamp(e[j] + dx[j], ci * gg[j]);
                fs[j] += ki * z1[j];
            }
        }
        for (uint32_t j = 0; j < n; j++) {
            /* eq. 6, trapezoidal: omega1 = omega0 + (u h - L^2 s2 dtheta - L h (f0 + f1) / 2) / Jeff */
            const float w0 = om[j];
            w1[j] = w0 + (uh - visc * dth[j] - Lh_half * (ka[j] + fs[j])) * inv_Jeff;
            wm[j] = 0.5f * (w0 + w1[j]);
        }
    }
    /* process noise: theta, omega, g_p; z's sample on every element at the new g_p */
    for (uint32_t j = 0; j < n; j++) {
        const float *const nj = nn + BR_NX * j;
        const float ga = gg[j] + q3 * nj[3];
        const float gl = (ga > gp_min) ? ga : gp_min;
        gn[j] = (gl < gp_max) ? gl : gp_max;
        dz[j] = q2 * nj[2];
        fs[j] = 0.0f;
    }
    for (int i = 0; i < km.n; i++) {
        const float ki = km.k[i], ci = km.c[i];
        float *BR_RESTRICT z1 = e1[i];
        for (uint32_t j = 0; j < n; j++) {
            z1[j] = br_pf_ms_clamp(z1[j] + dz[j], ci * gn[j]);
            fs[j] += ki * z1[j];
        }
    }
    uint32_t n_ok = 0u;
    float s1 = *s1p, s2 = *s2p;
    int32_t kn = *kmin;
    for (uint32_t j = 0; j < n; j++) {
        const float *const nj = nn + BR_NX * j;
        const float t = ((th[j] + dth[j]) + q0 * nj[0]) - shift;
        const float w = w1[j] + q1 * nj[1];
        const float f = fs[j];
        /* 2. Gaussian log-likelihood */
        const float e = t - y_rel;
        const float l = br_pf_loglik(e, inv_2r);
        s1 += e;
        s2 += e * e;
        /* validity: theta, omega and f_nl finite; a particle that fails keeps its state */
        const int v = ((t - t) + (w - w) + (f - f) == 0.0f);
        ok[j] = v;
        th[j] = v ? t : th[j];
        om[j] = v ? w : om[j];
        gg[j] = v ? gn[j] : gg[j];
        ka[j] = v ? f : ka[j];
        const float lk = v ? l : NAN;
        fo[j] = v ? f : 0.0f;
        lo[j] = lk;
        /* the largest l by an integer min (the thesis path's, above) */
        int32_t key;
        memcpy(&key, &lk, sizeof key);
        kn = (key < kn) ? key : kn;
        n_ok += (uint32_t)v;
    }
    for (int i = 0; i < km.n; i++) {
        float *BR_RESTRICT e = pf->ms + (uint32_t)i * m + j0;
        const float *BR_RESTRICT z1 = e1[i];
        for (uint32_t j = 0; j < n; j++) {
            e[j] = ok[j] ? z1[j] : e[j];
        }
    }
    *kmin = kn;
    *s1p = s1;
    *s2p = s2;
    return n_ok;
}

uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls)
{
    int32_t kmin = INT32_MAX;
    uint32_t n_ok = 0u;
    float s1 = ls->s1, s2 = ls->s2;
    for (uint32_t j = j0; j < j1; j += MS_BLOCK) {
        const uint32_t n = (j1 - j < MS_BLOCK) ? j1 - j : MS_BLOCK;
        n_ok += predict_ms_block(pf, c, j, n, nz + BR_NX * (j - j0), &kmin, &s1, &s2);
    }
    ls->s1 = s1;
    ls->s2 = s2;
    if (n_ok > 0u) {
        float lm;
        memcpy(&lm, &kmin, sizeof lm);
        ls->lmax = (lm > ls->lmax) ? lm : ls->lmax;
        ls->n_valid += n_ok;
    }
    return (j1 - j0) - n_ok;
}
