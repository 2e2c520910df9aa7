/* What every friction estimator (PF, UKF) shares: the measurement it takes
 * and the interface through which the axis loop drives it. */
#ifndef BR_EST_H
#define BR_EST_H

#include <stdint.h>
#include "bristle/br_status.h"

/* Encoder measurement: position = (counts + frac) counts. For a plain
 * quadrature encoder (floor quantisation) pass frac = 0.5, the centre of the
 * count; an interpolating encoder passes its sub-count position in [0, 1). */
typedef struct {
    int32_t counts;  /* free-running, wraps modulo 2^32 */
    float frac;      /* finite, in [0, 1] */
} br_meas_t;

/* One estimator step: y is the measurement at t_k, u_prev_Nm the torque that
 * was applied over [t_{k-1}, t_k]; on BR_OK *F_hat_N is the friction
 * estimate f_nl at t_k (load side, N). */
typedef br_status_t (*br_est_step_fn)(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

typedef struct {
    void *ctx;
    br_est_step_fn step;
} br_est_t;

/* The checks the PF and the UKF share: process-noise variances finite and
 * >= 0, R > 0, 0 < gp_min < gp_max with gp0 inside, an outlier gate > 0, at
 * least one outlier before re-anchoring, an encoder resolution > 0.
 * BR_OK or BR_E_PARAM. */
br_status_t br_est_check_common(const float q_var[4], float r_var_rad2, float gp0_N, float gp_min_N, float gp_max_N,
                                float outlier_sigma, uint32_t reanchor_after, float rad_per_count);

/* The step inputs both estimators accept: u finite, frac finite and in [0, 1];
 * BR_OK, else BR_E_INPUT. */
br_status_t br_est_check_step(const br_meas_t *y, float u_prev_Nm);

#endif
