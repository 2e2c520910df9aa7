/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's kernel interface (private to the firmware): the hot
 * loops of one step, with one portable reference and one implementation per
 * target, each a file of its own (docs/modules/pf.md, "Kernels"):
 *
 *   firmware/pf/br_pf_kernel_ref.c   br_pf_kref_*: the reference, plain C99,
 *                                    always in the library (cfg.scalar_path)
 *   firmware/pf/br_pf_kernel_simd.c  br_pf_kernel_*: hosts with float SIMD
 *   firmware/pf/br_pf_kernel_m7.c    br_pf_kernel_*: the Cortex-M7
 *   firmware/pf/br_pf_kernel_m4.c    br_pf_kernel_*: the Cortex-M4
 *   firmware/pf/br_pf_kernel_port.c  br_pf_kernel_*: every other target: the
 *                                    reference itself
 *
 * firmware/CMakeLists.txt compiles exactly one of the br_pf_kernel_* files.
 * br_pf.c orchestrates: it calls br_pf_kernel_* (br_pf_kref_* on the scalar
 * reference path) and redoes the particles a kernel leaves with its
 * per-particle step (particle_one), which is the reference of steps 1 and 2
 * for every particle and model. Every kernel gives the reference kernel's
 * results bit for bit (test_pf_kernels). */
#ifndef BR_PF_KERNEL_H
#define BR_PF_KERNEL_H

#include <math.h>
#include <stdint.h>

#include "bristle/br_pf.h"
#include "br_inline.h"
#include "br_model_kernel.h"

/* W of a particle of weight 1 (the best one after the max-shift) */
#define BR_PF_W_ONE (1u << BR_PF_W_BITS)

/* The constants of one prediction pass of the thesis model (steps 1 and 2,
 * bootstrap proposal), the same for every particle. */
typedef struct {
    br_model_k_t mk;  /* the thesis model's kernel constants (f_nl) */
    br_model_kp_t kp; /* the PF's RK4 constants (br_model_kp_rk4), for one sub-step */
    int n_sub;        /* the model's sub-steps per step (br_model_t.n_sub, docs/modules/model.md) */
    float s0L;        /* sigma0 L: k_p = s0L / g_p */
    float q[BR_NX];   /* process noise standard deviations */
    float gp_min, gp_max, inv_2r;
    float shift;      /* theta of the new origin relative to the old one, rad */
    float y_rel;      /* the measurement relative to the new origin, rad */
    br_model_km_t km; /* with elements (est.model.mslip.n >= 1): the clamp model's constants */
    float uh;         /* with elements: u h, the trapezoidal step's torque impulse */
} br_pf_kc_t;

/* What a prediction pass adds up: the largest log-weight of the valid
 * particles and their count; cfg.adapt's sums of d_j = theta_j - y and d_j^2
 * over the particles in their order. */
typedef struct {
    float lmax;
    uint32_t n_valid;
    float s1, s2;
} br_pf_lsum_t;

/* f_nl (eqs. 3, 4) of a predicted particle: eq. 4 with its k_p = sigma0 L / g_p */
static inline float br_pf_fnl_kp(const br_model_k_t *k, float om, float z, float kg)
{
    return br_model_k_fnl(k, z, br_model_kp_zdot(k->L, kg, om, z));
}

/* Step 2, the log-likelihood of the measurement y given particle j,
 * Gaussian: l_j = -(theta_j - y)^2 / (2 R), e = theta_j - y. The one place it
 * is written (every kernel and the per-particle step call it). A valid
 * particle's l is <= -0 (-inf when e^2 overflows): the largest log-weight
 * by integer keys (the SIMD and Cortex-M4 kernels) holds only while that is
 * so (docs/modules/pf.md, "Changing the likelihood"). */
static inline float br_pf_loglik(float e, float inv_2r) { return -(e * e) * inv_2r; }

/* Maxwell-slip elements (docs/modules/pf.md, "Maxwell-slip elements"): one
 * clamp of element i at the level g, by selects (fmaxf / fminf's result for
 * every input, the bound d = c_i g > 0: a NaN gives -d, as fmaxf):
 *   e_i <- clamp(e_i + dx, -c_i g, c_i g)                       (eq. MS1) */
