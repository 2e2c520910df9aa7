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
 * term is sum_i k_i z_i: the presliding memory a static map has not.
 *
 * With a horizon tau = cfg.pred_ahead_s > 0 (elements only; docs/modules/ff-pred.md)
 * the elements' change over the coming tau along the stored reference,
 *   dp = v tau + a tau^2 / 2,  g1 = g(v + a tau),
 *   dF = sum_i k_i clamp(z_i + dp, -share_i g1 / k_i, +share_i g1 / k_i) - sum_i k_i z_i,
 * is added to what br_ff_est_step returns (br_ff_pred_N; br_ff_pred.h adds it
 * to an estimator's F_hat). tau = 0: off, every output as without it. */
#ifndef BR_FF_H
#define BR_FF_H

#include "bristle/br_est.h"
#include "bristle/br_model.h"
#include "bristle/br_mslip.h"
#include "bristle/br_status.h"

/* Longest prediction horizon accepted, s (a hundred periods at 1 ms: farther
 * than the reference's Taylor travel means anything on a ball screw's circle) */
#define BR_FF_PRED_MAX_S 0.1f

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
    float pred_ahead_s;   /* the prediction's horizon tau, s: 0 off; in (0, BR_FF_PRED_MAX_S] needs
                             the elements (mslip.n >= 1) */
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
 * sigma2 + dsigma2_neg >= 0, ripple period > 0 with a ripple; a prediction
 * horizon 0, or in (0, BR_FF_PRED_MAX_S] with elements); the stored
 * reference starts at rest at 0. BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_ff_init(br_ff_t *ff, const br_ff_cfg_t *cfg);

/* comp_N for the reference in (with elements: those of the stored reference moved
 * by in's travel from it, without storing them). BR_E_NULL, BR_E_STATE (not initialised),
 * BR_E_INPUT (a non-finite input; *comp_N = 0). */
br_status_t br_ff_step(const br_ff_t *ff, const br_ff_in_t *in, float *comp_N);

/* Keeps the reference br_ff_est_step evaluates: the caller sets it before
 * each br_app_step (with elements: they move by the travel from the stored one). BR_E_INPUT (non-finite; the stored one is kept). */
br_status_t br_ff_set_ref(br_ff_t *ff, const br_ff_in_t *in);

/* The prediction dF over the horizon tau from the stored reference (the
 * equations above). z_anchor_m: the element deflections it starts from
 * (cfg.mslip.n of them; NULL: the feedforward's own, driven by the reference);
 * g_anchor_N: the level g1 (NULL: g(v + a tau), eq. 5). Without a horizon
 * (tau = 0) *dF_N = 0. BR_E_NULL, BR_E_STATE (not initialised), BR_E_INPUT (a
 * non-finite anchor, a level <= 0 or not finite), BR_E_NUMERIC (a change that
 * overflows); each with *dF_N = 0. */
br_status_t br_ff_pred_N(const br_ff_t *ff, const float *z_anchor_m, const float *g_anchor_N, float *dF_N);

/* br_est_step_fn over a br_ff_t (ctx): the feedforward as the compensation
 * source of br_app (BR_APP_EST_EXTERN); the measurement is not used. With a
 * horizon, the map at the stored reference plus br_ff_pred_N (own elements). */
br_status_t br_ff_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

#endif
