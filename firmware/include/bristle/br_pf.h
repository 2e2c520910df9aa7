/* SPDX-License-Identifier: Apache-2.0 */
/* Particle filter for the friction of one axis (thesis sections 2.3, 4), float32.
 *
 * Particles x_j = [theta, omega, z, g_p] of the eq. 6 model (br_model.h).
 * One step at t_k, with measurement y_k and the torque u_{k-1} of the last period:
 *   1. predict    x_j <- f_d(x_j, u_{k-1}) + sqrt(Q) n_j     n_j from the ROM table
 *   2. weigh      l_j = -(theta_j - y_k)^2 / (2 R),  w_j = e^(l_j - max l)   (max-shifted)
 *   3. quantise   W_j = floor(w_j 2^16) (the best particle has W = 2^16 > 0)
 *   4. resample   xi_i = (i + 1/2) / m; particle i copies the j with
 *                 C_{j-1} <= xi_i C_m < C_j, C_j = W_0 + ... + W_j, in integers
 *   5. estimate   F_hat = mean of f_nl(x_j) (eq. 6); the particle mean and the
 *                 ESS on request (br_pf_stats), not in the step
 * With a Maxwell-slip element set in the model (est.model.mslip.n = N >= 1)
 * each particle carries its own N element deflections e_j, stepped by the
 * clamp model (br_model_ms_step's trapezoidal step), z's noise their common
 * perturbation, f_nl = sum_i k_i e_ji (docs/modules/pf.md).
 * theta is stored relative to the latest measured count (an integer origin),
 * so float32 keeps sub-nanometre resolution at any travel.
 * See docs/modules/pf.md. */
#ifndef BR_PF_H
#define BR_PF_H

#include <stdint.h>

#include "bristle/br_est.h"
#include "bristle/br_model.h"
#include "bristle/br_status.h"

#ifndef BR_PF_MAX_PARTICLES
#define BR_PF_MAX_PARTICLES 2048u
#endif
/* weight quantisation: W in [0, 2^16]; the resampling works on 2 C_m <= 2^17 m,
 * which fits uint32 for m < 2^15 (and the indices fit uint16) */
#define BR_PF_W_BITS 16u
#if BR_PF_MAX_PARTICLES > 32767u
#error "BR_PF_MAX_PARTICLES must keep 2^17 m inside uint32 (m < 2^15)"
#endif
/* Maxwell-slip element deflections the particles carry (est.model.mslip.n
 * >= 1; docs/modules/pf.md, "Maxwell-slip elements"): n m <= BR_PF_MS_SLOTS,
 * by default four elements at the largest m (32 KiB; eight at m <= 1024) */
#ifndef BR_PF_MS_SLOTS
#define BR_PF_MS_SLOTS (4u * BR_PF_MAX_PARTICLES)
#endif
#if BR_PF_MS_SLOTS < 1u
#error "BR_PF_MS_SLOTS must be at least 1"
#endif

/* cfg.adapt: nis_ref below this is refused (E / nis_ref stays finite:
 * a step's NIS is limited to the gate's, (g + d / sigma)^2, at most
 * (1e6 + 1e6 sqrt(12))^2 < 3e13 by the gate's bounds, sigma >= rpc / sqrt(12)) */
#define BR_PF_ADAPT_REF_MIN 1.0e-6f

/* Innovation-driven process noise (docs/modules/pf.md, "Keeping lock"): a
 * variant of the thesis filter, off when nis_ref = 0. Each measured step
 * takes the normalised innovation squared of the predicted cloud,
 *   NIS = (y - mean theta_j)^2 / (var theta_j + R + rpc^2 / 12),
 * limited to the NIS of a step at the gate, (outlier_sigma + d / sqrt(R +
 * rpc^2 / 12))^2 with the gate's transient term d (a glitch counts as much as
 * a step at the gate), smooths it, E <- E + alpha (NIS - E), and the next predictions draw the
 * process noise of omega, z and g_p with the variances times
 *   s = min(max(E / nis_ref, 1), max_scale)
 * (standard deviations times sqrt(s)). While E <= nis_ref, s = 1 and the
 * arithmetic is the thesis filter's bit for bit. */
typedef struct {
    float nis_ref;   /* 0: off; > 0: the smoothed NIS above which the noise grows */
    float alpha;     /* smoothing per measured step, (0, 1] (when on) */
    float max_scale; /* largest variance factor, >= 1 (when on) */
} br_pf_adapt_t;

