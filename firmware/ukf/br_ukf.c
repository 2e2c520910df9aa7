/* SPDX-License-Identifier: Apache-2.0 */
/* Unscented Kalman filter for the friction of one axis, float32. See br_ukf.h
 * and docs/modules/ukf.md. */
#include "bristle/br_ukf.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"

#define NM BR_UKF_NMAX

static int vec_finite(const float *v, int n)
{
    int ok = 1;
    for (int i = 0; i < n; i++) {
        ok = ok && isfinite(v[i]);
    }
    return ok;
}

static int mat_finite(const float A[NM][NM], int n)
{
    int ok = 1;
    for (int i = 0; i < n; i++) {
        ok = ok && vec_finite(A[i], n);
    }
    return ok;
}

/* P0's diagonal entry i: p0_var, and load.p0_N2 for F_d */
static float p0_of(const br_ukf_cfg_t *cfg, int i) { return (i < BR_NX) ? cfg->p0_var[i] : cfg->load.p0_N2; }

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
    /* the external force: off (p0 = 0, then q and max must be 0 too), or p0 a
     * variance, q 0 or a variance, max > 0 and finite */
    const br_ukf_load_t *ld = &cfg->load;
    if (ld->p0_N2 == 0.0f) {
        if (ld->q_N2 != 0.0f || ld->max_N != 0.0f) {
            return BR_E_PARAM;
        }
    } else if (!br_est_var_ok(ld->p0_N2, 0) || !br_est_var_ok(ld->q_N2, 1) || !br_finite_pos(ld->max_N)) {
        return BR_E_PARAM;
    }
    /* the Maxwell-slip elements carry no prediction ahead (the model's
     * look-ahead steps the LuGre state): comp_ahead_periods must be 0 */
    if (cfg->est.model.mslip.n > 0 && cfg->est.comp_ahead_periods != 0.0f) {
        return BR_E_PARAM;
    }
    /* scaled UT: alpha in (0, 1], beta >= 0, n + lambda = alpha^2 (n + kappa) > 0 */
    const float n = (cfg->load.p0_N2 > 0.0f) ? (float)BR_UKF_NMAX : (float)BR_NX;
    if (!br_finite_pos(cfg->alpha) || cfg->alpha > 1.0f || !br_finite_nonneg(cfg->beta) || !isfinite(cfg->kappa) ||
        !(n + cfg->kappa > 0.0f)) {
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
    ukf->n = (cfg->load.p0_N2 > 0.0f) ? BR_UKF_NMAX : BR_NX;
    const float n = (float)ukf->n;
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
    /* the widest gate (eq. G1) is at the smallest innovation variance, R + rpc^2 / 12: a finite float */
    const float v_min = cfg->est.r_var_rad2 + ukf->quant_var_rad2;
    if (!isfinite(ukf->out_s2 * v_min * br_est_gate_f2(&cfg->est, v_min))) {
        return BR_E_PARAM;
    }
    ukf->m_per_count = cfg->est.model.lead_mprad * cfg->est.rad_per_count;
    br_est_delay_init(&ukf->delay, &cfg->est);
    br_est_dlyid_init(&ukf->dlyid, &cfg->est);
    /* theta response to F_d over one period, L dt^2 / (2 J_eff), J_eff = J + L^2 M (eq. 1) */
    const br_model_cfg_t *mc = &cfg->est.model;
    ukf->load_rad_per_N2 = (ukf->n > BR_NX) ? mc->lead_mprad * mc->dt_s * mc->dt_s /
                                                  (2.0f * (mc->J_kgm2 + mc->lead_mprad * mc->lead_mprad * mc->M_kg))
                                            : 0.0f;
    for (int i = 0; i < NM; i++) {
        ukf->x[i] = 0.0f;
        for (int j = 0; j < NM; j++) {
            ukf->P[i][j] = (i == j) ? p0_of(cfg, i) : 0.0f;
            ukf->S[i][j] = 0.0f;
        }
    }
    ukf->x[BR_X_GP] = cfg->est.gp0_N;
    for (int s = 0; s < BR_UKF_NSIG_MAX; s++) {
        for (int i = 0; i < NM; i++) {
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
    ukf->n_load_acq = 0u;
    ukf->n_load_undo = 0u;
    ukf->n_repair = 0u;
    ukf->alt_pending = 0;
    ukf->alt_origin = 0;
    ukf->alt_nu_rad = 0.0f;
    for (int i = 0; i < NM; i++) {
        ukf->alt_x[i] = 0.0f;
        for (int j = 0; j < NM; j++) {
            ukf->alt_P[i][j] = 0.0f;
        }
    }
    ukf->primed = 0;
    ukf->est = (br_ukf_est_t){{0.0f, 0.0f, 0.0f, cfg->est.gp0_N},
                              {cfg->p0_var[0], cfg->p0_var[1], cfg->p0_var[2], cfg->p0_var[3]},
                              0, 0.0f, 0.0f, 0.0f, 0.0f, cfg->load.p0_N2, {0.0f}};
    for (int i = 0; i < BR_MSLIP_MAX; i++) {
        ukf->el[i] = 0.0f;
        ukf->el_m[i] = 0.0f;
        ukf->alt_el[i] = 0.0f;
    }
    ukf->ready = 1;
    return BR_OK;
}

/* Cholesky-Banachiewicz of the leading n x n block of A into L (upper part zeroed). */
static br_status_t chol_n(const float A[NM][NM], float L[NM][NM], int n)
{
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            L[i][j] = 0.0f;
        }
    }
    for (int j = 0; j < n; j++) {
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
        for (int i = j + 1; i < n; i++) {
            float s = A[i][j];
            for (int k = 0; k < j; k++) {
                s -= L[i][k] * L[j][k];
            }
            L[i][j] = s / ljj;
        }
    }
    return BR_OK;
}

