/* Particle filter for the friction of one axis, float32. See br_pf.h and
 * docs/modules/pf.md. */
#include "bristle/br_pf.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "bristle/br_math.h"

/* W of a particle of weight 1 (the best one after the max-shift) */
#define BR_PF_W_ONE (1u << BR_PF_W_BITS)

static int finite_nonneg(float v) { return isfinite(v) && v >= 0.0f; }


br_status_t br_pf_init(br_pf_t *pf, const br_pf_cfg_t *cfg)
{
    if (pf == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    pf->ready = 0;
    if (cfg->noise == NULL) {
        return BR_E_NULL;
    }
    if (cfg->n_particles < 1u || cfg->n_particles > BR_PF_MAX_PARTICLES) {
        return BR_E_PARAM;
    }
    if (cfg->noise_len < 2u || (cfg->noise_len & (cfg->noise_len - 1u)) != 0u) {
        return BR_E_PARAM;
    }
    for (int i = 0; i < BR_NX; i++) {
        if (!finite_nonneg(cfg->x0_std[i])) {
            return BR_E_PARAM;
        }
    }
    br_status_t st = br_est_check_common(cfg->q_var, cfg->r_var_rad2, cfg->gp0_N, cfg->gp_min_N, cfg->gp_max_N,
                                         cfg->outlier_sigma, cfg->reanchor_after, cfg->rad_per_count);
    if (st != BR_OK) {
        return st;
    }
    st = br_model_init(&pf->model, &cfg->model);
    if (st != BR_OK) {
        return st;
    }
    pf->cfg = *cfg;
    for (int i = 0; i < BR_NX; i++) {
        pf->q_std[i] = sqrtf(cfg->q_var[i]);
    }
    pf->inv_2r = 0.5f / cfg->r_var_rad2;
    pf->outlier_l = -0.5f * cfg->outlier_sigma * cfg->outlier_sigma;
    pf->noise_pos = 0u;
    pf->origin_counts = 0;
    pf->primed = 0;
    pf->n_outliers = 0u;
    pf->est = (br_pf_est_t){{0.0f, 0.0f, 0.0f, cfg->gp0_N}, 0, 0.0f, (float)cfg->n_particles};
    pf->ready = 1;
    return BR_OK;
}

static float clampf(float v, float lo, float hi) { return fminf(fmaxf(v, lo), hi); }

/* Next standard-normal sample of the ROM table for (particle j, state i). */
static float noise_at(const br_pf_t *pf, uint32_t j, uint32_t i)
{
    return pf->cfg.noise[(pf->noise_pos + BR_NX * j + i) & (pf->cfg.noise_len - 1u)];
}

/* The table position moves on by the samples used plus noise_skip, so that
 * the particle-to-sample assignment shifts from step to step. */
static void noise_advance(br_pf_t *pf)
{
    pf->noise_pos = (pf->noise_pos + BR_NX * pf->cfg.n_particles + pf->cfg.noise_skip) & (pf->cfg.noise_len - 1u);
}

/* Estimate of the freshly drawn set: means and the mean of f_nl (eq. 6). */
static void estimate_current(br_pf_t *pf, float ess)
{
    const uint32_t m = pf->cfg.n_particles;
    float s[BR_NX] = {0.0f, 0.0f, 0.0f, 0.0f}, sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        float xj[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xj[i] = pf->x[i][j];
            s[i] += xj[i];
        }
        /* thesis estimate: the mean of f_nl (eq. 6) over the particles */
        sf += br_model_fnl_N(&pf->model, xj);
    }
    const float inv_m = 1.0f / (float)m;
    for (int i = 0; i < BR_NX; i++) {
        pf->est.mean[i] = s[i] * inv_m;
    }
    pf->est.F_hat_N = sf * inv_m;
    pf->est.origin_counts = pf->origin_counts;
    pf->est.ess = ess;
}

