/* SPDX-License-Identifier: Apache-2.0 */
/* The Maxwell-slip clamp kernel (docs/modules/mslip.md), float32, inline;
 * private to the firmware. The one place the clamp form is coded in C for the
 * firmware: br_mslip, the estimation model's element step (br_model) and the
 * feedforward evaluate it through these functions, so with -ffp-contract=off
 * they agree bit for bit. */
#ifndef BR_MSLIP_KERNEL_H
#define BR_MSLIP_KERNEL_H

#include <math.h>

/* Elements at z moved by dx at the level g, written to z1 (z1 may be z):
 *   z1_i = clamp(z_i + dx, -c_i g, c_i g),  c_i = share_i / k_i  (Delta_i = c_i g)
 * and returns the element force sum_i k_i z1_i (in the order i = 0..n-1). */
static inline float br_msk_move(int n, const float k_Npm[], const float c_mpN[], const float z_m[], float z1_m[],
                                float dx_m, float g_N)
{
    float f = 0.0f;
    int i;
    for (i = 0; i < n; i++) {
        const float d = c_mpN[i] * g_N;
        const float zi = fminf(fmaxf(z_m[i] + dx_m, -d), d);
        z1_m[i] = zi;
        f += k_Npm[i] * zi;
    }
    return f;
}

/* sum_i k_i z_i (in the order i = 0..n-1) */
static inline float br_msk_force(int n, const float k_Npm[], const float z_m[])
{
    float f = 0.0f;
    int i;
    for (i = 0; i < n; i++) {
        f += k_Npm[i] * z_m[i];
    }
    return f;
}

#endif