br_status_t br_ukf_chol4(const float A[BR_NX][BR_NX], float L[BR_NX][BR_NX])
{
    if (A == NULL || L == NULL) {
        return BR_E_NULL;
    }
    float a[NM][NM], l[NM][NM];
    for (int i = 0; i < BR_NX; i++) {
        for (int j = 0; j < BR_NX; j++) {
            a[i][j] = A[i][j];
        }
    }
    const br_status_t st = chol_n((const float(*)[NM])a, l, BR_NX);
    for (int i = 0; i < BR_NX; i++) {
        for (int j = 0; j < BR_NX; j++) {
            L[i][j] = l[i][j];
        }
    }
    return st;
}

/* P0 = diag(p0_var[, load.p0_N2]): the initial covariance and the recovery point. */
static void reset_cov(const br_ukf_t *ukf, float P[NM][NM])
{
    for (int i = 0; i < ukf->n; i++) {
        for (int j = 0; j < ukf->n; j++) {
            P[i][j] = (i == j) ? p0_of(&ukf->cfg, i) : 0.0f;
        }
    }
}

/* 1 when every entry of P (leading n x n) is finite: a covariance float32's
 * rounding made indefinite, not a broken one */
static int cov_finite(const float P[NM][NM], int n)
{
    int ok = 1;
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            ok = ok && isfinite(P[i][j]);
        }
    }
    return ok;
}

/* Sigma points of (x, P) into ukf->X, factor into ukf->S. A failed Cholesky
 * of a finite P is repaired (U9): its correlations dropped, each positive
 * variance times n (P <= n diag(P) for every covariance with that diagonal),
 * a variance that is not positive P0's, counted in n_repair, BR_OK.
 * Otherwise P is reset to P0 (x kept) and BR_E_NUMERIC returned; the points
 * are then those of the reset P, so they are always usable. */
static br_status_t sigma_points(br_ukf_t *ukf, const float x[NM], float P[NM][NM])
{
    const int n = ukf->n;
    br_status_t st = chol_n((const float(*)[NM])P, ukf->S, n);
    if (st != BR_OK && cov_finite((const float(*)[NM])P, n)) {
        /* (U9) states almost perfectly correlated (theta, omega and F_d after a
         * load re-acquisition's inflation, updated with a small R) come out of
         * float32's update indefinite, a variance even negative: the
         * correlations dropped, the variances times n (P0's where one is not
         * positive), whose factor is the diagonal's root (docs/modules/ukf.md,
         * "Cholesky and recovery") */
        const float fn = (float)n;
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) {
                P[i][j] = (i != j) ? 0.0f : ((P[i][i] > 0.0f) ? fn * P[i][i] : p0_of(&ukf->cfg, i));
            }
        }
        st = chol_n((const float(*)[NM])P, ukf->S, n);
        if (st == BR_OK && ukf->n_repair < UINT32_MAX) {
            ukf->n_repair++;
        }
    }
    if (st != BR_OK) {
        /* recovery: P <- P0, whose factor is diag(sqrt(P0)) */
        reset_cov(ukf, P);
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) {
                ukf->S[i][j] = (i == j) ? sqrtf(p0_of(&ukf->cfg, i)) : 0.0f;
            }
        }
        ukf->n_recover++;
        st = BR_E_NUMERIC;
    }
    const float c = ukf->c_sigma;
    for (int i = 0; i < n; i++) {
        ukf->X[0][i] = x[i];
    }
    for (int k = 0; k < n; k++) {
        /* X_{1+k} = x + c S_k, X_{1+n+k} = x - c S_k (S_k: column k of the factor) */
        for (int i = 0; i < n; i++) {
            const float d = c * ukf->S[i][k];
            ukf->X[1 + k][i] = x[i] + d;
            ukf->X[1 + n + k][i] = x[i] - d;
        }
    }
    /* the model needs g_p > 0: every sigma point's g_p in [gp_min, gp_max] */
    for (int s = 0; s < 2 * n + 1; s++) {
        ukf->X[s][BR_X_GP] = br_clampf(ukf->X[s][BR_X_GP], ukf->cfg.est.gp_min_N, ukf->cfg.est.gp_max_N);
    }
    return st;
}

