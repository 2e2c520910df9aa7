/* SPDX-License-Identifier: Apache-2.0 */
/* The estimators' noise tuning's search space and search settings (docs/tuning.md),
 * shared by the simulator's tuner (sim/apps/br_tune_est.c) and the tuning on
 * the target (sim/apps/br_pil_tune.c, docs/link.md, "Tuning on the target"):
 * the variances tuned, the log-variance start and bounds, the penalty of a
 * run that stopped, and Nelder-Mead's settings (sim/lib/nm). */
#ifndef BR_TUNE_SPACE_H
#define BR_TUNE_SPACE_H

#include "circle/br_circle.h"
#include "nm/br_nm.h"

/* the most variances tuned (the UKF's five) */
#define BR_TUNE_MAX_P 5

/* R's lower bound, counts^2: the variance of the encoder's quantisation, a
 * uniform error of one count (docs/machine-file.md: R = 1/12 count^2 +
 * position_noise_m2, the latter >= 0). A tuned R below it is no setting a
 * machine file can state (firmware/design/machine.py, est_physical), and the
 * UKF tuned without this bound (R 0.012 count^2) lost lock on a delayed plant
 * (docs/tuning.md). The bound sits a relative 1e-6 above it, so that the
 * float32 R written into the header is not below it either. */
#define BR_TUNE_QUANT_COUNTS2 (1.0 / 12.0)
#define BR_TUNE_R_FLOOR_MARGIN (1.0 + 1.0e-6)

/* the objective of a tuning that stops safe (a fault): above any contour RMS
 * a tuning that passes could have (H-inf only's is 2.3e-6 m), times 1 + the
 * share of the run lost, so that the search can leave such a region */
#define BR_TUNE_GUARD_PENALTY_M 1.0e-5

/* The tuned variances: PF (q_omega, q_z, q_gp, R); UKF (q_theta, q_omega, q_z, q_gp, R). */
int br_tune_n_params(int pf);
/* variance i of the circle's filter (pf: the PF's, else the UKF's), per step in its own unit
 * (R in rad^2) */
float *br_tune_param_ptr(br_circle_cfg_t *c, int pf, int i);
/* its name in logs and headers: q_theta, q_omega, q_z, q_gp, r ("?" out of range) */
const char *br_tune_param_name(int pf, int i);

/* The search's start x0 (the log of base's variances) and bounds: each
 * log-variance 3 decades either way; with r_floor, R (the last) not below the
 * quantisation (BR_TUNE_QUANT_COUNTS2), the bound never above the start (a
 * machine file's R at the quantisation itself, position_noise_m2 0, is its
 * start). */
void br_tune_space(const br_circle_cfg_t *base, int pf, int r_floor, double *x0, double *lo, double *hi);

/* Nelder-Mead's settings of the tuning: an initial step of 0.25 in each
 * log-variance (about 0.7 decade from the start), xatol 0.01 (about 3 % of
 * each variance), fatol 1e-12 m (1 pm of contour RMS), the given budget and
 * bounds, no progress callback. */
br_nm_cfg_t br_tune_nm_cfg(int n, const double *lo, const double *hi, int max_fev);

#endif
