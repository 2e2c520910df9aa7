/* SPDX-License-Identifier: Apache-2.0 */
/* Unscented Kalman filter for the friction of one axis (thesis sections 2.3, 4), float32.
 *
 * State x = [theta, omega, z, g_p] of the eq. 6 model (br_model.h), mean x and
 * covariance P (4 x 4), 2n + 1 = 9 sigma points of the scaled unscented
 * transform. One step at t_k, with measurement y_k and the torque u_{k-1}:
 *   1. sigma points  X_0 = x, X_i = x + c S_i, X_{i+n} = x - c S_i,
 *                    P = S S^T (Cholesky), c = sqrt(n + lambda),
 *                    lambda = alpha^2 (n + kappa) - n; g_p clamped to [gp_min, gp_max]
 *   2. predict       Y_j = f_d(X_j, u_{k-1})               (br_model_step)
 *                    x- = sum_j Wm_j Y_j,  P- = sum_j Wc_j (Y_j - x-)(Y_j - x-)^T + Q
 *                    (evaluated about Y_0, without the large Wc_0 of a small alpha)
 *   3. update        h(x) = theta is linear: S = P-_00 + R, K = P-_{:,0} / S,
 *                    x+ = x- + K (y - theta-), P+ = (I - K H) P- (I - K H)^T + K R K^T
 *                    (Joseph form), then symmetrised
 *   4. estimate      F_hat = sum_j Wm_j f_nl(X+_j) over the posterior sigma points
 * A failed Cholesky (pivot <= 0 or non-finite) resets P to diag(p0_var),
 * keeping the mean, and reports BR_E_NUMERIC. An outlier (|y - theta-| >
 * outlier_sigma sqrt(S + rpc^2 / 12) + outlier_transient_rad (eq. G1), the innovation's spread with the
 * encoder's quantisation) skips the update; reanchor_after of them in a row
 * re-anchor the filter on the measurement (as the PF does).
 * With cfg.load the state has a fifth entry, the external force F_d (the
 * torque in step 2 is u - L F_d), a gated innovation that a change of F_d
 * of at most 2 load.max_N explains is re-acquired (P_dd inflated, the
 * period predicted again) instead of rejected, and F_hat is friction + F_d
 * within +-load.max_N (docs/modules/ukf.md, "External force"). A
 * re-acquisition keeps its alternative (the period's first prediction, as an
 * outlier would have committed it); when the next innovation is gated and
 * that alternative, or it moved by the re-acquired innovation (a counter
 * slip), passes the gate (the smaller innovation of the two when both do),
 * the re-acquisition is undone: the step updates the alternative's
 * prediction (docs/modules/ukf.md, "A glitch is not a load").
 * theta is stored relative to an integer origin (the latest accepted count),
 * as in the PF, so float32 keeps sub-count resolution at any travel.
 * See docs/modules/ukf.md. */
#ifndef BR_UKF_H
#define BR_UKF_H

#include <stdint.h>

#include "bristle/br_est.h"
#include "bristle/br_model.h"
#include "bristle/br_status.h"

/* number of sigma points of the thesis's state, 2 n + 1 */
#define BR_UKF_NSIG (2 * BR_NX + 1)
/* with the external force (cfg.load): n = BR_NX + 1, index BR_UKF_X_LOAD */
#define BR_UKF_NMAX (BR_NX + 1)
#define BR_UKF_X_LOAD BR_NX
#define BR_UKF_NSIG_MAX (2 * BR_UKF_NMAX + 1)

/* The external force (a load, a cutting force: docs/modules/ukf.md, "External
 * force"), a fifth state F_d (N, load side, acting as friction does, against
 * +x) with a random walk. Off (the thesis's four states, bit for bit) when
 * p0_N2 is 0. */
typedef struct {
    float q_N2;    /* random-walk variance of F_d per step (N^2), 0 or a normal float <= BR_EST_VAR_MAX */
    float p0_N2;   /* initial (and recovery) variance of F_d (N^2); 0: no external-force state */
    float max_N;   /* |F_d| is kept <= max_N (the actuator's force); a gated innovation that a change of
                      F_d of at most 2 max_N explains is re-acquired as a load, not rejected; > 0 when on */
} br_ukf_load_t;