/* Unscented mean of f_nl (eq. 6) over the sigma points in ukf->X:
 * F_hat = sum_j Wm_j f_nl(X_j), written as f_0 + sum_{j>=1} W_j (f_j - f_0)
 * (sum Wm = 1) so that a large |Wm_0| (small alpha) does not cancel in float32.
 * With the external force (cfg.load) the compensation is friction + F_d, the
 * force a position measurement can tell (docs/modules/ukf.md, "External
 * force"), clamped to +-max_N. */
static float fnl_unscented(const br_ukf_t *ukf, int32_t origin_counts, const float el[])
{
    float F;
    if (ukf->model.cfg.mslip.n > 0) {
        /* Maxwell-slip: the elements' force sum_i k_i z_i (they are the
         * sigma points' unscented mean already) */
        F = br_model_ms_fnl_N(&ukf->model, el);
    } else {
        /* the force to compensate: f_nl for the thesis model (eq. 6), the extended model's otherwise */
        const float p0 = (float)origin_counts * ukf->m_per_count;
        const float f0 = br_model_fcomp_N(&ukf->model, ukf->X[0], p0);
        float df = 0.0f;
        for (int s = 1; s < 2 * ukf->n + 1; s++) {
            df += br_model_fcomp_N(&ukf->model, ukf->X[s], p0) - f0;
        }
        F = f0 + ukf->wi * df;
    }
    if (ukf->n == BR_NX) {
        return F;
    }
    /* + the unscented mean of F_d, linear: the central point's (the mean's); the sum within +-max_N */
    return br_clampf(F + ukf->X[0][BR_UKF_X_LOAD], -ukf->cfg.load.max_N, ukf->cfg.load.max_N);
}

/* The estimate of the committed x, P, origin. */
static void set_estimate(br_ukf_t *ukf, float F_hat_N, float innov, float innov_var)
{
    ukf->est.F_hat_N = F_hat_N;
    for (int i = 0; i < BR_NX; i++) {
        ukf->est.mean[i] = ukf->x[i];
        ukf->est.var[i] = ukf->P[i][i];
    }
    ukf->est.load_N = (ukf->n > BR_NX) ? ukf->x[BR_UKF_X_LOAD] : 0.0f;
    ukf->est.load_var_N2 = (ukf->n > BR_NX) ? ukf->P[BR_UKF_X_LOAD][BR_UKF_X_LOAD] : 0.0f;
    for (int i = 0; i < BR_MSLIP_MAX; i++) {
        ukf->est.elem_m[i] = ukf->el[i];
    }
    ukf->est.origin_counts = ukf->origin_counts;
    ukf->est.innov_rad = innov;
    ukf->est.innov_var_rad2 = innov_var;
}

/* First measurement: x = [frac rpc, 0, 0, gp0(, 0)] relative to origin = counts, P = P0. */
static br_status_t prime(br_ukf_t *ukf, const br_meas_t *y)
{
    ukf->origin_counts = y->counts;
    ukf->prev_counts = y->counts;
    ukf->prev_frac = y->frac;
    ukf->x[BR_X_THETA] = y->frac * ukf->cfg.est.rad_per_count;
    ukf->x[BR_X_OMEGA] = 0.0f;
    ukf->x[BR_X_Z] = 0.0f;
    ukf->x[BR_X_GP] = ukf->cfg.est.gp0_N;
    ukf->x[BR_UKF_X_LOAD] = 0.0f;
    for (int i = 0; i < BR_MSLIP_MAX; i++) {
        ukf->el[i] = 0.0f; /* the elements relaxed */
    }
    reset_cov(ukf, ukf->P);
    (void)sigma_points(ukf, ukf->x, ukf->P); /* diagonal with P0 > 0: cannot fail */
    set_estimate(ukf, fnl_unscented(ukf, ukf->origin_counts, ukf->el), 0.0f, 0.0f);
    ukf->primed = 1;
    return BR_OK;
}