/* cfg.gp_curve (docs/modules/pf.md, "Fast moves: g_p along the Stribeck
 * curve"): off (on = 0) g_p is a random walk, g_p' = 0 (the thesis). On, the
 * walk is on g_p's offset from the model's curve g(v) = Fc + (Fs - Fc)
 * e^(-|v| / vs) (eq. 5), which relaxes towards 0 by rho per step:
 *   g_p <- g(L w1) + rho (g_p - g(L w0)) + sqrt(q_g) n
 * (w0, w1 the particle's speed before and after the step), and a
 * re-anchoring moves g_p with the velocity it moves. Runs the per-particle
 * step for every particle (the kernels are the thesis model's). */
typedef struct {
    uint32_t on;     /* 0: off (the thesis filter), 1: on */
    float rho;       /* the offset's factor per step, [0, 1] (1: no relaxation) */
} br_pf_gp_curve_t;

/* cfg.proposal (docs/modules/pf.md, "A proposal that uses the measurement"):
 * how step 1 draws theta and omega. PRIOR: the thesis's bootstrap filter
 * (x_j <- f_d(x_j) + sqrt(Q) n_j, weighed by the likelihood). OPT: the
 * locally optimal proposal of this model: theta_j drawn from
 * p(theta | predicted mean, y), the weight the predictive likelihood
 * N(y; mean theta_j, Q_theta + R); omega, z, g_p as the prior draws them.
 * OPT_HELD: omega's process noise taken as an acceleration held over the
 * period (it moves theta by h/2 of it), so theta and omega are correlated in
 * Q and the proposal corrects both. A measured step only; the scalar path
 * runs it (the vector path's loops are the prior's). */
/* cfg.load (docs/modules/pf.md, "External force"): one load force F_d (N,
 * load side, against +x as friction is) shared by every particle, estimated
 * by a scalar Kalman filter beside the particles. Off (the thesis filter, bit
 * for bit) when both fields are 0. On, each step predicts the particles with
 * the torque u - L F_d; a Kalman filter of the cloud's common error
 * [theta, omega, F_d] (g = L h^2 / (2 J_eff): theta's change over a period
 * per newton) takes the predicted cloud's mean innovation, moves the cloud's
 * theta and omega by its gain and F_d by its third component, and the
 * moved cloud is then weighed and resampled; the compensation is f_nl plus
 * F_d through a notch at the PF's Nyquist frequency (the loop's period-2
 * mode, which an actuator delay of a period or more makes unstable).
 * A gated innovation that a change of at most 2 max_N over the k periods
 * since the last measurement explains (theta moved by -g k^2 dF) is
 * re-acquired as a load (the covariance inflated as if F_d's variance had
 * been larger by the change squared), not rejected; when the next step's
 * innovation is gated, the re-acquisition is tested as a counter glitch (a
 * spike, or a slip the counter keeps) and undone if one explains it. The
 * kernels are untouched: only the torque they are given changes. */
typedef struct {
    float q_N2;  /* random walk of F_d per step, N^2: a normal float <= BR_EST_VAR_MAX when on, 0: off */
    float max_N; /* |F_d| and the compensation kept <= max_N (the actuator's force); its initial
                    variance is max_N^2; > 0 when on, 0: off */
} br_pf_load_t;

#define BR_PF_PROPOSAL_PRIOR 0u
#define BR_PF_PROPOSAL_OPT 1u
#define BR_PF_PROPOSAL_OPT_HELD 2u

typedef struct {
    br_est_cfg_t est;        /* what the PF shares with the UKF: model (est.model.dt_s is the PF's
                                period), noise, g_p range, gates; outlier: |y - theta_j| >
                                est.outlier_sigma sqrt(R + rpc^2 / 12) + est.outlier_transient_rad
                                for every particle j (eq. G1) */
    uint32_t n_particles;    /* m, 1..BR_PF_MAX_PARTICLES */
    float x0_std[BR_NX];     /* initial spread around [y_0, 0, 0, gp0]; >= 0 */
    const float *noise;      /* standard-normal ROM table (e.g. br_noise_table) */
    uint32_t noise_len;      /* its length, a power of two >= 2 */
    uint32_t noise_skip;     /* extra table advance per step (indexing scheme, docs/modules/pf.md) */
    uint32_t scalar_path;    /* 1: the scalar reference path (one particle at a time, with branches);
                                0 (default): the structure-of-arrays loops the compiler vectorises,
                                the rare cases fixed up in scalar; both give identical results */
    br_pf_adapt_t adapt;     /* innovation-driven process noise of omega, z and g_p (all 0: off) */
    uint32_t proposal;       /* BR_PF_PROPOSAL_*: 0 (default) the thesis's bootstrap filter */
    br_pf_gp_curve_t gp_curve; /* g_p along the model's Stribeck curve (on = 0: off, g_p' = 0) */
    br_pf_load_t load;       /* the shared external force (all 0: off) */
} br_pf_cfg_t;