static inline float br_pf_ms_clamp(float e, float d)
{
    const float a = (e > -d) ? e : -d;
    return (a < d) ? a : d;
}

/* The deterministic part of step 1 with elements: br_model_km_step's
 * trapezoidal step (BR_MODEL_MS_PASSES fixed-point passes) with f0 =
 * sum_i k_i e_i carried by the particle (the same value br_msk_force makes):
 *   dtheta = omega_m h;  e1_i = clamp(e_i + L dtheta, +-c_i g)   (eq. MS1)
 *   f1 = sum_i k_i e1_i (i = 0..n-1, from 0)                       (eq. MS2)
 *   omega1 = omega0 + (u h - L^2 sigma2 dtheta - L h (f0 + f1) / 2) / Jeff   (eq. 6, trapezoidal)
 *   omega_m = (omega0 + omega1) / 2
 * e1 must not be e. Writes theta + dtheta and omega1 to *th, *om. */
static inline void br_pf_ms_det(const br_model_km_t *k, float uh, float *th, float *om, float g, float f0,
                                const float e[], float e1[])
{
    const float w0 = *om;
    float wm = w0, w1 = w0, dth = 0.0f;
    for (int pass = 0; pass < BR_MODEL_MS_PASSES; pass++) {
        dth = wm * k->h;
        const float dx = k->L * dth;
        float f1 = 0.0f;
        for (int i = 0; i < k->n; i++) {
            e1[i] = br_pf_ms_clamp(e[i] + dx, k->c[i] * g);
            f1 += k->k[i] * e1[i];
        }
        w1 = w0 + (uh - k->visc * dth - k->Lh_half * (f0 + f1)) * k->inv_Jeff;
        wm = 0.5f * (w0 + w1);
    }
    *th += dth;
    *om = w1;
}

/* The elements' process noise and the force of the predicted particle: z's
 * sample moves every element by the same dz (z is their common error), then
 * each is clamped at the new level g:
 *   e_i <- clamp(e_i + dz, +-c_i g)                                (eq. MS1)
 *   f_nl = sum_i k_i e_i                                            (eq. MS2) */
static inline float br_pf_ms_noise(const br_model_km_t *k, float e[], float dz, float g)
{
    float f = 0.0f;
    for (int i = 0; i < k->n; i++) {
        e[i] = br_pf_ms_clamp(e[i] + dz, k->c[i] * g);
        f += k->k[i] * e[i];
    }
    return f;
}

/* The target kernels' particle left for the fix-up: f_nl = 0 and l = NaN
 * stored with the pointers moved on (br_inline.h's br_store_f_inc) */
static inline void br_pf_store_left(float **fp, float **lp)
{
    br_store_f_inc(fp, 0.0f);
    br_store_f_inc(lp, NAN);
}

/* 1 for a valid particle (its log-weight l is not NaN), 0 for one kept at its state */
static inline float br_pf_valid_weight(float l) { return (l == l) ? 1.0f : 0.0f; }

/* 4. systematic resampling's indices by search, fused with step 5's sum of
 * f_nl over the resampled set in particle order (particle i is the predicted
 * particle j = idx_i, its f_nl held while j stays).
 * t_i = floor((2 i + 1) total / (2 m)), stepped as quotient and remainder
 * (the remainder kept less 2 m: its sign is the carry); particle i takes the
 * j with C_{j-1} <= t_i < C_j. total is the sum of the W_j, so
 * t_i <= floor(total - total / (2 m)) < C_{m-1}: the search stops by
 * j = m - 1 without a test of j. */
static inline float br_pf_select(br_pf_t *pf, uint32_t total)
{
    const uint32_t m = pf->cfg.n_particles;
    const uint32_t *restrict W = pf->W;
    uint16_t *restrict idx = pf->idx;
    const float *const fnl = pf->fnl;
    const uint32_t den = 2u * m;
    const uint32_t dq = (2u * total) / den, dr = (2u * total) % den;
    uint32_t t = total / den;
    int32_t rn = (int32_t)(total % den) - (int32_t)den;
    uint32_t j = 0u, c = W[0];
    float af = fnl[0];
    float sf = 0.0f;
    for (uint32_t i = 0; i < m; i++) {
        if (c <= t) {
            do {
                j++;
                c += W[j];
            } while (c <= t);
            af = fnl[j];
        }
        idx[i] = (uint16_t)j;
        sf += af;
        /* t_{i+1} = t_i + dq, plus 1 when the remainder carries */
        t += dq;
        rn += (int32_t)dr;
        if (rn >= 0) {
            t++;
            rn -= (int32_t)den;
        }
    }
    return sf;
}

