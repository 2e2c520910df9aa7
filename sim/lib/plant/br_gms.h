/* SPDX-License-Identifier: Apache-2.0 */
/* The generalized Maxwell-slip (GMS) friction of the plant
 * (../shared/spec/presliding.md; Al-Bender, Lampaert, Swevers, IEEE TAC 50(11),
 * 2005): N spring-slider elements in parallel share the load's travel x.
 * Element i: stiffness k_i, share alpha_i of the Stribeck level s(v)
 * (sum alpha_i = 1), deflection z_i, damping sigma1_i on its rate.
 *
 *   Delta_i(v) = alpha_i s(v) / k_i                  (the deflection at which element i slips)
 *   sticking:   dz_i/dt = v
 *   slipping:   dz_i/dt = C alpha_i (sgn(v) - z_i / Delta_i(v))   (finite-C slip law)
 *   F           = sum_i (k_i z_i + sigma1_i dz_i/dt)
 *
 * An element sticks until sgn(v) z_i reaches Delta_i, then slips until the
 * velocity changes sign (or stops). The clamp limit (C -> infinity, the form
 * of presliding.md an MCU can afford) is one clamp per travel dx:
 * z_i <- clamp(z_i + dx, -Delta_i, +Delta_i).
 *
 * Integration (docs/modules/plant.md, "Maxwell-slip friction"): over a
 * substep the velocity is held, and each element follows its exact solution
 * (stick phase, switch, slip phase), so |z_i| <= max(|z_i(0)|, alpha_i s_max / k_i)
 * whatever the step. The friction impulse is integrated in closed form. */
#ifndef BR_GMS_H
#define BR_GMS_H

#define BR_GMS_MAX 8 /* elements */

typedef struct {
    int n;          /* elements: 0 = none (the plant's LuGre), 1..BR_GMS_MAX */
    int clamp;      /* 1: the clamp limit (C -> infinity); 0: the finite-C slip law */
    double C_mps;   /* slip law's attraction rate, m/s (> 0 when clamp == 0) */
    double delta;   /* Stribeck shape exponent of s(v) (1: LuGre's g) */
    double k_Npm[BR_GMS_MAX];       /* element stiffness, > 0 */
    double alpha[BR_GMS_MAX];       /* share of s(v), > 0, sum 1 */
    double sigma1_Nspm[BR_GMS_MAX]; /* element damping on dz_i/dt, >= 0 */
} br_gms_cfg_t;

typedef struct {
    double z_m[BR_GMS_MAX]; /* deflections */
    int slip[BR_GMS_MAX];   /* slip law: 0 sticking, +1 / -1 slipping in that direction */
} br_gms_state_t;

/* Largest sum of the shares' deviation from 1 accepted (rounding of the shares written). */
#define BR_GMS_SHARE_TOL 1e-9

/* NULL when g is valid (n == 0 is: no elements), else what is wrong. */
const char *br_gms_check(const br_gms_cfg_t *g);

/* The elements of breakaway displacements d_i at the level Fs (presliding.md:
 * d_i = alpha_i Fs / k_i, so k_i = alpha_i Fs / d_i), each with damping
 * sigma1_Nspm; the law and C are left as they are. n <= BR_GMS_MAX. */
void br_gms_from_breakaway(br_gms_cfg_t *g, int n, const double d_m[], const double alpha[], double Fs_N,
                           double sigma1_Nspm);

/* Element damping by a damping ratio per element (docs/modules/plant.md,
 * "Element damping"): element i alone on the moving mass Meff_kg (at the
 * load, M + J / L^2) is a mode of stiffness k_i with damping ratio zeta,
 *   sigma1_i = 2 zeta sqrt(k_i Meff),
 * so scaling every breakaway displacement scales the element modes'
 * frequencies and keeps their damping ratio; any set of elements sticking
 * together has a ratio between zeta and zeta sqrt(n). Sets sigma1_Nspm only. */
void br_gms_damping_ratio(br_gms_cfg_t *g, double zeta, double Meff_kg);

/* Advances every element from x0 into x1 over h seconds at the held velocity
 * v with the Stribeck level s_N (> 0); returns the friction impulse
 * integral of sum_i (k_i z_i + sigma1_i dz_i/dt) dt over the substep. */
double br_gms_advance(const br_gms_cfg_t *g, const br_gms_state_t *x0, br_gms_state_t *x1, double v, double h,
                      double s_N);

/* The friction force of state x at velocity v with the level s_N. */
double br_gms_force_N(const br_gms_cfg_t *g, const br_gms_state_t *x, double v, double s_N);

/* The force-travel loop's presliding figure of presliding.md for a slow
 * reversal (s = Fs): the travel after a reversal from steady sliding at which
 * the force has covered 90 % of its swing from -Fs to +Fs, m. The clamp
 * form's (quasi-static: the slip law's relaxation does not enter). */
double br_gms_presliding_m(const br_gms_cfg_t *g, double Fs_N);

#endif