/* What each step makes: the force to compensate and theta's origin. */
typedef struct {
    int32_t origin_counts;   /* integer origin of theta */
    float F_hat_N;           /* mean f_nl over particles */
} br_pf_est_t;

/* Diagnostics made on request by br_pf_stats from the filter's state (the
 * control loop does not need them; docs/modules/pf.md, "Statistics on
 * request"). */
typedef struct {
    float mean[BR_NX];       /* particle mean; theta relative to br_pf_est_t.origin_counts */
    float ess;               /* effective sample size of the last step's weights, 1..m;
                                m after the first measurement and a predict-only step;
                                0 after a step that had no usable particle (BR_E_NUMERIC) */
} br_pf_stats_t;

/* how the last step weighed the particles (br_pf_stats' ESS) */
#define BR_PF_WEIGHED_EQUAL 0u   /* all alike: ESS = m */
#define BR_PF_WEIGHED_LOG 1u     /* w_j = e^(l_j - lmax) */
#define BR_PF_WEIGHED_VALID 2u   /* an outlier step: w_j = 1 for a valid particle, 0 otherwise */
#define BR_PF_WEIGHED_NONE 3u    /* no usable particle: ESS = 0 */

typedef struct {
    br_pf_cfg_t cfg;
    br_model_t model;
    float q_std[BR_NX];
    float inv_2r;                 /* 1 / (2 R) */
    float m_per_count;            /* L rpc: load position per encoder count */
    br_est_delay_t delay;         /* commands for the actuator delay (model.causes.delay_s) */
    br_dlyid_t dlyid;             /* the delay's identification (cfg.est.delay_id) */
    float outlier_l;              /* -outlier_sigma^2 (R + rpc^2 / 12) f^2 / (2 R): log-weight threshold,
                                     f = 1 + d / (outlier_sigma sqrt(R + rpc^2 / 12)), d the transient term */
    float gate_nis;               /* cfg.adapt's NIS cap, (outlier_sigma f)^2: a step's NIS at the gate */
    uint32_t noise_pos;           /* table position, advances every step */
    int32_t origin_counts;
    float prev_frac;              /* the last measurement's fraction */
    uint32_t n_outliers;          /* consecutive outlier steps */
    uint32_t n_predicted;         /* predict-only steps since the last measurement */
    float r_gate;                 /* R + rpc^2 / 12, rad^2 */
    float nis_avg;                /* cfg.adapt: the smoothed NIS, E */
    float q_scale_std;            /* cfg.adapt: sqrt(s), the factor on omega's, z's and g_p's noise std (1: the thesis filter) */
    /* cfg.proposal (constants of the step, from Q, R and h at init): the gains
     * of theta and omega on the predicted residual, the Cholesky factor
     * [l00 0; l10 l11] of their covariance given y, 1 / (2 S) with
     * S = Q_theta' + R, and the prior's coupling h/2 sqrt(Q_omega) of omega's
     * sample into theta (OPT_HELD; 0 otherwise) */
    float prop_k_th, prop_k_om, prop_l00, prop_l10, prop_l11, prop_inv_2s, prop_hold;
    /* cfg.load: the shared external force's estimate F_d (N), its value at the period's start
     * (load_prev_N, before the update) and F_d through the compensation's notch (load_comp_N);
     * the covariance of the cloud's common
     * error [theta, omega, F_d] (rad, rad/s, N), its upper triangle P00 P01 P02 P11 P12 P22;
     * g = L h^2 / (2 J_eff) (rad per N over one period); the re-acquisitions counted.
     * The last step's re-acquisition kept for its undo at the next (docs/modules/pf.md,
     * "A glitch is not a load"): load_alt set, the common error's correction it applied
     * (load_alt_e: theta, omega, F_d), P as the period's prediction left it (load_alt_P) and
     * its gated innovation nu1 (rad); the undone ones counted */
    float load_N, load_prev_N, load_comp_N, load_P[6], load_g_radpN;
    float load_alt_e[3], load_alt_P[6], load_alt_nu1;
    uint32_t n_load_acq, n_load_undo;
    int load_alt;
    int primed;                   /* particles drawn around the first measurement */
    /* particles as a structure of arrays: x[i][j] is state i of particle j.
     * One set, predicted and resampled in place (docs/modules/pf.md). */
    float x[BR_NX][BR_PF_MAX_PARTICLES];
    float kgp[BR_PF_MAX_PARTICLES];   /* k_p = sigma0 L / g_p of each particle, 1/rad: the
                                          particle-step's one division (docs/modules/pf.md); with
                                          elements, the particle's element force sum_i k_i e_ji, N
                                          (the next trapezoidal step's f0) */
    float ms[BR_PF_MS_SLOTS];         /* with elements: deflection i of particle j at ms[i m + j], m */
    float fnl[BR_PF_MAX_PARTICLES];   /* f_nl of the predicted particles (by predicted index) */
    float l[BR_PF_MAX_PARTICLES];     /* log-weights; NaN marks an invalid particle */
    uint32_t W[BR_PF_MAX_PARTICLES];  /* quantised weights */
    uint16_t idx[BR_PF_MAX_PARTICLES];/* resampling indices of the last step */
    br_pf_est_t est;
    uint32_t weighed;             /* BR_PF_WEIGHED_*: the last step's weights, for br_pf_stats */
    float lmax;                   /* the last step's largest log-weight (BR_PF_WEIGHED_LOG) */
    int ready;
} br_pf_t;

