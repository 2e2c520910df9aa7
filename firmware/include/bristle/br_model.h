/* SPDX-License-Identifier: Apache-2.0 */
/* Four-state estimation model of one ball-screw axis (thesis eq. 6), float32.
 *
 * State x = [theta (rad), omega (rad/s), z (m), g_p (N)] on the motor side;
 * g_p is the Stribeck level treated as a slowly varying parameter.
 *   dtheta/dt = omega
 *   domega/dt = (u - L (sigma2 L omega + f_nl(x))) / (J + L^2 M)
 *   dz/dt     = L omega - sigma0 L |omega| z / g_p
 *   dg_p/dt   = 0
 *   f_nl(x)   = sigma0 z + sigma1 dz/dt              (the lumped friction)
 * See docs/modules/model.md for the discretisation. */
#ifndef BR_MODEL_H
#define BR_MODEL_H

#include <stdint.h>

#include "bristle/br_lugre.h"
#include "bristle/br_mslip.h"
#include "bristle/br_status.h"
#include "bristle_gen/model/br_causes.h"

enum { BR_X_THETA = 0, BR_X_OMEGA = 1, BR_X_Z = 2, BR_X_GP = 3, BR_NX = 4 };

/* RK4 is used while the bristle rate times the step, a h = sigma0 L |omega| h / g_p,
 * stays at or below this value (RK4's real-axis stability bound is 2.785);
 * beyond it the step switches to the bounded displacement-exact scheme. */
#define BR_MODEL_RK4_AH_MAX 2.0f

/* Sub-steps (docs/modules/model.md, "Sub-steps"): one step of dt_s is made
 * of n = ceil(rho dt_s / BR_MODEL_SUB_RH_MAX) equal sub-steps, rho the
 * spectral radius of the presliding mode (the bristle spring sigma0 and the
 * damping sigma1 + sigma2 on the effective mass), chosen once at init; n = 1
 * (the thesis's single step) wherever rho dt_s <= BR_MODEL_SUB_RH_MAX. A
 * configuration that needs more than BR_MODEL_SUB_MAX is refused. */
#define BR_MODEL_SUB_RH_MAX 1.0f
#define BR_MODEL_SUB_MAX 32

/* What a diagnosis found beyond the thesis model (docs/modules/model.md,
 * "Extended model"; the causes of a measured log, docs/diagnose.md): all 0 is
 * eq. 6 exactly, bit for bit. The names are those of model.json and of the
 * machine file. With p = L theta_abs the load position and v = L omega:
 *   J_eff omega' = u(t - delay) - L [ k(p) s(t) (sigma2_d v + f_nl) + offset + A sin(2 pi p / P + phi) ]
 *   k(p) = max(0, 1 + grad p);  in -x (v < 0): sigma2_d = sigma2 + dsigma2_neg and the
 *   Stribeck level is c g_p, c = (Fc + dFc_neg) / Fc (eq. 4 with that level);
 *   s(t) = max(0, 1 + drift t), t the model's clock (br_model_tick), held over a step.
 * The fields: one float per parameter of a force or measurement cause, in the cause
 * registry's order (bristle_gen/model/br_causes.h, BR_CAUSE_FIELDS, generated from
 * python/bristle/diagnose/causes/; docs/architecture.md, "Adding a cause"). delay_s is read by the
 * estimators' command history (br_est.h), which delays the torque they predict with, not by the
 * model step. */
#define BR_CAUSE_FLOAT_FIELD_(field, cause, hook, on) float field;
typedef struct {
    BR_CAUSE_FIELDS(BR_CAUSE_FLOAT_FIELD_)
} br_causes_t;
#undef BR_CAUSE_FLOAT_FIELD_

typedef struct {
    float J_kgm2;       /* motor + screw inertia, > 0 */
    float M_kg;         /* table mass, >= 0 */
    float lead_mprad;   /* L = lead / (2 pi), > 0 */
    float sigma2_Nspm;  /* viscous friction, >= 0 */
    br_lugre_cfg_t lugre;
    float dt_s;         /* discretisation step, > 0 */
    br_causes_t causes; /* all 0: the thesis model */
    br_mslip_cfg_t mslip; /* n = 0: LuGre (eqs. 3-5, the thesis); n >= 1: the Maxwell-slip friction
                             in clamp form with the level g_p (docs/modules/model.md, "Maxwell-slip
                             model"); its sigma2 must be 0 (the viscous friction is sigma2_Nspm) and
                             no cause but the delay may be on */
} br_model_cfg_t;