/* Steps 1-2: sigma points of the posterior (x, P) of the last step and their
 * prediction through eq. 6 discretised, Y_j = f_d(X_j, u_{k-1}), into the
 * predicted mean xm and covariance Pm. With the external force F_d (cfg.load)
 * the torque is u - L F_d_j (eq. 1 with the load beside the friction) and
 * F_d_j carries over (a random walk). *chol_reset is set when a failed
 * Cholesky reset P (kept in ukf->P: the recovery outlives a later failure).
 * Returns 0 when the prediction is not finite. */
static int predict(br_ukf_t *ukf, float u_prev_Nm, float xm[NM], float Pm[NM][NM], int *chol_reset)
{
    const int n = ukf->n, nsig = 2 * n + 1;
    const float p0 = (float)ukf->origin_counts * ukf->m_per_count; /* theta's origin */
    const float L = ukf->cfg.est.model.lead_mprad;
    br_model_tick(&ukf->model); /* the model's clock moves on by one period (friction_drift) */
    *chol_reset = sigma_points(ukf, ukf->x, ukf->P) != BR_OK;
    const int ne = ukf->model.cfg.mslip.n;
    float e0[BR_MSLIP_MAX] = {0.0f}, de[BR_MSLIP_MAX] = {0.0f}, es[BR_MSLIP_MAX] = {0.0f};
    for (int i = 0; i < ne; i++) {
        de[i] = 0.0f;
    }
    for (int s = 0; s < nsig; s++) {
        /* the torque on the axis: u, less L F_d with the external force */
        const float u = (n > BR_NX) ? u_prev_Nm - L * ukf->X[s][BR_UKF_X_LOAD] : u_prev_Nm;
        if (ne > 0) {
            /* Maxwell-slip: the sigma point and its elements, the committed
             * ones offset by its z (the elements' common error), one step on
             * (br_model_ms_step; z is carried unchanged) */
            float ej[BR_MSLIP_MAX] = {0.0f};
            for (int i = 0; i < ne; i++) {
                ej[i] = ukf->el[i] + ukf->X[s][BR_X_Z];
            }
            if (br_model_ms_step(&ukf->model, ukf->X[s], ej, u, ukf->Y[s], (s == 0) ? e0 : es) != BR_OK) {
                return 0;
            }
            /* the elements' unscented mean e- = E_0 + W sum_{j>=1} (E_j - E_0) */
            for (int i = 0; s > 0 && i < ne; i++) {
                de[i] += es[i] - e0[i];
            }
        } else if (br_model_step_at(&ukf->model, ukf->X[s], p0, u, ukf->Y[s]) != BR_OK) {
            return 0;
        }
        /* F_d' = 0 (its random walk is in Q) */
        ukf->Y[s][BR_UKF_X_LOAD] = ukf->X[s][BR_UKF_X_LOAD];
    }
    for (int i = 0; i < ne; i++) {
        ukf->el_m[i] = e0[i] + ukf->wi * de[i];
    }
    /* predicted mean x- = sum_j Wm_j Y_j = Y_0 + m, m = sum_{j>=1} W (Y_j - Y_0) (sum Wm = 1) */
    float mdev[NM];
    for (int i = 0; i < n; i++) {
        float d = 0.0f;
        for (int s = 1; s < nsig; s++) {
            d += ukf->Y[s][i] - ukf->Y[0][i];
        }
        mdev[i] = ukf->wi * d;
        xm[i] = ukf->Y[0][i] + mdev[i];
    }
    /* predicted covariance P- = sum_j Wc_j (Y_j - x-)(Y_j - x-)^T + Q, evaluated about
     * the central point (d_j = Y_j - Y_0) as the algebraically equal
     *   P- = sum_{j>=1} W d_j d_j^T + (beta - alpha^2) m m^T + Q,
     * which has no large |Wc_0| to cancel in float32 and is PSD for beta >= alpha^2 */
    for (int i = 0; i < n; i++) {
        for (int j = 0; j <= i; j++) {
            Pm[i][j] = ukf->cmm * mdev[i] * mdev[j];
        }
    }
    for (int s = 1; s < nsig; s++) {
        float d[NM];
        for (int i = 0; i < n; i++) {
            d[i] = ukf->Y[s][i] - ukf->Y[0][i];
        }
        for (int i = 0; i < n; i++) {
            for (int j = 0; j <= i; j++) {
                Pm[i][j] += ukf->wi * d[i] * d[j];
            }
        }
    }
    for (int i = 0; i < n; i++) {
        Pm[i][i] += (i < BR_NX) ? ukf->cfg.est.q_var[i] : ukf->cfg.load.q_N2;
        for (int j = 0; j < i; j++) {
            Pm[j][i] = Pm[i][j];
        }
    }
    return vec_finite(xm, n) && mat_finite((const float(*)[NM])Pm, n) && vec_finite(ukf->el_m, ne);
}

