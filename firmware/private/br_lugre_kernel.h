/* SPDX-License-Identifier: Apache-2.0 */
/* The LuGre friction kernel (thesis eqs. 3-5), float32, inline; private to
 * the firmware. The one place these equations are coded in C for the
 * firmware: br_lugre (the stand-alone friction model), br_model (eq. 6, RK4
 * and the bounded scheme) and the particle filter's inline prediction all
 * evaluate them through these functions, so with -ffp-contract=off every
 * caller gets bit-identical results. docs/modules/lugre.md. */
#ifndef BR_LUGRE_KERNEL_H
#define BR_LUGRE_KERNEL_H

#include <math.h>

/* eq. 5: g(v) = Fc + (Fs - Fc) exp(-|v| / vs) */
static inline float br_lk_g_N(float Fc_N, float Fs_N, float vs_mps, float v_mps)
{
    return Fc_N + (Fs_N - Fc_N) * expf(-fabsf(v_mps) / vs_mps);
}

/* eq. 4: dz/dt = v - sigma0 |v| z / g */
static inline float br_lk_zdot_mps(float sigma0_Npm, float v_mps, float z_m, float g_N)
{
    return v_mps - sigma0_Npm * fabsf(v_mps) * z_m / g_N;
}

/* eq. 3: F = sigma0 z + sigma1 dz/dt */
static inline float br_lk_force_N(float sigma0_Npm, float sigma1_Nspm, float z_m, float zdot_mps)
{
    return sigma0_Npm * z_m + sigma1_Nspm * zdot_mps;
}

/* eq. 4 solved exactly over a displacement dx != 0 with g held
 * (dz/dx = 1 - sigma0 sgn(dx) z / g):
 *   z1 = zss + (z0 - zss) e^{-r},  zss = sgn(dx) g / sigma0,  r = sigma0 |dx| / g,
 * evaluated as z0 + (zss - z0)(1 - e^{-r}) with expm1 (no cancellation for
 * small moves). |z1| <= max(|z0|, g / sigma0): bounded at any speed. */
typedef struct {
    float z1_m;        /* deflection after the move */
    float zss_m;       /* steady-state deflection sgn(dx) g / sigma0 */
    float r;           /* sigma0 |dx| / g */
    float one_minus_e; /* 1 - e^{-r} */
} br_lk_move_t;

static inline br_lk_move_t br_lk_move(float sigma0_Npm, float z0_m, float dx_m, float g_N)
{
    br_lk_move_t mv;
    mv.zss_m = copysignf(g_N / sigma0_Npm, dx_m);
    mv.r = sigma0_Npm * fabsf(dx_m) / g_N;
    mv.one_minus_e = -expm1f(-mv.r);
    mv.z1_m = z0_m + (mv.zss_m - z0_m) * mv.one_minus_e;
    return mv;
}

/* The same move made at constant speed over a step h, with the integral of z
 * over the step (the bounded schemes' friction impulse needs it):
 *   int z dt = h (zss + (z0 - zss) (1 - e^{-r}) / r),
 * (1 - e^{-r}) / r by its series where r would underflow the division; a move
 * of 0 leaves z and gives z0 h. */
typedef struct {
    float z1_m;   /* deflection after the move */
    float zint_ms; /* integral of z over the step, m s */
} br_lk_step_t;

static inline br_lk_step_t br_lk_move_over(float sigma0_Npm, float z0_m, float dx_m, float g_N, float h_s)
{
    br_lk_step_t st;
    if (dx_m != 0.0f) {
        const br_lk_move_t mv = br_lk_move(sigma0_Npm, z0_m, dx_m, g_N);
        const float q = (mv.r > 1e-6f) ? mv.one_minus_e / mv.r : 1.0f - 0.5f * mv.r;
        st.z1_m = mv.z1_m;
        st.zint_ms = h_s * (mv.zss_m + (z0_m - mv.zss_m) * q);
    } else {
        st.z1_m = z0_m;
        st.zint_ms = z0_m * h_s;
    }
    return st;
}

#endif