typedef struct {
    br_est_cfg_t est;        /* what the UKF shares with the PF: model (est.model.dt_s is the UKF's
                                period), noise, g_p range (every sigma point and the mean are kept
                                in it), gates; outlier: |y - theta-| > est.outlier_sigma sqrt(S + rpc^2 / 12)
                                + est.outlier_transient_rad (eq. G1) */
    float p0_var[BR_NX];     /* initial (and recovery) variances P0 = diag(p0_var), > 0 */
    float alpha;             /* sigma-point spread, in (0, 1]; use >= 0.1 in float32 (1 recommended) */
    float beta;              /* prior-distribution weight, >= 0 (2 for a Gaussian) */
    float kappa;             /* secondary scaling, n + kappa > 0 (so n + lambda > 0) */
    br_ukf_load_t load;      /* the external-force state (all 0: off, n = 4) */
} br_ukf_cfg_t;

typedef struct {
    float mean[BR_NX];       /* posterior mean; theta relative to origin_counts */
    float var[BR_NX];        /* diag(P) */
    int32_t origin_counts;   /* integer origin of theta */
    float F_hat_N;           /* unscented mean of f_nl over the posterior sigma points */
    float innov_rad;         /* last innovation y - theta- (0 on the priming step) */
    float innov_var_rad2;    /* its predicted variance S = P-_00 + R */
    float load_N;            /* the external force's mean F_d (0 without cfg.load) */
    float load_var_N2;       /* its variance */
    float elem_m[BR_MSLIP_MAX]; /* the Maxwell-slip elements' deflections (model.mslip.n of
                                   them; 0 for LuGre) */
} br_ukf_est_t;

typedef struct {
    br_ukf_cfg_t cfg;
    br_model_t model;
    int n;                           /* state dimension: BR_NX, or BR_UKF_NMAX with cfg.load */
    float load_rad_per_N2;           /* L dt^2 / (2 J_eff): theta's response to F_d over one period (the
                                        load re-acquisition's force, rad / N; 0 without cfg.load) */
    float c_sigma;                   /* sqrt(n + lambda) */
    float wm0, wc0, wi;              /* weights: Wm_0, Wc_0, and Wm_i = Wc_i = W for i >= 1 */
    float cmm;                       /* beta - alpha^2: the m m^T term of P- about the central point */
    float out_s2;                    /* outlier_sigma^2 */
    float quant_var_rad2;            /* rpc^2 / 12: the encoder's quantisation variance, in the gate */
    float m_per_count;               /* L rpc: load position per encoder count */
    br_est_delay_t delay;            /* commands for the actuator delay (model.causes.delay_s) */
    br_dlyid_t dlyid;             /* the delay's identification (cfg.est.delay_id) */
    float x[BR_UKF_NMAX];            /* mean; theta relative to origin_counts (first n used) */
    float P[BR_UKF_NMAX][BR_UKF_NMAX];   /* covariance, symmetric positive definite */
    float S[BR_UKF_NMAX][BR_UKF_NMAX];   /* scratch: Cholesky factor of the last factorised P (lower) */
    float X[BR_UKF_NSIG_MAX][BR_UKF_NMAX]; /* sigma points (scratch; after a step without error, the posterior's) */
    float Y[BR_UKF_NSIG_MAX][BR_UKF_NMAX]; /* scratch: propagated sigma points of the last step */
    /* The Maxwell-slip elements (cfg.est.model.mslip.n >= 1; docs/modules/ukf.md,
     * "Maxwell-slip elements"): deflections beside the state, propagated with
     * the sigma points and carried as their unscented mean */
    float el[BR_MSLIP_MAX];          /* the committed elements */
    float el_m[BR_MSLIP_MAX];        /* scratch: the last prediction's */
    int32_t origin_counts;
    int32_t prev_counts;             /* last measurement (accepted or not): the measured */
    float prev_frac;                 /*   velocity for a re-anchoring */
    uint32_t n_outliers;             /* consecutive outlier steps */
    uint32_t n_recover;              /* covariance resets to P0 since init (a failed Cholesky
                                        the repair (n_repair) could not mend, or a non-finite
                                        prediction or update) */
    uint32_t n_repair;               /* failed factorisations of a finite P repaired (U9) */
    uint32_t n_predicted;            /* predict-only steps since the last measurement */
    uint32_t n_load_acq;             /* gated innovations re-acquired as a load (cfg.load) */
    uint32_t n_load_undo;            /* re-acquisitions undone by the next innovation (a glitch) */
    /* The last step's re-acquisition's alternative (cfg.load; docs/modules/ukf.md,
     * "A glitch is not a load"): that period's first prediction, as an outlier
     * commits it, in the frame of alt_origin; alt_nu_rad the gated innovation */
    int alt_pending;                 /* 1: the last step re-acquired, the alternative is held */
    float alt_x[BR_UKF_NMAX];
    float alt_P[BR_UKF_NMAX][BR_UKF_NMAX];
    float alt_el[BR_MSLIP_MAX];
    int32_t alt_origin;
    float alt_nu_rad;
    int primed;                      /* x, P set from the first measurement */
    br_ukf_est_t est;
    int ready;
} br_ukf_t;

