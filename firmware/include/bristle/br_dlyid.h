/* SPDX-License-Identifier: Apache-2.0 */
/* Actuator-delay identification while the axis runs (docs/modules/dlyid.md):
 * a bank of small Kalman filters, one per candidate delay, all driven by the
 * commands the estimator keeps, scored by their innovations; the estimator
 * takes the best candidate's delay when it is decisively better than the one
 * in use. The configuration and state types; the functions are the
 * estimators' (br_est.h: br_est_dlyid_init, br_est_dlyid_step). */
#ifndef BR_DLYID_H
#define BR_DLYID_H

#include <stdint.h>

/* Most candidate delays. */
#define BR_DLYID_MAX_CAND 8u
/* The filters' state: theta (rad, relative to the last measurement's count),
 * omega (rad/s), the whole friction F (load side, N, a random walk). */
#define BR_DLYID_NX 3

typedef struct {
    uint32_t n_cand;        /* candidates 0, step_s, ..., (n_cand - 1) step_s; 0: off, else 2..BR_DLYID_MAX_CAND */
    float step_s;           /* their spacing, > 0; the largest within the estimator's command history */
    float q_force_N2ps;     /* the filters' friction random walk, variance per second, > 0 */
    float memory_s;         /* time constant of the innovations' forgotten sums, > 0 */
    float warmup_s;         /* no decision before this time after the first measurement, >= 0 */
    float switch_ratio;     /* switch when the best sum is below this times the sum of the delay in
                               use, in (0, 1) */
} br_dlyid_cfg_t;

/* Filters of the bank: the n_cand candidates, then one for the configured
 * delay (model.causes.delay_s, on the grid or not), slot n_cand. */
#define BR_DLYID_MAX_SLOTS (BR_DLYID_MAX_CAND + 1u)

typedef struct {
    float x[BR_DLYID_MAX_SLOTS][BR_DLYID_NX]; /* each slot's filter mean */
    float P[BR_DLYID_NX][BR_DLYID_NX];       /* their common covariance (the delay moves only the input) */
    float J[BR_DLYID_MAX_SLOTS];             /* forgotten sums of squared innovations, rad^2 */
    float forget;                            /* e^(-dt / memory_s) */
    float q_force_N2;                        /* per period */
    float r_rad2;                            /* R + rpc^2 / 12 */
    float a02, a12, b0, b1;                  /* the period's transition and input (ZOH; a01 = dt) */
    uint32_t cm[BR_DLYID_MAX_SLOTS];         /* slot j's delay: cm[j] whole periods */
    float cf[BR_DLYID_MAX_SLOTS];            /* and cf[j] of the next */
    int32_t origin_counts;                   /* the last measurement's count */
    uint32_t k;                              /* periods since the first measurement */
    uint32_t warmup;                         /* periods */
    uint32_t cur;                            /* the slot of the delay in use (n_cand at the start:
                                                the configured delay) */
    uint32_t n_switch;                       /* switches so far */
    int primed;
} br_dlyid_t;

#endif
