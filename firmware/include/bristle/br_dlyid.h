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
/* After a velocity reversal that ended a run of at least this many
 * presliding lengths g_p,max / sigma0, the innovations are not scored until
 * the axis has travelled as far again (dly7): LuGre's bristle state settles
 * with the e-folding distance g(v) / sigma0 <= g_p,max / sigma0, so after
 * three lengths 95 % of the friction's jump is through. */
#define BR_DLYID_SETTLE_LENGTHS 3.0f
/* A candidate is taken only when the delay in use explains the motion worse
 * than the noise allows (dly6): its forgotten sum above this factor times
 * (R' + P+_00) / (1 - e^(-T / memory_s)), the encoder's noise and the filtered
 * position's own uncertainty over the sums' memory. Chosen on measured runs:
 * docs/modules/dlyid.md, "False switches". */
#define BR_DLYID_NOISE_FACTOR 2.0f

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
    float settle_rad;                        /* BR_DLYID_SETTLE_LENGTHS g_p,max / (sigma0 L), rad */
    float settle_left_rad;                   /* travel left before the innovations are scored again */
    float run_rad;                           /* travel since the last reversal */
    int32_t dir;                             /* the sign of the velocity in use's filter: -1, +1; 0 at rest
                                                since the start */
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
