/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's kernel for the Cortex-M4 (br_pf_kernel.h; FPv4
 * single precision: no vmaxnm / vminnm, no vrinta, so no fmaxf, fminf or
 * roundf, library calls there): the reference kernel's operations, with
 * what the M4 does in fewer instructions (docs/modules/pf.md, "Kernels"; docs/target.md, "What the kernels keep"):
 * the largest log-weight as an integer min, the four noise samples in one
 * load and f_nl and l stored with the pointer moved on, the exponential's
 * constants held in registers. Plain C but for br_inline.h's helpers of
 * those (asm on Arm; their C forms on the host: test_pf_kernels_m4). Same
 * results as the reference, bit for bit. */
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
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT zz = pf->x[BR_X_Z] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    const size_t n = j1 - j0;
    int32_t kmin = INT32_MAX; /* the largest l as the smallest int32 key (below) */
    uint32_t n_ok = (uint32_t)n; /* less one for each particle left for the fix-up */
    float s1 = ls->s1, s2 = ls->s2;
    const float *np = nz;                 /* particle j's BR_NX = 4 samples */
    float *fp = pf->fnl + j0, *lp = pf->l + j0; /* f_nl and l, stored with the pointer moved on */
    for (size_t j = 0; j < n; j++) {
        const float x[BR_NX] = {th[j], om[j], zz[j], gg[j]};
        float xn[BR_NX];
        /* 1. predict: RK4 of eq. 6 with the particle's k_p; ok_rk = 0 beyond
         * the RK4 limit */
        const int ok_rk = br_model_kp_rk4(&kp, x, ka[j], xn);
        /* process noise sqrt(Q) n */
        float nj[BR_NX];
        br_load4_f(&np, nj);
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
        /* validity as the reference's; a particle that fails branches out,
         * keeping its state (f_nl = 0, l = NaN) */
        if (!ok_rk || !((t - t) + (f - f) == 0.0f)) {
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
        /* the largest l by an integer min: a valid l is <= -0
         * (docs/modules/pf.md, "The largest log-weight"), so its bit pattern
         * as int32 is negative and orders the other way round */
        int32_t key;
        memcpy(&key, &l, sizeof key);
        kmin = (key < kmin) ? key : kmin;
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

/* Step 3 in one loop with the weights' total (the reference's exponential,
 * its constants held in registers); then the reference's search and copy. */
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
            W[j] = (uint32_t)br_exp_neg_w16_k(l[j] - lmax, k);
            total += W[j];
        }
    }
    const float sf = br_pf_select(pf, total);
    br_pf_kref_copy_fwd(pf);
    br_pf_kref_copy_back(pf);
    return sf;
}

/* Steps 1 and 2 with elements: four written out (br_pf_ms4.h, the clamps and
 * the largest l by selects: FPv4 has no vmaxnm); any other number of
 * elements or passes: the reference's loops. */
uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls)
{
    return br_pf_ms4_applies(c) ? br_pf_ms4_predict(pf, c, j0, j1, nz, ls, 0)
                                : br_pf_kref_predict_ms(pf, c, j0, j1, nz, ls);
}
