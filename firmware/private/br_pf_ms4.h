/* SPDX-License-Identifier: Apache-2.0 */
/* Steps 1 and 2 of the PF with four Maxwell-slip elements, written out for
 * the target kernels (br_pf_kernel_m7.c, br_pf_kernel_m4.c; docs/modules/pf.md,
 * "Maxwell-slip elements"): the reference's operations (br_pf_kref_predict_ms)
 * in the reference's order, every element in a register, the bounds c_i g_p
 * made once per particle for both passes (the same products), the
 * BR_MODEL_MS_PASSES = 2 passes written out. With the element loops over N
 * on the stack the M7 ran this step at 315 instructions per particle-step,
 * written out with a pass loop 182, with the passes written out 160
 * (tb_profile.py). Same results as the reference, bit for bit
 * (test_pf_kernels_m7 / _m4). */
#ifndef BR_PF_MS4_H
#define BR_PF_MS4_H

#include <math.h>
#include <stdint.h>

#include "br_inline.h"
#include "br_pf_kernel.h"

/* 1 when the written-out step applies: four elements, two passes */
static inline int br_pf_ms4_applies(const br_pf_kc_t *c) { return c->km.n == 4 && BR_MODEL_MS_PASSES == 2; }

/* clamp(v, lo, hi) for lo < hi, lo and hi not NaN, the reference's select
 * clamp for every v (a NaN v gives lo). nm = 1: fminf(fmaxf(v, lo), hi), one
 * vmaxnm and one vminnm on FPv5 (fmaxf passes over the NaN v, giving lo, and
 * the result is never NaN); nm = 0: the selects (FPv4 has no vmaxnm, fmaxf is
 * a library call there). nm is a constant of the caller. */
static inline float br_pf_ms4_clamp(float v, float lo, float hi, int nm)
{
    if (nm) {
        return fminf(fmaxf(v, lo), hi);
    }
    const float a = (v > lo) ? v : lo;
    return (a < hi) ? a : hi;
}

/* four elements, in registers */
typedef struct {
    float v0, v1, v2, v3;
} br_pf_ms4_t;

/* the bounds c_i g of the level g */
static inline br_pf_ms4_t br_pf_ms4_bounds(br_pf_ms4_t c, float g)
{
    const br_pf_ms4_t d = {c.v0 * g, c.v1 * g, c.v2 * g, c.v3 * g};
    return d;
}

/* e_i moved by dx, clamped at +-d_i (eq. MS1; d_i = c_i g > 0) */
static inline br_pf_ms4_t br_pf_ms4_move(br_pf_ms4_t e, float dx, br_pf_ms4_t d, int nm)
{
    const br_pf_ms4_t z = {br_pf_ms4_clamp(e.v0 + dx, -d.v0, d.v0, nm), br_pf_ms4_clamp(e.v1 + dx, -d.v1, d.v1, nm),
                           br_pf_ms4_clamp(e.v2 + dx, -d.v2, d.v2, nm), br_pf_ms4_clamp(e.v3 + dx, -d.v3, d.v3, nm)};
    return z;
}

/* sum k_i z_i in the reference's order, from 0 (eq. MS2; 0 + x is x but for x = -0) */
static inline float br_pf_ms4_force(br_pf_ms4_t k, br_pf_ms4_t z)
{
    return (((0.0f + k.v0 * z.v0) + k.v1 * z.v1) + k.v2 * z.v2) + k.v3 * z.v3;
}

/* br_pf_kernel_predict_ms's contract (br_pf_kernel.h) for four elements and
 * two passes (br_pf_ms4_applies); nm as br_pf_ms4_clamp's, also for the
 * largest l (fmaxf or a select; a valid l is never NaN). */
static inline uint32_t br_pf_ms4_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1,
                                         const float *nz, br_pf_lsum_t *ls, int nm)
{
    const float uh = c->uh, h = c->km.h, L = c->km.L, visc = c->km.visc, Lh_half = c->km.Lh_half;
    const float inv_Jeff = c->km.inv_Jeff;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
    const br_pf_ms4_t k = {c->km.k[0], c->km.k[1], c->km.k[2], c->km.k[3]};
    const br_pf_ms4_t cg = {c->km.c[0], c->km.c[1], c->km.c[2], c->km.c[3]};
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
        const br_pf_ms4_t e = {e0p[j], e1p[j], e2p[j], e3p[j]};
        const br_pf_ms4_t d = br_pf_ms4_bounds(cg, g0);
        /* 1. predict: the trapezoidal step (eqs. MS1, MS2, 6); pass 1 from omega_m = omega0 */
        const float dth1 = w0 * h;
        const float f11 = br_pf_ms4_force(k, br_pf_ms4_move(e, L * dth1, d, nm));
        const float w11 = w0 + (uh - visc * dth1 - Lh_half * (f0 + f11)) * inv_Jeff;
        /* pass 2 from omega_m = (omega0 + omega1) / 2 */
        const float dth = (0.5f * (w0 + w11)) * h;
        br_pf_ms4_t z = br_pf_ms4_move(e, L * dth, d, nm);
        const float f1 = br_pf_ms4_force(k, z);
        const float w1 = w0 + (uh - visc * dth - Lh_half * (f0 + f1)) * inv_Jeff;
        /* process noise sqrt(Q) n; theta relative to the new origin; g_p clamped */
        float nj[BR_NX];
        br_load4_f(&np, nj);
        const float t = ((th[j] + dth) + q0 * nj[0]) - shift;
        const float w = w1 + q1 * nj[1];
        const float g = br_pf_ms4_clamp(g0 + q3 * nj[3], gp_min, gp_max, nm);
        /* z's sample on every element, clamped at the new g_p; f_nl = sum k_i e_i (eqs. MS1, MS2) */
        z = br_pf_ms4_move(z, q2 * nj[2], br_pf_ms4_bounds(cg, g), nm);
        const float f = br_pf_ms4_force(k, z);
        /* 2. Gaussian log-likelihood */
        const float ey = t - y_rel;
        const float l = br_pf_loglik(ey, inv_2r);
        s1 += ey;
        s2 += ey * ey;
        /* validity: theta, omega and f_nl finite */
        if (!((t - t) + (w - w) + (f - f) == 0.0f)) {
            br_pf_store_left(&fp, &lp);
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
        lm = nm ? fmaxf(lm, l) : ((l > lm) ? l : lm);
    }
    ls->s1 = s1;
    ls->s2 = s2;
    if (n_ok > 0u) {
        ls->lmax = (lm > ls->lmax) ? lm : ls->lmax;
        ls->n_valid += n_ok;
    }
    return (j1 - j0) - n_ok;
}

#endif