br_status_t br_pf_init(br_pf_t *pf, const br_pf_cfg_t *cfg);

/* One filter step (see above). Statuses: BR_E_INPUT for a non-finite u or
 * frac outside [0, 1] (state untouched); BR_W_OUTLIER when y is further than
 * outlier_sigma sqrt(R + rpc^2 / 12) + outlier_transient_rad from every particle (eq. G1;
 * no weighting: the valid predicted
 * particles are kept with equal weights; after reanchor_after consecutive
 * outliers the cloud is re-anchored, its mean theta moved to y and its mean
 * omega to the measured velocity, so the filter regains lock);
 * BR_E_NUMERIC when every predicted particle is non-finite (the previous set is
 * kept). In every case the particles stay finite. */
br_status_t br_pf_step(br_pf_t *pf, const br_meas_t *y, float u_prev_Nm);

/* Predict-only step for a period without a measurement (a failed or missing
 * encoder read): step 1 for every particle with u_{k-1}, no weighting or
 * resampling, so the cloud spreads by the process noise each period; origin
 * unchanged; the estimate is the predicted set's mean and mean f_nl. The next
 * br_pf_step weighs and resamples as usual; a re-anchoring after a gap takes
 * the measured velocity over all the periods since the last measurement.
 * BR_E_STATE before the first measurement, BR_E_INPUT for a non-finite u,
 * BR_E_NUMERIC when every predicted particle is non-finite (set kept). */
br_status_t br_pf_predict(br_pf_t *pf, float u_prev_Nm);

/* Deterministic systematic resampling in integer arithmetic: for the weights
 * W[0..m-1] (not all zero) writes idx[i] = the j with C_{j-1} <= t_i < C_j,
 * t_i = floor((2 i + 1) C_m / (2 m)). Identical on every target. The filter's
 * own weights: m in 1..BR_PF_MAX_PARTICLES and every W_j <= 2^16, else
 * BR_E_PARAM; all zero gives BR_E_INPUT. */
br_status_t br_pf_resample_idx(const uint32_t *W, uint32_t m, uint16_t *idx);

/* The last step's estimate. */
const br_pf_est_t *br_pf_estimate(const br_pf_t *pf);

/* The particle mean and the ESS of the last step, made now from the set and
 * the log-weights the step left (a pass over the particles per state and
 * one over the weights: the same values, bit for bit, as the sums the step
 * made itself before 2026-11-24, except the mean on a re-anchoring step,
 * now the sum of the moved particles; docs/modules/pf.md). Call it before
 * the next step. BR_E_NULL for a NULL argument, BR_E_STATE before the
 * first measurement or after a failed init (no set). */
br_status_t br_pf_stats(const br_pf_t *pf, br_pf_stats_t *out);

/* br_est_t binding: ctx is a br_pf_t *. step: br_pf_step, *F_hat_N the
 * compensation (the estimate's F_hat_N, or br_est_comp_N's force ahead);
 * predict: br_pf_predict, *F_hat_N the predicted estimate's F_hat_N (written
 * unless the status is an error); reset: br_pf_init from the filter's own
 * configuration. */
br_status_t br_pf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);
br_status_t br_pf_est_predict(void *ctx, float u_prev_Nm, float *F_hat_N);
br_status_t br_pf_est_reset(void *ctx);

/* The three above over pf, as the application drives it. */
br_est_t br_pf_est(br_pf_t *pf);

#endif