br_status_t br_ukf_init(br_ukf_t *ukf, const br_ukf_cfg_t *cfg);

/* One filter step (see above). The first step after init primes
 * x = [frac rpc, 0, 0, gp0] (origin = counts), P = diag(p0_var), no predict.
 * Statuses:
 *   BR_E_NULL / BR_E_STATE  NULL argument / not initialised;
 *   BR_E_INPUT    non-finite u, or frac non-finite or outside [0, 1]: state untouched;
 *   BR_W_OUTLIER  |y - theta-| > outlier_sigma sqrt(S + rpc^2 / 12) + d: the prediction is kept
 *                 (origin unchanged), no update; on the reanchor_after-th
 *                 consecutive outlier the filter has lost lock and is
 *                 re-anchored: origin = y.counts, x = [frac rpc, measured
 *                 velocity, z, g_p] (z, g_p means kept), P = diag(p0_var);
 *   BR_E_NUMERIC  a non-finite prediction or update: x and origin are kept
 *                 and P is reset to diag(p0_var) (counted in n_recover), so
 *                 the filter cannot stay stuck; or a Cholesky failure: P was
 *                 reset the same way (the step otherwise completed). */
br_status_t br_ukf_step(br_ukf_t *ukf, const br_meas_t *y, float u_prev_Nm);

/* Predict-only step for a period without a measurement (a failed or missing
 * encoder read): steps 1-2 with u_{k-1}, x = x-, P = P- (the spread grows by
 * Q each period), origin unchanged; the estimate is the unscented mean of
 * f_nl over the predicted sigma points. The next br_ukf_step updates as
 * usual; a re-anchoring after a gap takes the measured velocity over all the
 * periods since the last measurement. BR_E_STATE before the first
 * measurement, BR_E_INPUT for a non-finite u, BR_E_NUMERIC as for a step. */
br_status_t br_ukf_predict(br_ukf_t *ukf, float u_prev_Nm);

/* Fixed-size 4 x 4 Cholesky factorisation A = L L^T (L lower, upper part
 * zeroed). BR_E_NUMERIC on a pivot <= 0 or a non-finite value (L then undefined). */
br_status_t br_ukf_chol4(const float A[BR_NX][BR_NX], float L[BR_NX][BR_NX]);

/* The last step's estimate (NULL for a NULL filter). */
const br_ukf_est_t *br_ukf_estimate(const br_ukf_t *ukf);

/* br_est_t binding: ctx is a br_ukf_t *. step: br_ukf_step, *F_hat_N the
 * compensation, written on BR_OK and on BR_W_OUTLIER (the prediction's
 * estimate), as for the PF; predict: br_ukf_predict, *F_hat_N the predicted
 * estimate's F_hat_N (written unless the status is an error); reset:
 * br_ukf_init from the filter's own configuration. */
br_status_t br_ukf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);
br_status_t br_ukf_est_predict(void *ctx, float u_prev_Nm, float *F_hat_N);
br_status_t br_ukf_est_reset(void *ctx);

/* The three above over ukf, as the application drives it. */
br_est_t br_ukf_est(br_ukf_t *ukf);

#endif
