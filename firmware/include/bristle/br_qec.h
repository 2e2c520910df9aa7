/* SPDX-License-Identifier: Apache-2.0 */
/* Reversal (quadrant-error) compensation: the industrial baseline CNC controls
 * ship against the quadrant glitch of a circle (docs/modules/qec.md). At each
 * sign change of the reference velocity a force pulse in the new direction is
 * added to the compensation and decays with a time constant, its amplitude
 * scaled by the reference's acceleration at the reversal; optionally on top of
 * the static friction feedforward (br_ff). Evaluated on the reference only:
 *
 *   s_k    = sgn(v_k) (0 at v_k = 0);  d_k = the last non-zero s (0 before any motion)
 *   reversal at k: s_k != 0 and s_k != d_{k-1}  (a start from rest counts)
 *   A      = max(0, A0 + A1 |a_k|)                        (amplitude at the reversal)
 *   p_k    = s_k A  at a reversal,  else  p_k = rho p_{k-1},  rho = exp(-dt / tau)
 *   comp_N = clamp(p_k + [F_ff(v_k, a_k, x_k)], -comp_max, comp_max)
 *
 * (the exponential decay: a step through a first-order lag, one time constant,
 * the form of the drives' friction-compensation pulse; docs/modules/qec.md). */
#ifndef BR_QEC_H
#define BR_QEC_H

#include "bristle/br_est.h"
#include "bristle/br_ff.h"
#include "bristle/br_status.h"

typedef struct {
    float A0_N;       /* pulse amplitude at zero acceleration, >= 0 */
    float A1_kg;      /* its change per |a_ref| (N per m/s^2), finite; the amplitude is kept >= 0 */
    float tau_s;      /* decay time constant, > 0 */
    float dt_s;       /* the period between two br_qec_set_ref calls, > 0 */
    float comp_max_N; /* output clamp, > 0 (the controller's tau_max / L) */
    int with_ff;      /* 0: the pulse alone; 1: the pulse on top of the static feedforward ff */
    br_ff_cfg_t ff;   /* with_ff = 1: the feedforward (checked by br_ff_init) */
} br_qec_cfg_t;

typedef struct {
    br_qec_cfg_t cfg;
    float rho;      /* exp(-dt / tau): the pulse's factor per period */
    float pulse_N;  /* p_k at the stored reference */
    int dir;        /* d_k: the last non-zero sign of the reference velocity, 0 before any motion */
    br_ff_in_t in;  /* the stored reference */
    br_ff_t ff;     /* the feedforward (with_ff) */
    int ready;
} br_qec_t;

/* Validates cfg (A0 >= 0, A1 finite, tau, dt, comp_max > 0, with_ff 0 or 1 and
 * then a valid feedforward); no pulse, at rest. BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_qec_init(br_qec_t *q, const br_qec_cfg_t *cfg);

/* The period's reference (load side; once per period, before br_app_step):
 * detects a reversal, starts or decays the pulse, moves the feedforward.
 * BR_E_NULL, BR_E_STATE (not initialised), BR_E_INPUT (non-finite; nothing
 * changes). */
br_status_t br_qec_set_ref(br_qec_t *q, const br_ff_in_t *in);

/* comp_N at the stored reference. BR_E_NULL, BR_E_STATE, BR_E_INPUT (a
 * non-finite sum; *comp_N = 0). */
br_status_t br_qec_comp(const br_qec_t *q, float *comp_N);

/* br_est_step_fn over a br_qec_t (ctx): the compensation source of br_app
 * (BR_APP_EST_EXTERN); the measurement is not used. */
br_status_t br_qec_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

#endif
