/* SPDX-License-Identifier: Apache-2.0 */
/* The causes' force terms (private to the firmware): one home for each term,
 * which the extended model's kernel (br_model_kernel.h, br_model.c) and the
 * static feedforward (br_ff.c) both use. docs/modules/model.md, "Extended
 * model"; docs/architecture.md, "Adding a cause". With p the load position
 * and v the velocity, the load force of the friction f is
 *   k(p) s(t) f + offset + A sin(2 pi p / P + phi)
 * with the level and the viscous coefficient of f by the direction of motion.
 * Each function is the operations its callers had, in their order, so that
 * their results are unchanged bit for bit. */
#ifndef BR_CAUSE_TERMS_H
#define BR_CAUSE_TERMS_H

#include <math.h>

#include "bristle/br_model.h"

#define BR_CT_2PI 6.28318531f

/* asymmetric_friction: c = (Fc + dFc_neg) / Fc, the Stribeck level's factor in -x */
static inline float br_ct_asym_c_neg(float Fc_N, float dFc_neg_N)
{
    return (Fc_N + dFc_neg_N) / Fc_N;
}

/* asymmetric_friction: the Stribeck level g in the direction of motion (c g in -x) */
static inline float br_ct_asym_level_N(float g_N, float c_neg, int neg)
{
    return neg ? c_neg * g_N : g_N;
}

/* asymmetric_friction: the viscous coefficient in the direction of motion */
static inline float br_ct_asym_sigma2_Nspm(float s2_Nspm, float s2_neg_Nspm, int neg)
{
    return neg ? s2_neg_Nspm : s2_Nspm;
}

/* position_gradient k(p) = max(0, 1 + grad p) and friction_drift s(t) = max(0, 1 + drift t):
 * a friction scale linear in x (position or time), floored at 0 */
static inline float br_ct_lin_scale(float rate, float x)
{
    return fmaxf(0.0f, 1.0f + rate * x);
}

/* position_ripple: 2 pi / P, 0 without ripple (A = 0) */
static inline float br_ct_ripple_k_radpm(float amp_N, float period_m)
{
    return (amp_N != 0.0f) ? BR_CT_2PI / period_m : 0.0f;
}

/* position_ripple: its phase at p, 2 pi (p mod P) / P + phi (p reduced to one
 * period first: fmodf is exact) */
static inline float br_ct_ripple_phase_rad(float k_radpm, float period_m, float phase_rad, float p_m)
{
    return k_radpm * fmodf(p_m, period_m) + phase_rad;
}

/* position_ripple: A sin(phase) */
static inline float br_ct_ripple_N(float amp_N, float phase_rad)
{
    return amp_N * sinf(phase_rad);
}

/* offset and the friction scale: k f + offset (the ripple is added after) */
static inline float br_ct_scaled_load_N(float scale, float friction_N, float offset_N)
{
    return scale * friction_N + offset_N;
}

#endif
