/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's kernel for the Cortex-M7 (br_pf_kernel.h; FPv5
 * single precision, no float SIMD): the reference kernel's operations, with
 * what the M7 does in fewer instructions (docs/modules/pf.md, "Kernels"; docs/target.md, "What the kernels keep"):
 * fmaxf / fminf (vmaxnm / vminnm) for the g_p clamp, the a h test and the
 * largest log-weight; the a h and validity tests as one unsigned compare;
 * the exponential's roundf form (br_exp_neg_kb_rinta); the noise samples in
 * one load, f_nl and l stored with the pointer moved on and the
 * exponential's constants held in registers (br_inline.h's helpers: asm on
 * Arm, C elsewhere). The host test runs its C form (test_pf_kernels_m7).
 * Same results as the reference, bit for bit. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "br_inline.h"
#include "br_math.h"
#include "br_pf_kernel.h"
#include "br_pf_ms4.h"

uint32_t br_pf_kernel_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                              br_pf_lsum_t *ls)
{
    const br_model_kp_t kp = c->kp;
    /* f_nl's L taken from kp (the same value): one constant fewer in the loop */
    br_model_k_t mk = c->mk;
    mk.L = kp.L;
    const float s0L = c->s0L;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    uint32_t ah_lim_bits;
    memcpy(&ah_lim_bits, &kp.ah_lim, sizeof ah_lim_bits);
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT zz = pf->x[BR_X_Z] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    const size_t n = j1 - j0;
    float lm = -INFINITY; /* the largest valid l by fmaxf (one vmaxnm) */
    uint32_t n_ok = (uint32_t)n; /* less one for each particle left for the fix-up */
    float s1 = ls->s1, s2 = ls->s2;
    const float *np = nz;                 /* particle j's BR_NX = 4 samples */
    float *fp = pf->fnl + j0, *lp = pf->l + j0; /* f_nl and l, stored with the pointer moved on */
    for (size_t j = 0; j < n; j++) {
        const float x[BR_NX] = {th[j], om[j], zz[j], gg[j]};
        float xn[BR_NX];
        /* 1. predict: RK4 of eq. 6 with the particle's k_p */
        const float kg0 = ka[j];
        float ah0, ah1;
        br_model_kp_rk4_step(&kp, x, kg0, xn, &ah0, &ah1);
        /* the a h test as one compare of the larger product (vmaxnm): the
         * start's, k_p |omega_0|, is finite (a finite particle, k_p > 0), so
         * the larger is never NaN, and it is <= the limit exactly when both
         * are, unless the end's is NaN (fmaxf passes over it): then the
         * predicted omega is NaN, so is f_nl, and the validity test sends
         * the particle to the fix-up (docs/modules/pf.md, "The a h and
         * validity tests") */
        const float ahm = fmaxf(ah0, ah1);
        /* process noise sqrt(Q) n */
        float nj[BR_NX];
        br_load4_f(&np, nj);
        const float t = (xn[BR_X_THETA] + q0 * nj[0]) - shift;
        const float w = xn[BR_X_OMEGA] + q1 * nj[1];
        const float z = xn[BR_X_Z] + q2 * nj[2];
        /* g_p's clamp by vmaxnm / vminnm: 0 < gp_min < gp_max finite */
        const float g = fminf(fmaxf(xn[BR_X_GP] + q3 * nj[3], gp_min), gp_max);
        /* the particle's one division, k_p = sigma0 L / g_p */
        const float kg = s0L / g;
        /* f_nl of the predicted particle (eqs. 3, 4) */
        const float f = br_pf_fnl_kp(&mk, w, z, kg);
        /* 2. Gaussian log-likelihood, l = -(theta - y)^2 / (2 R) */
        const float e = t - y_rel;
        const float l = br_pf_loglik(e, inv_2r);
        s1 += e;
        s2 += e * e;
        /* the a h test and the validity test as one compare on the bit
         * patterns: c_ah = ahm + (v - v), v = t + f, is ahm (>= +0) for a
         * valid particle and NaN otherwise; as unsigned integers the patterns
         * of floats >= +0 order as the floats and every NaN lies above the
         * limit's (docs/modules/pf.md). A particle that fails branches out,
         * keeping its state (f_nl = 0, l = NaN) */
        const float v = t + f, c_ah = ahm + (v - v);
        uint32_t c_bits;
        memcpy(&c_bits, &c_ah, sizeof c_bits);
        if (!(c_bits <= ah_lim_bits)) {
            br_pf_store_left(&fp, &lp);
            n_ok--;
            continue;
        }
        th[j] = t;
        om[j] = w;
        zz[j] = z;
        gg[j] = g;
        ka[j] = kg;
        br_store_f_inc(&fp, f);
        br_store_f_inc(&lp, l);
        lm = fmaxf(lm, l);
    }
    ls->s1 = s1;
    ls->s2 = s2;
    if (n_ok > 0u) {
        ls->lmax = (lm > ls->lmax) ? lm : ls->lmax;
        ls->n_valid += n_ok;
    }
    return (uint32_t)n - n_ok;
}

/* Step 3 in one loop with the weights' total, the exponential's roundf form
 * (the same W as the reference's); then the reference's search and copy. */
float br_pf_kernel_resample(br_pf_t *pf, float lmax, int outlier)
{
    uint32_t total;
    if (outlier) {
        total = br_pf_kref_weights(pf, lmax, 1);
    } else {
        const uint32_t m = pf->cfg.n_particles;
        const float *BR_RESTRICT l = pf->l;
        uint32_t *BR_RESTRICT W = pf->W;
        /* br_exp_neg's constants once, held in registers over the loop
         * (BR_HOLD: GCC would make 0.5, 1 and the range words afresh for
         * every particle) */
        br_exp_k_t k = br_exp_k();
        BR_HOLD_F(k.half);
        BR_HOLD_F(k.one);
        BR_HOLD_U(k.lo);
        BR_HOLD_U(k.span);
        total = 0u;
        for (uint32_t j = 0; j < m; j++) {
            /* W_j = floor(e^(l_j - lmax) 2^16), the scale in the exponent */
            W[j] = (uint32_t)br_exp_neg_kb_rinta(l[j] - lmax, k, 127 + 16, 65536.0f);
            total += W[j];
        }
    }
    const float sf = br_pf_select(pf, total);
    br_pf_kref_copy_fwd(pf);
    br_pf_kref_copy_back(pf);
    return sf;
}

uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls)
{
    /* four elements written out, the clamps and the largest l by vmaxnm /
     * vminnm; any other number of elements or passes: the reference's loops */
    return br_pf_ms4_applies(c) ? br_pf_ms4_predict(pf, c, j0, j1, nz, ls, 1)
                                : br_pf_kref_predict_ms(pf, c, j0, j1, nz, ls);
}
