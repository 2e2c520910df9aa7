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
            br_store_f_inc(&fp, 0.0f);
            br_store_f_inc(&lp, NAN);
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

/* fminf(fmaxf(v, -d), d): one vmaxnm, one vminnm (d > 0) */
static inline float clamp_nm(float v, float d) { return fminf(fmaxf(v, -d), d); }

/* four elements, in registers */
typedef struct {
    float v0, v1, v2, v3;
} ms4_t;

/* the bounds c_i g of the level g */
static inline ms4_t ms4_bounds(ms4_t c, float g)
{
    const ms4_t d = {c.v0 * g, c.v1 * g, c.v2 * g, c.v3 * g};
    return d;
}

/* e_i moved by dx, clamped at +-d_i (eq. MS1) */
static inline ms4_t ms4_move(ms4_t e, float dx, ms4_t d)
{
    const ms4_t z = {clamp_nm(e.v0 + dx, d.v0), clamp_nm(e.v1 + dx, d.v1), clamp_nm(e.v2 + dx, d.v2),
                     clamp_nm(e.v3 + dx, d.v3)};
    return z;
}

/* sum k_i z_i in the reference's order, from 0 (eq. MS2) */
static inline float ms4_force(ms4_t k, ms4_t z)
{
    return (((0.0f + k.v0 * z.v0) + k.v1 * z.v1) + k.v2 * z.v2) + k.v3 * z.v3;
}

/* Steps 1 and 2 with four elements (the common set), the reference's
 * operations written out: every element in a register, each clamp by vmaxnm
 * / vminnm (fminf(fmaxf(v, -d), d) is the reference's select clamp for
 * every v when d = c_i g_p > 0: a NaN gives -d in both), the bounds c_i g_p
 * made once per particle for both passes (the same products), the sums in
 * the reference's order (from 0: 0 + x is x but for x = -0), the
 * BR_MODEL_MS_PASSES = 2 passes written out (predict_ms runs the reference
 * for any other count). With the element loops over N on the stack this
 * path ran 315 instructions per particle-step against 182 written out
 * (docs/modules/pf.md). */
static uint32_t predict_ms4(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                            br_pf_lsum_t *ls)
{
    const float uh = c->uh, h = c->km.h, L = c->km.L, visc = c->km.visc, Lh_half = c->km.Lh_half;
    const float inv_Jeff = c->km.inv_Jeff;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    const ms4_t k = {c->km.k[0], c->km.k[1], c->km.k[2], c->km.k[3]};
    const ms4_t cg = {c->km.c[0], c->km.c[1], c->km.c[2], c->km.c[3]};
    const uint32_t m = pf->cfg.n_particles;
    float *BR_RESTRICT e0p = pf->ms, *BR_RESTRICT e1p = pf->ms + m, *BR_RESTRICT e2p = pf->ms + 2u * m;
    float *BR_RESTRICT e3p = pf->ms + 3u * m;
    float *BR_RESTRICT th = pf->x[BR_X_THETA];
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA];
    float *BR_RESTRICT gg = pf->x[BR_X_GP];
    float *BR_RESTRICT ka = pf->kgp;
    float lm = -INFINITY;
    uint32_t n_ok = j1 - j0;
    float s1 = ls->s1, s2 = ls->s2;
    const float *np = nz;
    float *fp = pf->fnl + j0, *lp = pf->l + j0;
    for (uint32_t j = j0; j < j1; j++) {
        const float w0 = om[j], g0 = gg[j], f0 = ka[j];
        const ms4_t e = {e0p[j], e1p[j], e2p[j], e3p[j]};
        const ms4_t d = ms4_bounds(cg, g0);
        /* 1. predict: the trapezoidal step (eqs. MS1, MS2, 6); pass 1 from omega_m = omega0 */
        const float dth1 = w0 * h;
        const float f11 = ms4_force(k, ms4_move(e, L * dth1, d));
        const float w11 = w0 + (uh - visc * dth1 - Lh_half * (f0 + f11)) * inv_Jeff;
        /* pass 2 from omega_m = (omega0 + omega1) / 2 */
        const float dth = (0.5f * (w0 + w11)) * h;
        ms4_t z = ms4_move(e, L * dth, d);
        const float f1 = ms4_force(k, z);
        const float w1 = w0 + (uh - visc * dth - Lh_half * (f0 + f1)) * inv_Jeff;
        /* process noise; g_p's clamp by vmaxnm / vminnm */
        float nj[BR_NX];
        br_load4_f(&np, nj);
        const float t = ((th[j] + dth) + q0 * nj[0]) - shift;
        const float w = w1 + q1 * nj[1];
        const float g = fminf(fmaxf(g0 + q3 * nj[3], gp_min), gp_max);
        /* z's sample on every element, clamped at the new g_p; f_nl = sum k_i e_i (eqs. MS1, MS2) */
        z = ms4_move(z, q2 * nj[2], ms4_bounds(cg, g));
        const float f = ms4_force(k, z);
        /* 2. Gaussian log-likelihood */
        const float ey = t - y_rel;
        const float l = br_pf_loglik(ey, inv_2r);
        s1 += ey;
        s2 += ey * ey;
        /* validity: theta, omega and f_nl finite */
        if (!((t - t) + (w - w) + (f - f) == 0.0f)) {
            br_store_f_inc(&fp, 0.0f);
            br_store_f_inc(&lp, NAN);
            n_ok--;
            continue;
        }
        th[j] = t;
        om[j] = w;
        gg[j] = g;
        ka[j] = f;
        e0p[j] = z.v0;
        e1p[j] = z.v1;
        e2p[j] = z.v2;
        e3p[j] = z.v3;
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
    return (j1 - j0) - n_ok;
}

uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls)
{
    /* any other number of elements or passes: the reference's loops */
    return (c->km.n == 4 && BR_MODEL_MS_PASSES == 2) ? predict_ms4(pf, c, j0, j1, nz, ls) : br_pf_kref_predict_ms(pf, c, j0, j1, nz, ls);
}
