/* SPDX-License-Identifier: Apache-2.0 */
/* Actuator-delay identification while the axis runs (docs/modules/dlyid.md):
 * a bank of small Kalman filters, one per candidate delay, all driven by the
 * commands the estimator keeps, scored by their innovations; the estimator
 * takes the best candidate's delay when it is decisively better than the one
 * in use. A module below the estimators: it reads the model's configuration
 * and what the caller hands it, never the estimators' types (br_est.h wraps
 * it for the PF and the UKF: br_est_dlyid_init, br_est_dlyid_step). */
#ifndef BR_DLYID_H
#define BR_DLYID_H

#include <stdint.h>

#include "bristle/br_model.h"

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
    /* The steady phase (docs/modules/dlyid.md, "A fast start, a slow steady state"): from
     * steady_after_s after the first measurement on, the sums forget with steady_memory_s and
     * a switch needs steady_switch_ratio (and dly6's noise floor is at that memory). 0: one
     * phase, the settings above throughout (bit for bit as without the fields). */
    float steady_after_s;      /* >= 0, <= 1e9 periods; 0: off */
    float steady_memory_s;     /* > 0 when steady_after_s > 0 */
    float steady_switch_ratio; /* in (0, 1) when steady_after_s > 0 */
} br_dlyid_cfg_t;

/* Filters of the bank: the n_cand candidates, then one for the configured
 * delay (model.causes.delay_s, on the grid or not), slot n_cand. */
#define BR_DLYID_MAX_SLOTS (BR_DLYID_MAX_CAND + 1u)

typedef struct {
    float x[BR_DLYID_MAX_SLOTS][BR_DLYID_NX]; /* each slot's filter mean */
    float P[BR_DLYID_NX][BR_DLYID_NX];       /* their common covariance (the delay moves only the input) */
    float J[BR_DLYID_MAX_SLOTS];             /* forgotten sums of squared innovations, rad^2 */
    float forget;                            /* e^(-dt / memory_s) */
    float forget_steady;                     /* e^(-dt / steady_memory_s) (the steady phase) */
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
    uint32_t steady;                         /* periods before the steady phase (UINT32_MAX: none) */
    uint32_t cur;                            /* the slot of the delay in use (n_cand at the start:
                                                the configured delay) */
    uint32_t n_switch;                       /* switches so far */
    int primed;
} br_dlyid_t;

/* What the bank reads of the estimator it serves (br_est_cfg_t holds each). */
typedef struct {
    const br_model_cfg_t *model; /* the period, lead, inertias, sigma0 and the configured delay
                                    (causes.delay_s) */
    float rad_per_count;         /* encoder resolution, > 0 */
    float r_var_rad2;            /* the estimator's measurement noise variance, > 0 */
    float gp_max_N;              /* g_p's upper bound, > 0 */
} br_dlyid_axis_t;

/* A delay of delay_s at the period dt_s as *m whole periods and the fraction
 * *f of the next, 0 <= f < 1 (the caller keeps delay_s / dt_s within uint32).
 * The one split of a delay into periods: the bank's candidates and the
 * estimators' command history (br_est_delay_init) both use it. */
void br_dlyid_periods(float delay_s, float dt_s, uint32_t *m, float *f);

/* 1 when c is off (n_cand = 0) or within br_dlyid_cfg_t's ranges with finite
 * constants (dly1) at ax's period (ax checked before: a model br_model_init
 * accepts, rad_per_count, r_var_rad2 and gp_max_N finite and > 0). Whether the
 * largest candidate fits a command history is the caller's check. */
int br_dlyid_cfg_ok(const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax);

/* Candidate j's delay j step_s in periods, its filters unprimed, the
 * configured delay's slot (n_cand) in use. Off (n_cand = 0): nothing. */
void br_dlyid_init(br_dlyid_t *id, const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax);

/* One period's measurement (counts + frac counts): every slot's filter
 * predicts with u_Nm[j], the torque its delay (cm[j] + cf[j] periods) brought
 * over the last period (from the caller's command history), and takes the
 * measurement (dly2-dly5). Once past the warm-up, when the best slot's
 * forgotten sum of squared innovations is below switch_ratio times that of
 * the slot in use and the one in use explains the motion worse than the noise
 * allows, the best becomes the one in use (dly6, dly7) and 1 is returned: the
 * caller then models the delay cm[cur] + cf[cur] periods. A filter that is
 * not finite restarts the bank at the next measurement, nothing switched.
 * Off (n_cand = 0): 0, nothing read. */
int br_dlyid_step(br_dlyid_t *id, const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax, int32_t counts, float frac,
                  const float u_Nm[BR_DLYID_MAX_SLOTS]);

#endif
