/* SPDX-License-Identifier: Apache-2.0 */
/* What every friction estimator (PF, UKF) shares: the configuration common
 * to both, the measurement it takes and the interface through which the
 * application drives it (br_est_t: step, predict, reset). */
#ifndef BR_EST_H
#define BR_EST_H

#include <stdint.h>

#include "bristle/br_dlyid.h"
#include "bristle/br_model.h"
#include "bristle/br_status.h"

/* Largest variance an estimator accepts, in any of its units (rad^2,
 * (rad/s)^2, m^2, N^2): a standard deviation of 1e6 rad, rad/s, m or N is no
 * physical setting, and beyond it the float32 sigma points, squared residuals
 * and the eq. 6 prediction of a spread-out state lose the range they need. */
#define BR_EST_VAR_MAX 1.0e12f
/* Widest outlier gate, in standard deviations: a gate of a million is no gate,
 * and its square must stay a float (the PF's log-weight threshold). */
#define BR_EST_GATE_MAX_SIGMA 1.0e6f
/* Largest transient term of the outlier gate (outlier_transient_rad), in
 * encoder counts: a million counts of friction transient within one period is
 * no axis's; the bound keeps the gate's square and the NIS cap finite floats
 * (each filter checks its own constants too). */
#define BR_EST_GATE_MAX_TRANSIENT_COUNTS 1.0e6f
/* Smallest measurement variance, in encoder counts^2: a millionth of a count^2
 * is far below any quantised encoder's noise (1/12 count^2), and it keeps
 * 1 / (2 R) and the log-weights finite. */
#define BR_EST_R_MIN_COUNTS2 1.0e-6f
/* Longest compensation lead beyond the actuator delay, in periods
 * (comp_ahead_periods): two periods carry the model further than any
 * zero-order hold needs (half a period is its centre). */
#define BR_EST_AHEAD_MAX_PERIODS 2.0f

/* The configuration the PF and the UKF share (each embeds it as `est`). */
typedef struct {
    br_model_cfg_t model;    /* eq. 6 model; model.dt_s is the estimator's period */
    float q_var[BR_NX];      /* process noise variance per step: rad^2, (rad/s)^2, m^2, N^2; >= 0 */
    float r_var_rad2;        /* measurement noise variance, > 0 */
    float gp0_N;             /* initial g_p, in [gp_min_N, gp_max_N] */
    float gp_min_N;          /* g_p is kept in [gp_min_N, gp_max_N], 0 < min < max */
    float gp_max_N;
    float outlier_sigma;     /* a measurement further than outlier_sigma standard deviations from the
                                whole estimate is an outlier, > 0 (each filter says which deviation) */
    float outlier_transient_rad; /* the gate's transient term d: an outlier is further than
                                    outlier_sigma deviations + d (rad; the friction transient's
                                    displacement over a period, docs/modules/pf.md, "The gate");
                                    0: the thesis gate, in [0, BR_EST_GATE_MAX_TRANSIENT_COUNTS rpc] */
    uint32_t reanchor_after; /* consecutive outliers before the filter is re-anchored on y, >= 1 */
    float rad_per_count;     /* encoder resolution, > 0 */
    float comp_ahead_periods; /* 0: the compensation is the filtered estimate (the thesis);
                                 > 0: the force predicted over the actuator delay and this many
                                 periods beyond it (br_est_comp_N), <= BR_EST_AHEAD_MAX_PERIODS */
    br_dlyid_cfg_t delay_id;  /* actuator-delay identification while running; n_cand = 0: off */
} br_est_cfg_t;