/* First measurement: particles drawn around [y, 0, 0, gp0]. */
static void prime(br_pf_t *pf, const br_meas_t *y)
{
    const uint32_t m = pf->cfg.n_particles;
    const float mean[BR_NX] = {y->frac * pf->cfg.rad_per_count, 0.0f, 0.0f, pf->cfg.gp0_N};
    for (uint32_t j = 0; j < m; j++) {
        for (uint32_t i = 0; i < BR_NX; i++) {
            pf->x[i][j] = mean[i] + pf->cfg.x0_std[i] * noise_at(pf, j, i);
        }
        pf->x[BR_X_GP][j] = clampf(pf->x[BR_X_GP][j], pf->cfg.gp_min_N, pf->cfg.gp_max_N);
    }
    noise_advance(pf);
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->primed = 1;
    estimate_current(pf, (float)m);
}

br_status_t br_pf_resample_idx(const uint32_t *W, uint32_t m, uint16_t *idx)
{
    if (W == NULL || idx == NULL) {
        return BR_E_NULL;
    }
    if (m < 1u || m > 65535u) {
        return BR_E_PARAM;
    }
    uint64_t total = 0u;
    for (uint32_t j = 0; j < m; j++) {
        total += W[j];
    }
    if (total == 0u) {
        return BR_E_INPUT;
    }
    /* xi_i = (i + 1/2)/m on the integer scale: t_i = floor((2 i + 1) C_m / (2 m));
     * particle j is picked while C_{j-1} <= t_i < C_j (C inclusive running sums).
     * t_i is stepped exactly as quotient and remainder of (2 i + 1) C_m by 2 m:
     * two divisions in all instead of one per particle. */
    const uint64_t den = 2u * (uint64_t)m;
    const uint64_t dq = (2u * total) / den, dr = (2u * total) % den;
    uint64_t t = total / den, r = total % den;
    uint32_t j = 0u;
    uint64_t c = W[0];
    for (uint32_t i = 0; i < m; i++) {
        if (i > 0u) {
            t += dq;
            r += dr;
            if (r >= den) {
                t++;
                r -= den;
            }
        }
        while (c <= t && j + 1u < m) {
            j++;
            c += W[j];
        }
        idx[i] = (uint16_t)j;
    }
    return BR_OK;
}