/* A step whose prediction or update is not finite: the mean and origin are
 * kept, P is reset to P0 and the reset counted, so the next step
 * starts again from a usable covariance instead of failing forever. */
static br_status_t fail_reset(br_ukf_t *ukf)
{
    reset_cov(ukf, ukf->P);
    ukf->alt_pending = 0;
    ukf->n_recover++;
    return BR_E_NUMERIC;
}

/* (x, P) -> (xd, Pd), the leading n entries */
static void copy_mean_cov(int n, const float x[NM], const float P[NM][NM], float xd[NM], float Pd[NM][NM])
{
    for (int i = 0; i < n; i++) {
        xd[i] = x[i];
        for (int j = 0; j < n; j++) {
            Pd[i][j] = P[i][j];
        }
    }
}

/* the first ne elements of e into ed */
static void elements_copy(int ne, const float e[], float ed[])
{
    for (int i = 0; i < ne; i++) {
        ed[i] = e[i];
    }
}

/* Maxwell-slip: the predicted elements within their slip bounds at the
 * posterior's g_p, |z_i| <= c_i g_p, into el */
static void elements_bounded(const br_ukf_t *ukf, float gp, float el[])
{
    for (int i = 0; i < ukf->model.cfg.mslip.n; i++) {
        const float d = ukf->model.ms_c_mpN[i] * gp;
        el[i] = br_clampf(ukf->el_m[i], -d, d);
    }
}

/* Step 4 and the commit: sigma points of (xm, Pm) (a failed Cholesky resets Pm
 * as in step 1 and sets *chol_reset), the unscented mean of f_nl over them
 * into *F_hat, then x = xm, P = Pm. Returns 0, committing nothing, when
 * *F_hat is not finite. */
static int posterior(br_ukf_t *ukf, const float xm[NM], float Pm[NM][NM], int32_t origin_counts, float *F_hat,
                     int *chol_reset)
{
    if (sigma_points(ukf, xm, Pm) != BR_OK) {
        *chol_reset = 1;
    }
    const int ne = ukf->model.cfg.mslip.n;
    float el[BR_MSLIP_MAX];
    elements_bounded(ukf, xm[BR_X_GP], el);
    *F_hat = fnl_unscented(ukf, origin_counts, el);
    if (!isfinite(*F_hat)) {
        return 0;
    }
    for (int i = 0; i < ne; i++) {
        ukf->el[i] = el[i];
    }
    for (int i = 0; i < ukf->n; i++) {
        ukf->x[i] = xm[i];
        for (int j = 0; j < ukf->n; j++) {
            ukf->P[i][j] = Pm[i][j];
        }
    }
    return 1;
}

/* Maxwell-slip: the predicted elements moved by dx_m (a correction of the
 * position; clamped at the posterior's g_p in posterior) */
static void elements_shift(br_ukf_t *ukf, float dx_m)
{
    for (int i = 0; i < ukf->model.cfg.mslip.n; i++) {
        ukf->el_m[i] += dx_m;
    }
}

/* P <- (P + P^T) / 2 */
static void symmetrise(float P[NM][NM], int n)
{
    for (int i = 0; i < n; i++) {
        for (int j = i + 1; j < n; j++) {
            const float m = 0.5f * (P[i][j] + P[j][i]);
            P[i][j] = m;
            P[j][i] = m;
        }
    }
}