/* Steps 1 and 2 (docs/modules/pf.md) of the thesis model for particles
 * j0 .. j1 - 1 of pf, whose standard-normal samples are nz[BR_NX (j - j0) + i]
 * (contiguous: no wrap round the table). A particle inside the RK4 limit with
 * a valid prediction is overwritten by it (state, k_p, f_nl, l) and added to
 * ls (lmax, n_valid). Any other particle keeps its state, gets f_nl = 0 and
 * l = NaN and is left for the caller's fix-up; a kernel may leave more
 * particles than the reference does, never fewer, and only ones that the
 * fix-up predicts as the reference would. ls's s1 and s2 hold the run's sums
 * in particle order when nothing is left (the caller makes them again
 * otherwise). Returns the number of particles left. With n_sub > 1 the
 * prediction is n_sub sub-steps of RK4 (br_model_kp_rk4_n), every one inside
 * the limit; the target kernels' loops are the single step's, so
 * br_pf_predict_run hands such a pass to the reference kernel. */
uint32_t br_pf_kref_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                            br_pf_lsum_t *ls);
uint32_t br_pf_kernel_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                              br_pf_lsum_t *ls);

/* The thesis model's pass over particles j0 .. j1 - 1 as br_pf.c runs it:
 * the target's kernel for one step per period, the reference kernel's
 * sub-step loop for n_sub > 1 (docs/modules/model.md, "Sub-steps"); the
 * test outside the kernels keeps their loops as they were. */
static inline uint32_t br_pf_predict_run(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1,
                                         const float *nz, br_pf_lsum_t *ls)
{
    return (c->n_sub != 1) ? br_pf_kref_predict(pf, c, j0, j1, nz, ls) : br_pf_kernel_predict(pf, c, j0, j1, nz, ls);
}

/* Steps 1 and 2 with elements (est.model.mslip.n >= 1; docs/modules/pf.md,
 * "Maxwell-slip elements"), bootstrap proposal, for particles j0 .. j1 - 1:
 * br_pf_ms_det, the process noise (theta, omega, g_p as the thesis model;
 * z's sample on the elements, br_pf_ms_noise), the log-likelihood. The
 * same contract as *_predict, with the elements pf->ms (stride m) and the
 * force kept in pf->kgp: a valid prediction (theta, omega and f_nl finite)
 * overwrites the particle, any other keeps it (f_nl = 0, l = NaN) for the
 * fix-up. There is no RK4 limit: only an invalid particle is left. */
uint32_t br_pf_kref_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                               br_pf_lsum_t *ls);
uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls);

/* Steps 3, 4 and step 5's sum, over pf's m predicted particles with their
 * log-weights pf->l (NaN: invalid) and lmax, the largest valid one (finite
 * unless outlier): the weights W_j (outlier: 2^16 for every valid particle),
 * systematic resampling's indices idx, the set copied in place (state, k_p
 * and, with elements, the elements), and the sum of f_nl over the resampled set in particle order, which
 * it returns. */
float br_pf_kref_resample(br_pf_t *pf, float lmax, int outlier);
float br_pf_kernel_resample(br_pf_t *pf, float lmax, int outlier);

/* Pieces of the reference that other kernels share (br_pf_kernel_ref.c):
 * the quantised weights, returning their total; the copy's forward and
 * backward passes (the search is br_pf_select, above). */
uint32_t br_pf_kref_weights(br_pf_t *pf, float lmax, int outlier);
void br_pf_kref_copy_fwd(br_pf_t *pf);
void br_pf_kref_copy_back(br_pf_t *pf);
/* With elements (est.model.mslip.n >= 1) the two passes move each
 * particle's elements with it; br_pf_kref_copy_ms_fwd: the forward pass of
 * the elements alone (the SIMD kernel's, whose forward pass of the states is
 * its own) */
void br_pf_kref_copy_ms_fwd(br_pf_t *pf);

#endif
