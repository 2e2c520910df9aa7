/* SPDX-License-Identifier: Apache-2.0 */
/* Static friction feedforward from an identified model: the baseline a user
 * would pick instead of an estimator (industrial drives' friction and cogging
 * compensation, ODrive's anticogging table). Evaluated on the reference, not
 * on the measurement, with no state (docs/modules/ff.md):
 *
 *   s(v)   = tanh(v / v_eps)                            (smoothed sign)
 *   g(v)   = Fc + (Fs - Fc) exp(-|v| / vs)              (eq. 5; times c = (Fc + dFc_neg) / Fc in -x)
 *   F_ff   = k(p) [ s(v) g(v) + sigma2_d v ] + offset + A sin(2 pi p / P + phi) + M a
 *   k(p)   = max(0, 1 + grad p);  sigma2_d = sigma2 (+ dsigma2_neg in -x)
 *   comp_N = clamp(F_ff, -comp_max, comp_max)
 *
 * with v, a, p the reference's load-side velocity, acceleration and position.
 * The causes are those of br_causes_t (a diagnosis's model.json); the actuator
 * delay has no static map and is ignored.
 *
 * With a Maxwell-slip element set (cfg.mslip.n >= 1, docs/modules/mslip.md) the
 * term s(v) g(v) is replaced by the elements driven along the reference's
 * position path: br_ff_set_ref moves them by the travel p - p_prev at the level
 * g(v) (z_i <- clamp(z_i + dp, -share_i g / k_i, +share_i g / k_i)), and the
 * term is sum_i k_i z_i: the presliding memory a static map has not. */
#ifndef BR_FF_H
#define BR_FF_H

#include "bristle/br_est.h"
#include "bristle/br_model.h"
#include "bristle/br_mslip.h"
#include "bristle/br_status.h"

typedef struct {
    float Fc_N;         /* Coulomb level, > 0 */
    float Fs_N;         /* stiction level, >= Fc_N */
    float vs_mps;       /* Stribeck velocity, > 0 */
    float sigma2_Nspm;  /* viscous coefficient fed forward, >= 0 (0: left to the loop) */
    float v_eps_mps;    /* width of the smoothed sign, > 0 */
    float mass_kg;      /* moving mass of the inertia term M a, >= 0 (0: off) */
    float comp_max_N;   /* output clamp, > 0 (the controller's tau_max / L) */
    br_causes_t causes; /* diagnosed causes as feedforward maps; delay_s ignored */
    br_mslip_cfg_t mslip; /* n = 0: the static map; n >= 1: the Maxwell-slip elements along the
                             reference (their sigma2 must be 0: the viscous term is sigma2_Nspm) */
} br_ff_cfg_t;

/* The reference at t_k, load side. */
typedef struct {
    float v_mps;   /* velocity */
    float a_mps2;  /* acceleration (used only with mass_kg > 0) */
    float p_m;     /* position (used only with a ripple or a gradient) */
} br_ff_in_t;

typedef struct {
    br_ff_cfg_t cfg;
    float c_neg;          /* (Fc + dFc_neg) / Fc */
    float ripple_k_radpm; /* 2 pi / P, 0 without ripple */
    br_ff_in_t in;        /* the reference br_ff_est_step evaluates (br_ff_set_ref) */
    float ms_c_mpN[BR_MSLIP_MAX]; /* share_i / k_i */
    float ms_z_m[BR_MSLIP_MAX];   /* the elements at the stored reference's position */
    int ready;
} br_ff_t;

/* Validates cfg (every field finite and in its range; Fc + dFc_neg > 0,
 * sigma2 + dsigma2_neg >= 0, ripple period > 0 with a ripple); the stored
 * reference starts at rest at 0. BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_ff_init(br_ff_t *ff, const br_ff_cfg_t *cfg);

/* comp_N for the reference in (with elements: those of the stored reference moved
 * by in's travel from it, without storing them). BR_E_NULL, BR_E_STATE (not initialised),
 * BR_E_INPUT (a non-finite input; *comp_N = 0). */
br_status_t br_ff_step(const br_ff_t *ff, const br_ff_in_t *in, float *comp_N);

/* Keeps the reference br_ff_est_step evaluates: the caller sets it before
 * each br_app_step (with elements: they move by the travel from the stored one). BR_E_INPUT (non-finite; the stored one is kept). */
br_status_t br_ff_set_ref(br_ff_t *ff, const br_ff_in_t *in);

/* br_est_step_fn over a br_ff_t (ctx): the feedforward as the compensation
 * source of br_app (BR_APP_EST_EXTERN); the measurement is not used. */
br_status_t br_ff_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

#endif