/* The mean's bounded states: g_p in [gp_min, gp_max], F_d in [-max_N, max_N]. */
static void clamp_mean(const br_ukf_t *ukf, float x[NM])
{
    x[BR_X_GP] = br_clampf(x[BR_X_GP], ukf->cfg.est.gp_min_N, ukf->cfg.est.gp_max_N);
    if (ukf->n > BR_NX) {
        x[BR_UKF_X_LOAD] = br_clampf(x[BR_UKF_X_LOAD], -ukf->cfg.load.max_N, ukf->cfg.load.max_N);
    }
}

/* Step 3: theta- re-expressed relative to the new origin y.counts (wrap-safe
 * integer delta) into *theta_new; the innovation nu = frac rpc - theta- and
 * S = P-_00 + R (h(x) = theta). Returns 1 when nu passes the gate,
 * |nu| <= g sqrt(S + rpc^2 / 12) + d (eq. G1, docs/modules/ukf.md). */
static int innovate(const br_ukf_t *ukf, const br_meas_t *y, const float xm[NM], const float Pm[NM][NM],
                    float *theta_new, float *nu, float *S)
{
    const float rpc = ukf->cfg.est.rad_per_count;
    const float shift = (float)br_counts_delta(y->counts, ukf->origin_counts) * rpc;
    *theta_new = xm[BR_X_THETA] - shift;
    *nu = y->frac * rpc - *theta_new;
    *S = Pm[0][0] + ukf->cfg.est.r_var_rad2;
    /* eq. G1: |nu| > g sqrt(v) + d, v = S + rpc^2 / 12, as nu^2 > g^2 v f^2 */
    const float v = *S + ukf->quant_var_rad2;
    return !(*nu * *nu > ukf->out_s2 * v * br_est_gate_f2(&ukf->cfg.est, v));
}

/* Load re-acquisition (cfg.load; docs/modules/ukf.md, "External force"): a
 * gated innovation nu that a change of the external force explains, the force
 * dF = nu / (g k^2), g = L dt^2 / (2 J_eff), k the periods since the last
 * measurement, with |dF| <= 2 max_N: the last posterior's F_d variance is
 * inflated by dF^2 and the period predicted again into xm, Pm (the model's
 * clock put back first). Returns 1 when that prediction's innovation passes
 * the gate (ukf->P keeps the inflation), 0 otherwise (ukf->P, xm and Pm
 * untouched). */
static int load_reacquire(br_ukf_t *ukf, const br_meas_t *y, float u_a, float nu, float xm[NM], float Pm[NM][NM],
                          int *chol_reset)
{
    if (ukf->n == BR_NX) {
        return 0;
    }
    const float k = (float)ukf->n_predicted + 1.0f;
    const float dF = nu / (ukf->load_rad_per_N2 * k * k);
    if (!(fabsf(dF) <= 2.0f * ukf->cfg.load.max_N)) {
        return 0;
    }
    const float keep = ukf->P[BR_UKF_X_LOAD][BR_UKF_X_LOAD];
    /* the alternative, should the next innovation undo this: the first
     * prediction as an outlier commits it (old origin, elements bounded) */
    float alt_el[BR_MSLIP_MAX];
    elements_bounded(ukf, xm[BR_X_GP], alt_el);
    /* P_dd += dF^2 (the last posterior's), then the period again from it */
    ukf->P[BR_UKF_X_LOAD][BR_UKF_X_LOAD] = keep + dF * dF;
    br_model_set_clock(&ukf->model, ukf->model.n_steps - 1u);
    float xr[NM], Pr[NM][NM], th, nu_r, S_r, el_m[BR_MSLIP_MAX];
    int reset = 0;
    elements_copy(ukf->model.cfg.mslip.n, ukf->el_m, el_m);
    if (predict(ukf, u_a, xr, Pr, &reset) && innovate(ukf, y, xr, (const float(*)[NM])Pr, &th, &nu_r, &S_r)) {
        copy_mean_cov(ukf->n, xm, (const float(*)[NM])Pm, ukf->alt_x, ukf->alt_P);
        elements_copy(ukf->model.cfg.mslip.n, alt_el, ukf->alt_el);
        ukf->alt_origin = ukf->origin_counts;
        ukf->alt_nu_rad = nu;
        ukf->alt_pending = 1;
        copy_mean_cov(ukf->n, xr, (const float(*)[NM])Pr, xm, Pm);
        *chol_reset = *chol_reset || reset;
        if (ukf->n_load_acq < UINT32_MAX) {
            ukf->n_load_acq++;
        }
        return 1;
    }
    /* not a load: the first prediction stands (its clock too: predict ticked
     * again; its elements) */
    ukf->P[BR_UKF_X_LOAD][BR_UKF_X_LOAD] = keep;
    elements_copy(ukf->model.cfg.mslip.n, el_m, ukf->el_m);
    return 0;
}

