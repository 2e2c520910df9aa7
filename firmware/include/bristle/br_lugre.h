/* SPDX-License-Identifier: Apache-2.0 */
/* LuGre dynamic friction (thesis eqs. 3-5), float32.
 *
 *   F_nl = sigma0 z + sigma1 dz/dt                       (eq. 3)
 *   dz/dt = v - sigma0 |v| z / g(v)                      (eq. 4)
 *   g(v)  = Fc + (Fs - Fc) exp(-|v| / vs)                (eq. 5)
 *
 * v is the load-side sliding velocity (m/s), z the mean bristle deflection (m).
 * See docs/modules/lugre.md. */
#ifndef BR_LUGRE_H
#define BR_LUGRE_H

#include "bristle/br_status.h"

typedef struct {
    float sigma0_Npm;  /* bristle stiffness, > 0 */
    float sigma1_Nspm; /* bristle damping, >= 0 */
    float Fc_N;        /* Coulomb level, > 0 */
    float Fs_N;        /* stiction level, >= Fc_N */
    float vs_mps;      /* Stribeck velocity, > 0 */
} br_lugre_cfg_t;

typedef struct {
    br_lugre_cfg_t cfg;
    float z_m;
    int ready;
} br_lugre_t;

/* Checks a configuration: every field finite and in range. */
br_status_t br_lugre_cfg_check(const br_lugre_cfg_t *cfg);

/* Eq. 5: Stribeck level g(v) in N. */
float br_lugre_g_N(const br_lugre_cfg_t *cfg, float v_mps);

/* Eq. 4: bristle rate for level g_N (> 0). */
float br_lugre_zdot_mps(const br_lugre_cfg_t *cfg, float z_m, float v_mps, float g_N);

/* Eq. 3: friction force from deflection and its rate. */
float br_lugre_force_N(const br_lugre_cfg_t *cfg, float z_m, float zdot_mps);

/* Exact solution of eq. 4 written over displacement instead of time
 * (dz/dx = 1 - sigma0 sgn(dx) z / g) for a level g held over the move dx:
 *   z1 = s g/sigma0 + (z0 - s g/sigma0) exp(-sigma0 |dx| / g),  s = sgn(dx).
 * Unconditionally bounded: |z1| <= max(|z0|, g/sigma0) at any speed.
 * Evaluated as z0 + (zss - z0)(1 - e^{-r}) with expm1 (no cancellation for small moves). */
float br_lugre_z_advance_m(const br_lugre_cfg_t *cfg, float z_m, float dx_m, float g_N);

br_status_t br_lugre_init(br_lugre_t *s, const br_lugre_cfg_t *cfg);

/* Advances z over dt_s at constant velocity v_mps (exact, bounded) and returns
 * the friction force at the end of the step in *F_N. A non-finite input is
 * rejected with BR_E_INPUT and leaves the state unchanged. */
br_status_t br_lugre_step(br_lugre_t *s, float v_mps, float dt_s, float *F_N);

#endif