/* Fixed-point passes of the Maxwell-slip model's trapezoidal step (docs/modules/model.md). */
#define BR_MODEL_MS_PASSES 2

typedef struct {
    br_model_cfg_t cfg;
    float inv_Jeff;     /* 1 / (J + L^2 M) */
    float visc_Nmsprad; /* L^2 sigma2 */
    int extended;       /* a cause other than the delay is on: the extended right-hand side */
    float c_neg;        /* (Fc + dFc_neg) / Fc, the Stribeck level's factor in -x */
    float sigma2_neg_Nspm; /* sigma2 + dsigma2_neg */
    float ripple_k_radpm;  /* 2 pi / P (0 without ripple) */
    uint32_t n_steps;      /* the model's clock: steps of dt_s since init (saturates) */
    float drift_k;         /* s(t) = max(0, 1 + drift n_steps dt_s): the friction scale now (1 without drift) */
    float ms_c_mpN[BR_MSLIP_MAX]; /* Maxwell-slip: share_i / k_i (Delta_i = c_i g_p) */
    float rho_h;        /* the presliding mode's spectral radius times dt_s (0 with elements) */
    int n_sub;          /* sub-steps per step of dt_s, 1 .. BR_MODEL_SUB_MAX (1 with elements) */
    float h_sub_s;      /* dt_s / n_sub, the step of the kernels */
    int ready;
} br_model_t;

br_status_t br_model_init(br_model_t *m, const br_model_cfg_t *cfg);

/* The model's clock (friction_drift): br_model_set_clock sets it to n steps of
 * dt_s, br_model_tick advances it by one (saturating at UINT32_MAX); both update
 * the friction scale s(t) = max(0, 1 + drift t), t = n dt_s, that every step and
 * force of the extended model use until the clock moves again. The estimators
 * tick once per prediction. Without a drift the scale stays 1. */
void br_model_set_clock(br_model_t *m, uint32_t n_steps);
void br_model_tick(br_model_t *m);

/* Eq. 6 right-hand side f(x, u), extended by the causes; theta absolute
 * (the load position is p = L theta). */
void br_model_deriv(const br_model_t *m, const float x[BR_NX], float u_Nm, float dx[BR_NX]);

/* Lumped friction f_nl(x) in N (load side): eqs. 3-4 with the level g_p (c g_p
 * in -x with an asymmetry). */
float br_model_fnl_N(const br_model_t *m, const float x[BR_NX]);

/* The force a compensation must cancel (load side, N) for a state whose theta
 * is relative to an origin at load position p0_m (p = p0_m + L theta): f_nl
 * for the thesis model; with causes k(p) (sigma2_d v + f_nl) - sigma2 v +
 * offset + ripple, everything but the nominal viscous friction (which the
 * controller sees as part of the plant, as in the thesis). */
float br_model_fcomp_N(const br_model_t *m, const float x[BR_NX], float p0_m);

/* One discretisation step of dt_s with the torque u_Nm held, theta absolute:
 * n_sub sub-steps of h = dt_s / n_sub, each by RK4 where a h <=
 * BR_MODEL_RK4_AH_MAX at its ends and its stages, otherwise by the bounded
 * scheme.
 * Non-finite input or g_p <= 0 gives BR_E_INPUT and x_next = x. */
br_status_t br_model_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float x_next[BR_NX]);

/* The same for a state whose theta is relative to an origin at load position
 * p0_m (the estimators keep theta relative to an integer count origin). */
br_status_t br_model_step_at(const br_model_t *m, const float x[BR_NX], float p0_m, float u_Nm,
                             float x_next[BR_NX]);

/* The Maxwell-slip model (cfg.mslip.n >= 1): the friction is that of the
 * element deflections z_m[0..n-1], which the caller carries beside x (x[BR_X_Z]
 * is not used and is carried unchanged). br_model_ms_fnl_N: sum_i k_i z_i.
 * br_model_ms_step: one step of dt_s with u held (theta absolute or relative:
 * the model does not depend on it): the elements clamp-moved along the
 * step's travel at the level g_p, the rigid body by the trapezoidal rule in
 * BR_MODEL_MS_PASSES fixed-point passes. z_next_m may be z_m, x_next may be x.
 * BR_E_STATE without elements; non-finite x, z or u, or g_p <= 0, give
 * BR_E_INPUT, a non-finite result BR_E_NUMERIC, both with the outputs = inputs. */
float br_model_ms_fnl_N(const br_model_t *m, const float z_m[]);
br_status_t br_model_ms_step(const br_model_t *m, const float x[BR_NX], const float z_m[], float u_Nm,
                             float x_next[BR_NX], float z_next_m[]);

#endif
