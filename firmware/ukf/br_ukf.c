/* SPDX-License-Identifier: Apache-2.0 */
/* Unscented Kalman filter for the friction of one axis, float32. See br_ukf.h
 * and docs/modules/ukf.md. */
#include "bristle/br_ukf.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"

static int vec_finite(const float v[BR_NX])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]) && isfinite(v[3]);
}

static int mat_finite(const float A[BR_NX][BR_NX])
{
    int ok = 1;
    for (int i = 0; i < BR_NX; i++) {
        ok = ok && vec_finite(A[i]);
    }
    return ok;
}

static br_status_t check_cfg(const br_ukf_cfg_t *cfg)
{
    for (int i = 0; i < BR_NX; i++) {
        if (!br_est_var_ok(cfg->p0_var[i], 0)) {
            return BR_E_PARAM;
        }
    }
    const br_status_t st = br_est_cfg_check(&cfg->est);
    if (st != BR_OK) {
        return st;
    }
    /* scaled UT: alpha in (0, 1], beta >= 0, n + lambda = alpha^2 (n + kappa) > 0 */
    if (!br_finite_pos(cfg->alpha) || cfg->alpha > 1.0f || !br_finite_nonneg(cfg->beta) || !isfinite(cfg->kappa) ||
        !((float)BR_NX + cfg->kappa > 0.0f)) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

br_status_t br_ukf_init(br_ukf_t *ukf, const br_ukf_cfg_t *cfg)
{
    if (ukf == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    ukf->ready = 0;
    br_status_t st = check_cfg(cfg);
    if (st != BR_OK) {
        return st;
    }
    st = br_model_init(&ukf->model, &cfg->est.model);
    if (st != BR_OK) {
        return st;
    }
    const float n = (float)BR_NX;
    /* scaled UT (Julier 2002): lambda = alpha^2 (n + kappa) - n, so n + lambda = alpha^2 (n + kappa) */
    const float n_lam = cfg->alpha * cfg->alpha * (n + cfg->kappa);
    const float lambda = n_lam - n;
    /* weights: Wm_0 = lambda / (n + lambda), Wc_0 = Wm_0 + 1 - alpha^2 + beta, W_i = 1 / (2 (n + lambda)) */
    const float wm0 = lambda / n_lam;
    const float wc0 = wm0 + 1.0f - cfg->alpha * cfg->alpha + cfg->beta;
    const float wi = 0.5f / n_lam;
    if (!br_finite_pos(n_lam) || !isfinite(wm0) || !isfinite(wc0) || !br_finite_pos(wi)) {
        return BR_E_PARAM;
    }
    ukf->cfg = *cfg;
    ukf->c_sigma = sqrtf(n_lam);
    ukf->wm0 = wm0;
    ukf->wc0 = wc0;
    ukf->wi = wi;
    ukf->cmm = cfg->beta - cfg->alpha * cfg->alpha;
    ukf->out_s2 = cfg->est.outlier_sigma * cfg->est.outlier_sigma;
    /* the encoder's quantisation variance rpc^2 / 12 (a uniform error over one count) */
    ukf->quant_var_rad2 = cfg->est.rad_per_count * cfg->est.rad_per_count * (1.0f / 12.0f);
    ukf->m_per_count = cfg->est.model.lead_mprad * cfg->est.rad_per_count;
    br_est_delay_init(&ukf->delay, &cfg->est);
    br_est_dlyid_init(&ukf->dlyid, &cfg->est);
    for (int i = 0; i < BR_NX; i++) {
        ukf->x[i] = 0.0f;
        for (int j = 0; j < BR_NX; j++) {
            ukf->P[i][j] = (i == j) ? cfg->p0_var[i] : 0.0f;
            ukf->S[i][j] = 0.0f;
        }
    }
    ukf->x[BR_X_GP] = cfg->est.gp0_N;
    for (int s = 0; s < BR_UKF_NSIG; s++) {
        for (int i = 0; i < BR_NX; i++) {
            ukf->X[s][i] = ukf->x[i];
            ukf->Y[s][i] = ukf->x[i];
        }
    }
    ukf->origin_counts = 0;
    ukf->prev_counts = 0;
    ukf->prev_frac = 0.0f;
    ukf->n_outliers = 0u;
    ukf->n_recover = 0u;
    ukf->n_predicted = 0u;
    ukf->primed = 0;
    ukf->est = (br_ukf_est_t){{0.0f, 0.0f, 0.0f, cfg->est.gp0_N},
                              {cfg->p0_var[0], cfg->p0_var[1], cfg->p0_var[2], cfg->p0_var[3]},
                              0, 0.0f, 0.0f, 0.0f};
    ukf->ready = 1;
    return BR_OK;
}

br_status_t br_ukf_chol4(const float A[BR_NX][BR_NX], float L[BR_NX][BR_NX])
{
    if (A == NULL || L == NULL) {
        return BR_E_NULL;
    }
    for (int i = 0; i < BR_NX; i++) {
        for (int j = 0; j < BR_NX; j++) {
            L[i][j] = 0.0f;
        }
    }
    for (int j = 0; j < BR_NX; j++) {
        /* Cholesky-Banachiewicz: L_jj = sqrt(A_jj - sum_{k<j} L_jk^2) */
        float d = A[j][j];
        for (int k = 0; k < j; k++) {
            d -= L[j][k] * L[j][k];
        }
        if (!(d > 0.0f) || !isfinite(d)) {
            return BR_E_NUMERIC;
        }
        const float ljj = sqrtf(d);
        L[j][j] = ljj;
        /* L_ij = (A_ij - sum_{k<j} L_ik L_jk) / L_jj, i > j; a non-finite entry
         * reaches the pivot of row i and is caught there */
        for (int i = j + 1; i < BR_NX; i++) {
            float s = A[i][j];
            for (int k = 0; k < j; k++) {
                s -= L[i][k] * L[j][k];
            }
            L[i][j] = s / ljj;
        }
    }
    return BR_OK;
}

/* P0 = diag(p0_var): the initial covariance and the recovery point. */
static void reset_cov(const br_ukf_cfg_t *cfg, float P[BR_NX][BR_NX])
{
    for (int i = 0; i < BR_NX; i++) {
        for (int j = 0; j < BR_NX; j++) {
            P[i][j] = (i == j) ? cfg->p0_var[i] : 0.0f;
        }
    }
}

/* Sigma points of (x, P) into ukf->X, factor into ukf->S. On a failed Cholesky
 * P is reset to diag(p0_var) (x kept) and BR_E_NUMERIC returned; the points are
 * then those of the reset P, so they are always usable. */
static br_status_t sigma_points(br_ukf_t *ukf, const float x[BR_NX], float P[BR_NX][BR_NX])
{
    br_status_t st = br_ukf_chol4((const float(*)[BR_NX])P, ukf->S);
    if (st != BR_OK) {
        /* recovery: P <- diag(p0_var), whose factor is diag(sqrt(p0_var)) */
        reset_cov(&ukf->cfg, P);
        for (int i = 0; i < BR_NX; i++) {
            for (int j = 0; j < BR_NX; j++) {
                ukf->S[i][j] = (i == j) ? sqrtf(ukf->cfg.p0_var[i]) : 0.0f;
            }
        }
        ukf->n_recover++;
        st = BR_E_NUMERIC;
    }
    const float c = ukf->c_sigma;
    for (int i = 0; i < BR_NX; i++) {
        ukf->X[0][i] = x[i];
    }
    for (int k = 0; k < BR_NX; k++) {
        /* X_{1+k} = x + c S_k, X_{1+n+k} = x - c S_k (S_k: column k of the factor) */
        for (int i = 0; i < BR_NX; i++) {
            const float d = c * ukf->S[i][k];
            ukf->X[1 + k][i] = x[i] + d;
            ukf->X[1 + BR_NX + k][i] = x[i] - d;
        }
    }
    /* the model needs g_p > 0: every sigma point's g_p in [gp_min, gp_max] */
    for (int s = 0; s < BR_UKF_NSIG; s++) {
        ukf->X[s][BR_X_GP] = br_clampf(ukf->X[s][BR_X_GP], ukf->cfg.est.gp_min_N, ukf->cfg.est.gp_max_N);
    }
    return st;
}

/* Unscented mean of f_nl (eq. 6) over the sigma points in ukf->X:
 * F_hat = sum_j Wm_j f_nl(X_j), written as f_0 + sum_{j>=1} W_j (f_j - f_0)
 * (sum Wm = 1) so that a large |Wm_0| (small alpha) does not cancel in float32. */
static float fnl_unscented(const br_ukf_t *ukf, int32_t origin_counts)
{
    /* the force to compensate: f_nl for the thesis model (eq. 6), the extended model's otherwise */
    const float p0 = (float)origin_counts * ukf->m_per_count;
    const float f0 = br_model_fcomp_N(&ukf->model, ukf->X[0], p0);
    float df = 0.0f;
    for (int s = 1; s < BR_UKF_NSIG; s++) {
        df += br_model_fcomp_N(&ukf->model, ukf->X[s], p0) - f0;
    }
    return f0 + ukf->wi * df;
}

/* The estimate of the committed x, P, origin. */
static void set_estimate(br_ukf_t *ukf, float F_hat_N, float innov, float innov_var)
{
    ukf->est.F_hat_N = F_hat_N;
    for (int i = 0; i < BR_NX; i++) {
        ukf->est.mean[i] = ukf->x[i];
        ukf->est.var[i] = ukf->P[i][i];
    }
    ukf->est.origin_counts = ukf->origin_counts;
    ukf->est.innov_rad = innov;
    ukf->est.innov_var_rad2 = innov_var;
}

/* First measurement: x = [frac rpc, 0, 0, gp0] relative to origin = counts, P = P0. */
static br_status_t prime(br_ukf_t *ukf, const br_meas_t *y)
{
    ukf->origin_counts = y->counts;
    ukf->prev_counts = y->counts;
    ukf->prev_frac = y->frac;
    ukf->x[BR_X_THETA] = y->frac * ukf->cfg.est.rad_per_count;
    ukf->x[BR_X_OMEGA] = 0.0f;
    ukf->x[BR_X_Z] = 0.0f;
    ukf->x[BR_X_GP] = ukf->cfg.est.gp0_N;
    reset_cov(&ukf->cfg, ukf->P);
    (void)sigma_points(ukf, ukf->x, ukf->P); /* diagonal with p0_var > 0: cannot fail */
    set_estimate(ukf, fnl_unscented(ukf, ukf->origin_counts), 0.0f, 0.0f);
    ukf->primed = 1;
    return BR_OK;
}

/* Steps 1-2: sigma points of the posterior (x, P) of the last step and their
 * prediction through eq. 6 discretised, Y_j = f_d(X_j, u_{k-1}), into the
 * predicted mean xm and covariance Pm. *chol_reset is set when a failed
 * Cholesky reset P (kept in ukf->P: the recovery outlives a later failure).
 * Returns 0 when the prediction is not finite. */
static int predict(br_ukf_t *ukf, float u_prev_Nm, float xm[BR_NX], float Pm[BR_NX][BR_NX], int *chol_reset)
{
    const float p0 = (float)ukf->origin_counts * ukf->m_per_count; /* theta's origin */
    br_model_tick(&ukf->model); /* the model's clock moves on by one period (friction_drift) */
    *chol_reset = sigma_points(ukf, ukf->x, ukf->P) != BR_OK;
    for (int s = 0; s < BR_UKF_NSIG; s++) {
        if (br_model_step_at(&ukf->model, ukf->X[s], p0, u_prev_Nm, ukf->Y[s]) != BR_OK) {
            return 0;
        }
    }
    /* predicted mean x- = sum_j Wm_j Y_j = Y_0 + m, m = sum_{j>=1} W (Y_j - Y_0) (sum Wm = 1) */
    float mdev[BR_NX];
    for (int i = 0; i < BR_NX; i++) {
        float d = 0.0f;
        for (int s = 1; s < BR_UKF_NSIG; s++) {
            d += ukf->Y[s][i] - ukf->Y[0][i];
        }
        mdev[i] = ukf->wi * d;
        xm[i] = ukf->Y[0][i] + mdev[i];
    }
    /* predicted covariance P- = sum_j Wc_j (Y_j - x-)(Y_j - x-)^T + Q, evaluated about
     * the central point (d_j = Y_j - Y_0) as the algebraically equal
     *   P- = sum_{j>=1} W d_j d_j^T + (beta - alpha^2) m m^T + Q,
     * which has no large |Wc_0| to cancel in float32 and is PSD for beta >= alpha^2 */
    for (int i = 0; i < BR_NX; i++) {
        for (int j = 0; j <= i; j++) {
            Pm[i][j] = ukf->cmm * mdev[i] * mdev[j];
        }
    }
    for (int s = 1; s < BR_UKF_NSIG; s++) {
        float d[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            d[i] = ukf->Y[s][i] - ukf->Y[0][i];
        }
        for (int i = 0; i < BR_NX; i++) {
            for (int j = 0; j <= i; j++) {
                Pm[i][j] += ukf->wi * d[i] * d[j];
            }
        }
    }
    for (int i = 0; i < BR_NX; i++) {
        Pm[i][i] += ukf->cfg.est.q_var[i];
        for (int j = 0; j < i; j++) {
            Pm[j][i] = Pm[i][j];
        }
    }
    return vec_finite(xm) && mat_finite((const float(*)[BR_NX])Pm);
}

/* A step whose prediction or update is not finite: the mean and origin are
 * kept, P is reset to diag(p0_var) and the reset counted, so the next step
 * starts again from a usable covariance instead of failing forever. */
static br_status_t fail_reset(br_ukf_t *ukf)
{
    reset_cov(&ukf->cfg, ukf->P);
    ukf->n_recover++;
    return BR_E_NUMERIC;
}

/* Step 4 and the commit: sigma points of (xm, Pm) (a failed Cholesky resets Pm
 * as in step 1 and sets *chol_reset), the unscented mean of f_nl over them
 * into *F_hat, then x = xm, P = Pm. Returns 0, committing nothing, when
 * *F_hat is not finite. */
static int posterior(br_ukf_t *ukf, const float xm[BR_NX], float Pm[BR_NX][BR_NX], int32_t origin_counts,
                     float *F_hat, int *chol_reset)
{
    if (sigma_points(ukf, xm, Pm) != BR_OK) {
        *chol_reset = 1;
    }
    *F_hat = fnl_unscented(ukf, origin_counts);
    if (!isfinite(*F_hat)) {
        return 0;
    }
    for (int i = 0; i < BR_NX; i++) {
        ukf->x[i] = xm[i];
        for (int j = 0; j < BR_NX; j++) {
            ukf->P[i][j] = Pm[i][j];
        }
    }
    return 1;
}

/* P <- (P + P^T) / 2 */
static void symmetrise(float P[BR_NX][BR_NX])
{
    for (int i = 0; i < BR_NX; i++) {
        for (int j = i + 1; j < BR_NX; j++) {
            const float m = 0.5f * (P[i][j] + P[j][i]);
            P[i][j] = m;
            P[j][i] = m;
        }
    }
}

br_status_t br_ukf_step(br_ukf_t *ukf, const br_meas_t *y, float u_prev_Nm)
{
    if (ukf == NULL || y == NULL) {
        return BR_E_NULL;
    }
    if (!ukf->ready) {
        return BR_E_STATE;
    }
    const br_status_t in = br_est_check_step(y, u_prev_Nm);
    if (in != BR_OK) {
        return in;
    }
    /* the torque that reached the axis over the last period (the command itself without a delay) */
    const float u_a = br_est_delay_apply(&ukf->delay, u_prev_Nm);
    /* the delay's identification (off unless cfg.est.delay_id.n_cand): from the next period on,
     * the torque with the delay it finds */
    br_est_dlyid_step(&ukf->dlyid, &ukf->cfg.est, y, &ukf->delay);
    if (!ukf->primed) {
        return prime(ukf, y);
    }
    const float rpc = ukf->cfg.est.rad_per_count;

    /* 1.-2. sigma points of the last posterior, predicted mean and covariance */
    float xm[BR_NX], Pm[BR_NX][BR_NX];
    int chol_reset;
    if (!predict(ukf, u_a, xm, Pm, &chol_reset)) {
        return fail_reset(ukf);
    }

    /* 3. measurement: theta re-expressed relative to the new origin y.counts
     *    (wrap-safe integer delta); y_rel = frac rpc, innovation nu = y_rel - theta- */
    const float shift = (float)br_counts_delta(y->counts, ukf->origin_counts) * rpc;
    const float theta_new = xm[BR_X_THETA] - shift;
    const float nu = y->frac * rpc - theta_new;
    /* innovation variance S = H P- H^T + R = P-_00 + R (h(x) = theta) */
    const float S = Pm[0][0] + ukf->cfg.est.r_var_rad2;
    if (!isfinite(nu) || !br_finite_pos(S)) {
        return fail_reset(ukf);
    }
    br_status_t verdict = BR_OK;
    int32_t origin_new = y->counts;
    /* gate (docs/modules/ukf.md): outlier when nu^2 > g^2 (P-_00 + R + rpc^2 / 12),
     * the innovation's variance with the encoder's quantisation */
    if (nu * nu > ukf->out_s2 * (S + ukf->quant_var_rad2)) {
        /* outlier: keep the prediction in the old origin's frame, no update */
        verdict = BR_W_OUTLIER;
        origin_new = ukf->origin_counts;
        if (ukf->n_outliers + 1u >= ukf->cfg.est.reanchor_after) {
            /* lost lock: re-anchor on the measurement, theta = frac rpc relative
             * to y.counts, omega = the measured velocity over the last period
             * (wrap-safe count difference), z and g_p means kept, P = diag(p0_var) */
            const float dcounts = (float)br_counts_delta(y->counts, ukf->prev_counts);
            xm[BR_X_THETA] = y->frac * rpc;
            const float periods = (float)ukf->n_predicted + 1.0f;
            xm[BR_X_OMEGA] = (dcounts + (y->frac - ukf->prev_frac)) * rpc / (periods * ukf->cfg.est.model.dt_s);
            reset_cov(&ukf->cfg, Pm);
            origin_new = y->counts;
            if (!vec_finite(xm)) {
                return fail_reset(ukf);
            }
        }
    } else {
        /* gain K = P- H^T / S = P-_{:,0} / S; mean x+ = x- + K nu (theta in the new frame) */
        float K[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            K[i] = Pm[i][0] / S;
        }
        xm[BR_X_THETA] = theta_new;
        for (int i = 0; i < BR_NX; i++) {
            xm[i] += K[i] * nu;
        }
        /* Joseph form P+ = A P- A^T + R K K^T, A = I - K H, H = e_0^T:
         *   (A P-)_ij = P-_ij - K_i P-_0j,  (A P- A^T)_ij = (A P-)_ij - (A P-)_i0 K_j */
        float AP[BR_NX][BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            for (int j = 0; j < BR_NX; j++) {
                AP[i][j] = Pm[i][j] - K[i] * Pm[0][j];
            }
        }
        const float r = ukf->cfg.est.r_var_rad2;
        for (int i = 0; i < BR_NX; i++) {
            for (int j = 0; j < BR_NX; j++) {
                Pm[i][j] = AP[i][j] - AP[i][0] * K[j] + r * K[i] * K[j];
            }
        }
        /* P+ <- (P+ + P+^T) / 2 */
        symmetrise(Pm);
        /* g_p of the mean kept in [gp_min, gp_max], as the sigma points' are */
        xm[BR_X_GP] = br_clampf(xm[BR_X_GP], ukf->cfg.est.gp_min_N, ukf->cfg.est.gp_max_N);
        if (!vec_finite(xm) || !mat_finite((const float(*)[BR_NX])Pm)) {
            return fail_reset(ukf);
        }
    }

    /* 4. posterior sigma points, the unscented mean of f_nl, commit x and P */
    float F_hat;
    if (!posterior(ukf, xm, Pm, origin_new, &F_hat, &chol_reset)) {
        return fail_reset(ukf);
    }
    ukf->origin_counts = origin_new;
    ukf->prev_counts = y->counts;
    ukf->prev_frac = y->frac;
    ukf->n_predicted = 0u;
    /* as in the PF, every further outlier in the run re-anchors again */
    if (verdict != BR_W_OUTLIER) {
        ukf->n_outliers = 0u;
    } else if (ukf->n_outliers < UINT32_MAX) {
        ukf->n_outliers++;
    }
    set_estimate(ukf, F_hat, nu, S);
    return chol_reset ? BR_E_NUMERIC : verdict;
}

br_status_t br_ukf_predict(br_ukf_t *ukf, float u_prev_Nm)
{
    if (ukf == NULL) {
        return BR_E_NULL;
    }
    if (!ukf->ready) {
        return BR_E_STATE;
    }
    if (!isfinite(u_prev_Nm)) {
        return BR_E_INPUT;
    }
    if (!ukf->primed) {
        return BR_E_STATE; /* nothing to predict from before the first measurement */
    }
    float xm[BR_NX], Pm[BR_NX][BR_NX];
    int chol_reset;
    /* no measurement: the delay's identification starts again at the next one */
    ukf->dlyid.primed = 0;
    if (!predict(ukf, br_est_delay_apply(&ukf->delay, u_prev_Nm), xm, Pm, &chol_reset)) {
        return fail_reset(ukf);
    }
    xm[BR_X_GP] = br_clampf(xm[BR_X_GP], ukf->cfg.est.gp_min_N, ukf->cfg.est.gp_max_N);
    /* the predicted set's sigma points give the estimate, as after an update */
    float F_hat;
    if (!posterior(ukf, xm, Pm, ukf->origin_counts, &F_hat, &chol_reset)) {
        return fail_reset(ukf);
    }
    if (ukf->n_predicted < UINT32_MAX) {
        ukf->n_predicted++;
    }
    set_estimate(ukf, F_hat, 0.0f, 0.0f);
    return chol_reset ? BR_E_NUMERIC : BR_OK;
}

const br_ukf_est_t *br_ukf_estimate(const br_ukf_t *ukf) { return (ukf != NULL) ? &ukf->est : NULL; }

br_status_t br_ukf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    br_ukf_t *ukf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    const br_status_t st = br_ukf_step(ukf, y, u_prev_Nm);
    if (!BR_FAILED(st)) { /* an outlier step still predicts */
        /* the compensation: F_hat, or the force predicted ahead (cfg.est.comp_ahead_periods) */
        *F_hat_N = br_est_comp_N(&ukf->cfg.est, &ukf->model, &ukf->delay, ukf->x,
                                 (float)ukf->origin_counts * ukf->m_per_count, u_prev_Nm, ukf->est.F_hat_N);
    }
    return st;
}

br_status_t br_ukf_est_predict(void *ctx, float u_prev_Nm, float *F_hat_N)
{
    br_ukf_t *ukf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    const br_status_t st = br_ukf_predict(ukf, u_prev_Nm);
    if (!BR_FAILED(st)) {
        *F_hat_N = ukf->est.F_hat_N;
    }
    return st;
}

br_status_t br_ukf_est_reset(void *ctx)
{
    br_ukf_t *ukf = ctx;
    if (ukf == NULL) {
        return BR_E_NULL;
    }
    const br_ukf_cfg_t c = ukf->cfg; /* init reads the configuration it overwrites */
    return br_ukf_init(ukf, &c);
}

br_est_t br_ukf_est(br_ukf_t *ukf)
{
    const br_est_t e = {ukf, br_ukf_est_step, br_ukf_est_predict, br_ukf_est_reset};
    return e;
}