/* Checks the shared configuration: the model (br_model_init's checks, the
 * causes' included; the delay at most BR_EST_DELAY_HIST - 2 periods), an
 * encoder resolution > 0, process-noise variances 0 or normal floats up to
 * BR_EST_VAR_MAX (no subnormals), R from BR_EST_R_MIN_COUNTS2 counts^2 up to
 * BR_EST_VAR_MAX, 0 < gp_min < gp_max with gp0 inside, an outlier gate in
 * (0, BR_EST_GATE_MAX_SIGMA] with a transient term finite in
 * [0, BR_EST_GATE_MAX_TRANSIENT_COUNTS rad_per_count], at
 * least one outlier before re-anchoring, a compensation lead in
 * [0, BR_EST_AHEAD_MAX_PERIODS], and the delay identification off or within
 * br_dlyid_cfg_t's ranges (its largest candidate within the command history).
 * BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_est_cfg_check(const br_est_cfg_t *cfg);

/* The outlier gate's factor f^2 = (1 + d / (g sqrt(v)))^2 (eq. G1,
 * docs/modules/pf.md, "The gate"; g = cfg->outlier_sigma, d =
 * cfg->outlier_transient_rad): the gate g sqrt(v) + d of a residual of variance
 * v is f times g sqrt(v); exactly 1 when d = 0 (the thesis gate, bit for bit).
 * v > 0; infinite for a gate beyond the float range (each filter's init refuses it). */
float br_est_gate_f2(const br_est_cfg_t *cfg, float v);

/* 1 when v is a usable variance: a normal float in [FLT_MIN, BR_EST_VAR_MAX],
 * or exactly 0 where zero_ok. */
int br_est_var_ok(float v, int zero_ok);

/* Commands the estimators keep for an actuator delay (model.causes.delay_s):
 * delays up to BR_EST_DELAY_HIST - 2 periods. */
#define BR_EST_DELAY_HIST 64u

/* The torque that reached the axis over the last period, from the commands:
 * with the delay d = (m + f) dt (m whole periods, 0 <= f < 1) and each command
 * held over its period, u_a = (1 - f) u[k-1-m] + f u[k-2-m] (0 before the
 * first command). No delay: u_a is the last command itself. */
typedef struct {
    float u[BR_EST_DELAY_HIST]; /* commanded torques, newest at head */
    uint32_t head;
    uint32_t n;                 /* commands kept, <= BR_EST_DELAY_HIST */
    uint32_t m;                 /* whole periods of the delay */
    float f;                    /* its fraction of a period */
    int on;                     /* delay_s > 0, or the delay identification on: the history is kept */
} br_est_delay_t;

/* 1 when a delay of delay_s at the period dt_s lies within the history:
 * delay_s <= (BR_EST_DELAY_HIST - 2) dt_s (NaN: 0). */
int br_est_delay_fits(float delay_s, float dt_s);

/* Empties the history for the configuration's delay (checked by br_est_cfg_check). */
void br_est_delay_init(br_est_delay_t *d, const br_est_cfg_t *cfg);

/* Empties the history for a delay of delay_s at the period dt_s (within the
 * history: br_est_delay_fits); on = 0: no history, the last command itself. */
void br_est_delay_reset(br_est_delay_t *d, float delay_s, float dt_s, int on);

/* Keeps u_prev_Nm, the command held over the last period, and returns the
 * torque that reached the axis over it. */
float br_est_delay_apply(br_est_delay_t *d, float u_prev_Nm);

/* The torque that reached the axis over the last period for a delay of m + f
 * periods (0 <= f < 1, m <= BR_EST_DELAY_HIST - 2), from d's history (call
 * after br_est_delay_apply): (1 - f) u[k-1-m] + f u[k-2-m]. */
float br_est_delay_torque(const br_est_delay_t *d, uint32_t m, float f);


/* The force to compensate (docs/modules/est.md, "Compensating ahead").
 * With cfg->comp_ahead_periods = lambda = 0 it is F_hat_N itself. Otherwise
 * the estimate x (theta relative to p0_m) is carried by the model over
 * H = delay / dt + lambda periods, each period with the torque that will
 * reach the axis over it (from d's history; u_prev_Nm, the newest command,
 * stands in for the ones not yet computed) less L F_ext_N (the external force
 * the estimator carries, held over H: its random walk's prediction; 0
 * without one), and
 *   F_comp = F_hat + f_c(x(t + H dt)) - f_c(x)
 * with f_c(x(t + H dt)) interpolated linearly inside its last period. A step
 * the model refuses (a state out of its range) gives F_hat_N, no lead; the
 * controller refuses a compensation out of range (br_ctrl). Call after the
 * estimator's step (d then holds u_prev_Nm). */
