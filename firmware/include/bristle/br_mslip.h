/* SPDX-License-Identifier: Apache-2.0 */
/* Maxwell-slip friction in its clamp form (../shared/spec/presliding.md;
 * Al-Bender, Lampaert, Swevers, IEEE TAC 50(11), 2005), float32: N <= 8
 * spring-slider elements in parallel share the load's travel x.
 *
 *   Delta_i(g) = share_i g / k_i                       (element i slips at this deflection)
 *   z_i       <- clamp(z_i + dx, -Delta_i(g), +Delta_i(g))   (the C -> infinity limit)
 *   F          = sum_i k_i z_i + sigma2 v
 *
 * g is the Stribeck level the caller holds over the move (eq. 5's g(v), or
 * the estimators' g_p). With the breakaway displacements d_i at Fs,
 * k_i = share_i Fs / d_i. See docs/modules/mslip.md. */
#ifndef BR_MSLIP_H
#define BR_MSLIP_H

#include "bristle/br_status.h"

#define BR_MSLIP_MAX 8 /* elements */

/* Largest |sum of the shares - 1| accepted (float32 rounding of the shares written). */
#define BR_MSLIP_SHARE_TOL 1e-5f

typedef struct {
    int n;                      /* elements: 0 = none (LuGre elsewhere), 1..BR_MSLIP_MAX */
    float k_Npm[BR_MSLIP_MAX];  /* element stiffness, > 0 */
    float share[BR_MSLIP_MAX];  /* share of the Stribeck level, in (0, 1], sum 1 */
    float sigma2_Nspm;          /* viscous term of F, >= 0 (0: none) */
} br_mslip_cfg_t;

typedef struct {
    br_mslip_cfg_t cfg;
    float c_mpN[BR_MSLIP_MAX]; /* share_i / k_i: Delta_i = c_i g */
    float z_m[BR_MSLIP_MAX];   /* element deflections */
    int ready;
} br_mslip_t;

/* BR_OK when cfg is valid: n in 0..BR_MSLIP_MAX, every k_i finite and > 0,
 * every share finite in (0, 1] and their sum within BR_MSLIP_SHARE_TOL of 1,
 * sigma2 finite >= 0; the elements beyond n are not read. Else BR_E_PARAM
 * (BR_E_NULL for NULL). n = 0 is valid here: "no elements". */
br_status_t br_mslip_cfg_check(const br_mslip_cfg_t *cfg);

/* Validates cfg (n >= 1: a friction needs an element) and starts with every
 * element undeflected. BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_mslip_init(br_mslip_t *s, const br_mslip_cfg_t *cfg);

/* Every element back to z = 0. */
void br_mslip_reset(br_mslip_t *s);

/* Moves the elements by the travel dx_m at the level g_N (> 0) and returns in
 * *F_N the force sum k_i z_i + sigma2 v_mps after the move. A non-finite
 * input or g_N <= 0 is BR_E_INPUT and leaves the state and *F_N unchanged. */
br_status_t br_mslip_step(br_mslip_t *s, float dx_m, float v_mps, float g_N, float *F_N);

#endif