br_status_t br_pf_step(br_pf_t *pf, const br_meas_t *y, float u_prev_Nm)
{
    if (pf == NULL || y == NULL) {
        return BR_E_NULL;
    }
    if (!pf->ready) {
        return BR_E_STATE;
    }
    if (!isfinite(u_prev_Nm) || !isfinite(y->frac) || y->frac < 0.0f || y->frac > 1.0f) {
        return BR_E_INPUT;
    }
    if (!pf->primed) {
        prime(pf, y);
        return BR_OK;
    }
    const uint32_t m = pf->cfg.n_particles;
    const float rpc = pf->cfg.rad_per_count;
    /* new integer origin: theta_j is re-expressed relative to y.counts */
    const float shift = (float)br_counts_delta(y->counts, pf->origin_counts) * rpc;
    const float y_rel = y->frac * rpc;
    float lmax = -INFINITY;
    uint32_t n_valid = 0u;

    for (uint32_t j = 0; j < m; j++) {
        float xj[BR_NX], xn[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xj[i] = pf->x[i][j];
        }
        /* 1. predict: eq. 6 discretised (br_model_step), then process noise from the ROM table */
        br_status_t st = br_model_step(&pf->model, xj, u_prev_Nm, xn);
        for (uint32_t i = 0; i < BR_NX; i++) {
            xn[i] += pf->q_std[i] * noise_at(pf, j, i);
        }
        xn[BR_X_GP] = clampf(xn[BR_X_GP], pf->cfg.gp_min_N, pf->cfg.gp_max_N);
        xn[BR_X_THETA] -= shift;
        int valid = (st == BR_OK) && isfinite(xn[0]) && isfinite(xn[1]) && isfinite(xn[2]) && isfinite(xn[3]);
        float fnl = valid ? br_model_fnl_N(&pf->model, xn) : 0.0f;
        valid = valid && isfinite(fnl);
        for (int i = 0; i < BR_NX; i++) {
            pf->xp[i][j] = valid ? xn[i] : xj[i];
        }
        pf->fnl[j] = fnl;
        /* 2. Gaussian log-likelihood of the measurement, -(theta_j - y)^2 / (2 R) */
        const float e = xn[BR_X_THETA] - y_rel;
        const float l = valid ? -(e * e) * pf->inv_2r : -INFINITY;
        pf->l[j] = l;
        if (valid) {
            n_valid++;
            lmax = fmaxf(lmax, l);
        }
    }
    noise_advance(pf);
    if (n_valid == 0u) {
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    const br_status_t verdict = (lmax < pf->outlier_l) ? BR_E_OUTLIER : BR_OK;

    /* 3. max-shifted weights, quantised; an outlier gives every valid particle weight 1 */
    float sw = 0.0f, sw2 = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        float w;
        if (!(pf->l[j] > -INFINITY)) {
            w = 0.0f;
        } else if (verdict == BR_E_OUTLIER) {
            w = 1.0f;
        } else {
            w = br_exp_neg(pf->l[j] - lmax);
        }
        pf->W[j] = (uint32_t)(w * (float)BR_PF_W_ONE);
        sw += w;
        sw2 += w * w;
    }
    /* 4. deterministic systematic resampling on the integer weights */
    (void)br_pf_resample_idx(pf->W, m, pf->idx);
    /* 5. estimate over the resampled set: particle mean and the mean of f_nl (eq. 6) */
    float s[BR_NX] = {0.0f, 0.0f, 0.0f, 0.0f}, sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        const uint32_t k = pf->idx[j];
        for (int i = 0; i < BR_NX; i++) {
            pf->x[i][j] = pf->xp[i][k];
            s[i] += pf->x[i][j];
        }
        sf += pf->fnl[k];
    }
    const float inv_m = 1.0f / (float)m;
    pf->n_outliers = (verdict == BR_E_OUTLIER) ? pf->n_outliers + 1u : 0u;
    if (pf->n_outliers >= pf->cfg.reanchor_after) {
        /* lost lock: re-anchor the cloud on the measurement, keeping its spread:
         * theta's mean moves to y, omega's mean to the measured velocity */
        const float omega_meas = (shift + (y->frac - pf->prev_frac) * rpc) / pf->cfg.model.dt_s;
        const float d_th = y_rel - s[BR_X_THETA] * inv_m, d_om = omega_meas - s[BR_X_OMEGA] * inv_m;
        sf = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            float xj[BR_NX];
            pf->x[BR_X_THETA][j] += d_th;
            pf->x[BR_X_OMEGA][j] += d_om;
            for (int i = 0; i < BR_NX; i++) {
                xj[i] = pf->x[i][j];
            }
            /* f_nl depends on omega: the estimate is that of the moved cloud */
            sf += br_model_fnl_N(&pf->model, xj);
        }
        s[BR_X_THETA] += d_th * (float)m;
        s[BR_X_OMEGA] += d_om * (float)m;
    }
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    for (int i = 0; i < BR_NX; i++) {
        pf->est.mean[i] = s[i] * inv_m;
    }
    pf->est.F_hat_N = sf * inv_m;
    pf->est.origin_counts = y->counts;
    /* effective sample size of the weights, (sum w)^2 / sum w^2 */
    pf->est.ess = sw * sw / sw2;
    return verdict;
}

const br_pf_est_t *br_pf_estimate(const br_pf_t *pf) { return (pf != NULL) ? &pf->est : NULL; }

br_status_t br_pf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    br_pf_t *pf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    br_status_t st = br_pf_step(pf, y, u_prev_Nm);
    if (st == BR_OK || st == BR_E_OUTLIER) { /* an outlier step still predicts */
        *F_hat_N = pf->est.F_hat_N;
    }
    return st;
}