/* The committed posterior (x, P, elements, origin) and the held alternative
 * trade places. */
static void alt_swap(br_ukf_t *ukf)
{
    float x[NM], P[NM][NM], el[BR_MSLIP_MAX];
    const int ne = ukf->model.cfg.mslip.n;
    copy_mean_cov(ukf->n, ukf->x, (const float(*)[NM])ukf->P, x, P);
    copy_mean_cov(ukf->n, ukf->alt_x, (const float(*)[NM])ukf->alt_P, ukf->x, ukf->P);
    copy_mean_cov(ukf->n, x, (const float(*)[NM])P, ukf->alt_x, ukf->alt_P);
    elements_copy(ne, ukf->el, el);
    elements_copy(ne, ukf->alt_el, ukf->el);
    elements_copy(ne, el, ukf->alt_el);
    const int32_t o = ukf->origin_counts;
    ukf->origin_counts = ukf->alt_origin;
    ukf->alt_origin = o;
}

/* The undo of the last step's re-acquisition (docs/modules/ukf.md, "A glitch
 * is not a load"), for a gated innovation after it: the period predicted
 * again from the alternative (the last step's first prediction, its clock
 * put back first), and its innovation gated as it is (a spike: the last
 * measurement alone was off) and with theta- moved by the last step's gated
 * innovation nu_1 (a slip: the counter stays off by it). One that passes is
 * taken, the smaller |nu| when both do: the alternative becomes the
 * committed posterior and its prediction (moved for a slip) is written into
 * xm, Pm; returns 1. Neither: returns 0 with the committed posterior and the
 * first prediction's elements back (xm, Pm untouched). */