float br_est_comp_N(const br_est_cfg_t *cfg, const br_model_t *m, const br_est_delay_t *d,
                    const float x[BR_NX], float p0_m, float u_prev_Nm, float F_ext_N, float F_hat_N);

/* Encoder measurement: position = (counts + frac) counts. For a plain
 * quadrature encoder (floor quantisation) pass frac = 0.5, the centre of the
 * count; an interpolating encoder passes its sub-count position in [0, 1). */
typedef struct {
    int32_t counts;  /* free-running, wraps modulo 2^32 */
    float frac;      /* finite, in [0, 1] */
} br_meas_t;

/* The actuator-delay identification (br_dlyid.h, docs/modules/dlyid.md) over
 * the estimator's configuration: cfg->delay_id, with the model, the encoder,
 * R and g_p's bound of cfg. init: br_dlyid_init (the configured delay's slot
 * in use, where br_est_delay_init starts d). */
void br_est_dlyid_init(br_dlyid_t *id, const br_est_cfg_t *cfg);

/* One period, after br_est_delay_apply has kept the last command: br_dlyid_step
 * with each slot's torque from d's history (br_est_delay_torque); when the
 * bank switches, d's delay becomes the new slot's (id->n_switch counts the
 * switches). Off (n_cand = 0): nothing. */
void br_est_dlyid_step(br_dlyid_t *id, const br_est_cfg_t *cfg, const br_meas_t *y, br_est_delay_t *d);

/* The estimator interface (docs/modules/est.md, "The interface"): what the
 * application calls, whatever the estimator is. */

/* One estimator step: y is the measurement at t_k, u_prev_Nm the torque that
 * was applied over [t_{k-1}, t_k]. Unless the status is an error (negative),
 * *F_hat_N is the compensation force at t_k (load side, N: the friction
 * estimate f_nl, or the force predicted ahead, br_est_comp_N); BR_W_OUTLIER
 * means the measurement was skipped and the estimate is the prediction's. */
typedef br_status_t (*br_est_step_fn)(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

/* A period without a measurement (a failed encoder read): the estimator
 * predicts over it with u_prev_Nm. Unless the status is an error, *F_hat_N is
 * the predicted estimate at t_k. */
typedef br_status_t (*br_est_predict_fn)(void *ctx, float u_prev_Nm, float *F_hat_N);

/* Starts the estimator again from its own configuration (at an arm): primed
 * again at the next measurement. BR_OK or the re-initialisation's error. */
typedef br_status_t (*br_est_reset_fn)(void *ctx);

typedef struct {
    void *ctx;
    br_est_step_fn step;       /* required */
    br_est_predict_fn predict; /* NULL: the estimate is held over a period without a measurement */
    br_est_reset_fn reset;     /* NULL: nothing to start again (an estimator the caller restarts) */
} br_est_t;

/* One period of the estimator e, the one call through which a period reaches
 * it: y the period's measurement, or NULL for a period without one (then
 * e->predict, or the estimate held: BR_OK, *F_hat_N unchanged). Returns the
 * step's or the prediction's status; BR_E_NULL for a NULL e, e->step or
 * F_hat_N. */
br_status_t br_est_period(const br_est_t *e, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

/* Starts e again (e->reset; BR_OK when it has none). BR_E_NULL for a NULL e. */
br_status_t br_est_restart(const br_est_t *e);

/* The step inputs both estimators accept: u finite, frac finite and in [0, 1];
 * BR_OK, else BR_E_INPUT. */
br_status_t br_est_check_step(const br_meas_t *y, float u_prev_Nm);

#endif