static int glitch_undo(br_ukf_t *ukf, const br_meas_t *y, float u_a, float xm[NM], float Pm[NM][NM],
                       int *chol_reset)
{
    float xa[NM], Pa[NM][NM], th, S, el_m[BR_MSLIP_MAX];
    int reset = 0;
    elements_copy(ukf->model.cfg.mslip.n, ukf->el_m, el_m);
    alt_swap(ukf);
    br_model_set_clock(&ukf->model, ukf->model.n_steps - 1u);
    if (predict(ukf, u_a, xa, Pa, &reset)) {
        /* a spike (theta- as it is) and a slip (theta- + nu_1); one S for
         * both, so the likelier is the smaller |nu| (a slip can be within
         * the spike's gate, the alternative being two periods old) */
        const float th_s = xa[BR_X_THETA];
        float nu_s, nu_l;
        const int pass_s = innovate(ukf, y, xa, (const float(*)[NM])Pa, &th, &nu_s, &S);
        xa[BR_X_THETA] = th_s + ukf->alt_nu_rad;
        const int pass_l = innovate(ukf, y, xa, (const float(*)[NM])Pa, &th, &nu_l, &S);
        const int slip = pass_l && !(pass_s && fabsf(nu_s) <= fabsf(nu_l));
        xa[BR_X_THETA] = slip ? xa[BR_X_THETA] : th_s;
        if ((slip || pass_s) && isfinite(slip ? nu_l : nu_s)) {
            copy_mean_cov(ukf->n, xa, (const float(*)[NM])Pa, xm, Pm);
            *chol_reset = *chol_reset || reset;
            if (ukf->n_load_undo < UINT32_MAX) {
                ukf->n_load_undo++;
            }
            return 1;
        }
    }
    /* a load after all: the committed posterior and its prediction stand */
    alt_swap(ukf);
    elements_copy(ukf->model.cfg.mslip.n, el_m, ukf->el_m);
    return 0;
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
    const int n = ukf->n;
    const float rpc = ukf->cfg.est.rad_per_count;

    /* the last step's re-acquisition's alternative: for this step only */
    const int alt = ukf->alt_pending;
    ukf->alt_pending = 0;

    /* 1.-2. sigma points of the last posterior, predicted mean and covariance */
    float xm[NM], Pm[NM][NM];
    int chol_reset;
    if (!predict(ukf, u_a, xm, Pm, &chol_reset)) {
        return fail_reset(ukf);
    }

    /* 3. measurement, innovation and its variance; the gate */
    float theta_new, nu, S;
    int pass = innovate(ukf, y, xm, (const float(*)[NM])Pm, &theta_new, &nu, &S);
    if (!isfinite(nu) || !br_finite_pos(S)) {
        return fail_reset(ukf);
    }
    /* after a re-acquisition, a gated innovation that a glitch explains undoes it */
    if (!pass && alt && glitch_undo(ukf, y, u_a, xm, Pm, &chol_reset)) {
        pass = innovate(ukf, y, xm, (const float(*)[NM])Pm, &theta_new, &nu, &S);
    }
    /* a gated innovation that a load explains is re-acquired, not rejected (cfg.load) */
    if (!pass && load_reacquire(ukf, y, u_a, nu, xm, Pm, &chol_reset)) {
        pass = innovate(ukf, y, xm, (const float(*)[NM])Pm, &theta_new, &nu, &S);
    }
    br_status_t verdict = BR_OK;
    int32_t origin_new = y->counts;
    if (!pass) {
        /* outlier: keep the prediction in the old origin's frame, no update */
        verdict = BR_W_OUTLIER;
        origin_new = ukf->origin_counts;
        if (ukf->n_outliers + 1u >= ukf->cfg.est.reanchor_after) {
            /* lost lock: re-anchor on the measurement, theta = frac rpc relative
             * to y.counts, omega = the measured velocity over the last period
             * (wrap-safe count difference), z, g_p (and F_d) means kept, P = P0 */
            const float dcounts = (float)br_counts_delta(y->counts, ukf->prev_counts);
            xm[BR_X_THETA] = y->frac * rpc;
            const float periods = (float)ukf->n_predicted + 1.0f;
            xm[BR_X_OMEGA] = (dcounts + (y->frac - ukf->prev_frac)) * rpc / (periods * ukf->cfg.est.model.dt_s);
            /* the elements with the position's jump to the measurement, L nu */
            elements_shift(ukf, ukf->cfg.est.model.lead_mprad * nu);
            reset_cov(ukf, Pm);
            origin_new = y->counts;
            if (!vec_finite(xm, n)) {
                return fail_reset(ukf);
            }
        }
    } else {
        /* gain K = P- H^T / S = P-_{:,0} / S; mean x+ = x- + K nu (theta in the new frame) */
        float K[NM];
        for (int i = 0; i < n; i++) {
            K[i] = Pm[i][0] / S;
        }
        xm[BR_X_THETA] = theta_new;
        for (int i = 0; i < n; i++) {
            xm[i] += K[i] * nu;
        }
        if (ukf->model.cfg.mslip.n > 0) {
            /* Maxwell-slip: the elements' common error z, estimated, goes
             * into the elements and its mean back to 0 (an error state: its
             * covariance stays) */
            elements_shift(ukf, xm[BR_X_Z]);
            xm[BR_X_Z] = 0.0f;
        }
        /* Joseph form P+ = A P- A^T + R K K^T, A = I - K H, H = e_0^T:
         *   (A P-)_ij = P-_ij - K_i P-_0j,  (A P- A^T)_ij = (A P-)_ij - (A P-)_i0 K_j */
        float AP[NM][NM];
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) {
                AP[i][j] = Pm[i][j] - K[i] * Pm[0][j];
            }
        }
        const float r = ukf->cfg.est.r_var_rad2;
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++) {
                Pm[i][j] = AP[i][j] - AP[i][0] * K[j] + r * K[i] * K[j];
            }
        }
        /* P+ <- (P+ + P+^T) / 2 */
        symmetrise(Pm, n);
        /* g_p of the mean kept in [gp_min, gp_max], as the sigma points' are; F_d in [-max, max] */
        clamp_mean(ukf, xm);
        if (!vec_finite(xm, n) || !mat_finite((const float(*)[NM])Pm, n)) {
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
    float xm[NM], Pm[NM][NM];
    int chol_reset;
    /* no measurement: the delay's identification starts again at the next one,
     * and a re-acquisition is not undone across the gap */
    ukf->dlyid.primed = 0;
    ukf->alt_pending = 0;
    if (!predict(ukf, br_est_delay_apply(&ukf->delay, u_prev_Nm), xm, Pm, &chol_reset)) {
        return fail_reset(ukf);
    }
    clamp_mean(ukf, xm);
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
                                 (float)ukf->origin_counts * ukf->m_per_count, u_prev_Nm, ukf->est.load_N,
                                 ukf->est.F_hat_N);
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
