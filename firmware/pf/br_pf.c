/* Particle filter for the friction of one axis, float32. See br_pf.h and
 * docs/modules/pf.md. */
#include "bristle/br_pf.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"
#include "br_inline.h"
#include "br_math.h"
#include "br_model_kernel.h"

/* W of a particle of weight 1 (the best one after the max-shift) */
#define BR_PF_W_ONE (1u << BR_PF_W_BITS)


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
        if (!br_est_var_ok(cfg->x0_std[i] * cfg->x0_std[i], 1) || !br_finite_nonneg(cfg->x0_std[i])) {
            return BR_E_PARAM;
        }
    }
    br_status_t st = br_est_cfg_check(&cfg->est);
    if (st != BR_OK) {
        return st;
    }
    /* g_p is static in the model: its process noise is the only thing that keeps
     * the resampled particles apart in g_p; without it the cloud collapses */
    if (!(cfg->est.q_var[BR_X_GP] > 0.0f)) {
        return BR_E_PARAM;
    }
    st = br_model_init(&pf->model, &cfg->est.model);
    if (st != BR_OK) {
        return st;
    }
    pf->cfg = *cfg;
    for (int i = 0; i < BR_NX; i++) {
        pf->q_std[i] = sqrtf(cfg->est.q_var[i]);
    }
    pf->inv_2r = 0.5f / cfg->est.r_var_rad2;
    pf->m_per_count = cfg->est.model.lead_mprad * cfg->est.rad_per_count;
    br_est_delay_init(&pf->delay, &cfg->est);
    pf->outlier_l = -0.5f * cfg->est.outlier_sigma * cfg->est.outlier_sigma;
    pf->noise_pos = 0u;
    pf->origin_counts = 0;
    pf->primed = 0;
    pf->n_outliers = 0u;
    pf->n_predicted = 0u;
    pf->est = (br_pf_est_t){{0.0f, 0.0f, 0.0f, cfg->est.gp0_N}, 0, 0.0f, (float)cfg->n_particles};
    pf->ready = 1;
    return BR_OK;
}

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

/* Load position of the integer origin, p0 = L rpc origin (float: exact to
 * one count up to 2^24 counts, to 2^(n-24) counts at 2^n) */
static float origin_pos_m(const br_pf_t *pf) { return (float)pf->origin_counts * pf->m_per_count; }

/* Estimate of the freshly drawn set: means and the mean of f_nl (eq. 6). */
static void estimate_current(br_pf_t *pf, float ess)
{
    const uint32_t m = pf->cfg.n_particles;
    float s[BR_NX] = {0.0f, 0.0f, 0.0f, 0.0f}, sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        for (int i = 0; i < BR_NX; i++) {
            s[i] += pf->x[j][i];
        }
        /* thesis estimate: the mean of f_nl (eq. 6) over the particles */
        sf += br_model_fcomp_N(&pf->model, pf->x[j], origin_pos_m(pf));
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
    const float mean[BR_NX] = {y->frac * pf->cfg.est.rad_per_count, 0.0f, 0.0f, pf->cfg.est.gp0_N};
    for (uint32_t j = 0; j < m; j++) {
        for (uint32_t i = 0; i < BR_NX; i++) {
            pf->x[j][i] = mean[i] + pf->cfg.x0_std[i] * noise_at(pf, j, i);
        }
        pf->x[j][BR_X_GP] = br_clampf(pf->x[j][BR_X_GP], pf->cfg.est.gp_min_N, pf->cfg.est.gp_max_N);
    }
    noise_advance(pf);
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->primed = 1;
    estimate_current(pf, (float)m);
}

/* Systematic resampling on integer weights with a known total, 0 < total and
 * 2 total < 2^32 (W_j <= 2^16 and m <= BR_PF_MAX_PARTICLES < 2^15).
 * xi_i = (i + 1/2)/m on the integer scale: t_i = floor((2 i + 1) C_m / (2 m));
 * particle j is picked while C_{j-1} <= t_i < C_j (C inclusive running sums).
 * t_i is stepped exactly as quotient and remainder of (2 i + 1) C_m by 2 m:
 * two divisions in all instead of one per particle. */
static void resample(const uint32_t *W, uint32_t m, uint32_t total, uint16_t *idx)
{
    const uint32_t den = 2u * m;
    const uint32_t dq = (2u * total) / den, dr = (2u * total) % den;
    uint32_t t = total / den, r = total % den;
    uint32_t j = 0u, c = W[0];
    for (uint32_t i = 0; i < m; i++) {
        while (c <= t && j + 1u < m) {
            j++;
            c += W[j];
        }
        idx[i] = (uint16_t)j;
        /* t_{i+1} = t_i + dq, plus 1 when the remainder carries */
        t += dq;
        r += dr;
        if (r >= den) {
            t++;
            r -= den;
        }
    }
}

br_status_t br_pf_resample_idx(const uint32_t *W, uint32_t m, uint16_t *idx)
{
    if (W == NULL || idx == NULL) {
        return BR_E_NULL;
    }
    if (m < 1u || m > BR_PF_MAX_PARTICLES) {
        return BR_E_PARAM;
    }
    uint32_t total = 0u;
    for (uint32_t j = 0; j < m; j++) {
        if (W[j] > BR_PF_W_ONE) {
            return BR_E_PARAM;
        }
        total += W[j];
    }
    if (total == 0u) {
        return BR_E_INPUT;
    }
    resample(W, m, total, idx);
    return BR_OK;
}

/* Steps 1 and 2 for every particle: prediction into xp, the force to
 * compensate (f_nl for the thesis model), log-weight. ext: the extended
 * model's kernel mx (theta relative to the origin at its p0) instead of the
 * thesis model's; a constant at each call site, so that each case is its own
 * loop. Returns the number of valid (finite) predicted particles and their
 * largest log-weight in *lmax. */
BR_INLINE uint32_t predict_and_weigh_with(br_pf_t *pf, float u_prev_Nm, float shift, float y_rel, float *lmax,
                                          const int ext, const br_model_kx_t *mx)
{
    /* the model's constants and the loop's invariants, held in registers */
    const br_model_k_t mk = br_model_k(&pf->model);
    const float q0 = pf->q_std[0], q1 = pf->q_std[1], q2 = pf->q_std[2], q3 = pf->q_std[3];
    const float gp_min = pf->cfg.est.gp_min_N, gp_max = pf->cfg.est.gp_max_N, inv_2r = pf->inv_2r;
    const float *const noise = pf->cfg.noise;
    const uint32_t m = pf->cfg.n_particles, mask = pf->cfg.noise_len - 1u;
    uint32_t pos = pf->noise_pos, n_valid = 0u;
    float lm = -INFINITY;

    for (uint32_t j = 0; j < m; j++, pos += BR_NX) {
        const float *const xj = pf->x[j];
        float *const xo = pf->xp[j];
        /* 1. predict: eq. 6 discretised as br_model_step (RK4, or the bounded scheme
         * beyond its a h limit); the particles are finite with g_p >= gp_min > 0.
         * xn stays in registers; only the rare bounded step goes through memory. */
        float xn[BR_NX];
        if (ext ? !br_model_kx_rk4(mx, xj, u_prev_Nm, xn) : !br_model_k_rk4(&mk, xj, u_prev_Nm, xn)) {
            float xb[BR_NX];
            if (ext) {
                br_model_bounded_step_x(mx, xj, u_prev_Nm, xb);
            } else {
                br_model_bounded_step(&pf->model, xj, u_prev_Nm, xb);
            }
            for (int i = 0; i < BR_NX; i++) {
                xn[i] = xb[i];
            }
        }
        /* process noise: the next BR_NX standard-normal samples of the ROM table,
         * read in one block unless they wrap round its end */
        float n0, n1, n2, n3;
        const uint32_t p0 = pos & mask;
        if (p0 + (BR_NX - 1u) <= mask) {
            n0 = noise[p0];
            n1 = noise[p0 + 1u];
            n2 = noise[p0 + 2u];
            n3 = noise[p0 + 3u];
        } else {
            n0 = noise[p0];
            n1 = noise[(pos + 1u) & mask];
            n2 = noise[(pos + 2u) & mask];
            n3 = noise[(pos + 3u) & mask];
        }
        const float th_old = xn[BR_X_THETA] + q0 * n0; /* relative to the last origin */
        const float th = th_old - shift;
        const float om = xn[BR_X_OMEGA] + q1 * n1;
        const float z = xn[BR_X_Z] + q2 * n2;
        const float gp = br_clampf(xn[BR_X_GP] + q3 * n3, gp_min, gp_max);
        /* the force to compensate of the predicted particle: eq. 6's f_nl, or
         * the extended model's (at its position relative to the last origin) */
        float fnl;
        if (ext) {
            const float xe[BR_NX] = {th_old, om, z, gp};
            fnl = br_model_kx_fcomp_N(mx, xe);
        } else {
            fnl = br_model_k_fnl(&mk, z, br_model_k_zdot(&mk, om, z, gp));
        }
        /* Validity: x - x is 0 for finite x and NaN otherwise. g_p is finite after
         * the clamp; a non-finite omega or z makes f_nl non-finite (inf - inf,
         * 0 * inf or inf in eqs. 3-4), so theta and f_nl tell all four states. */
        if ((th - th) + (fnl - fnl) == 0.0f) {
            xo[BR_X_THETA] = th;
            xo[BR_X_OMEGA] = om;
            xo[BR_X_Z] = z;
            xo[BR_X_GP] = gp;
            pf->fnl[j] = fnl;
            /* 2. Gaussian log-likelihood of the measurement, -(theta_j - y)^2 / (2 R) */
            const float e = th - y_rel;
            /* may be -inf for a particle far from y: still valid (NaN marks invalid) */
            const float l = -(e * e) * inv_2r;
            pf->l[j] = l;
            lm = fmaxf(lm, l);
            n_valid++;
        } else {
            /* unusable: the particle keeps its state and gets weight 0; its
             * log-weight is NaN, which no valid particle's can be (fmaxf and
             * the max-shifted exponential both skip it) */
            for (int i = 0; i < BR_NX; i++) {
                xo[i] = xj[i];
            }
            pf->fnl[j] = 0.0f;
            pf->l[j] = NAN;
        }
    }
    *lmax = lm;
    return n_valid;
}

/* Steps 1 and 2 with the configured model; theta of the particles relative
 * to pf->origin_counts */
static uint32_t predict_and_weigh(br_pf_t *pf, float u_prev_Nm, float shift, float y_rel, float *lmax)
{
    /* the extended kernel's constants (a few operations per step; unused by the thesis model) */
    const br_model_kx_t mx = br_model_kx(&pf->model, origin_pos_m(pf));
    if (pf->model.extended) {
        return predict_and_weigh_with(pf, u_prev_Nm, shift, y_rel, lmax, 1, &mx);
    }
    return predict_and_weigh_with(pf, u_prev_Nm, shift, y_rel, lmax, 0, &mx);
}

/* Step 3: max-shifted weights w_j = e^(l_j - lmax), quantised to W_j (an invalid
 * particle has l_j = NaN and br_exp_neg gives 0 for it); on an outlier every
 * valid particle (l_j not NaN, even -inf when its residual overflowed) gets w = 1. Returns the total of W; *sw and *sw2 get the sums of w and w^2
 * (for the ESS). */
static uint32_t quantise_weights(br_pf_t *pf, float lmax, int outlier, float *sw, float *sw2)
{
    const uint32_t m = pf->cfg.n_particles;
    const float *const l = pf->l;
    uint32_t *const W = pf->W;
    uint32_t total = 0u;
    float s1 = 0.0f, s2 = 0.0f;
    /* two loops, so that the common one has no per-particle branch on the verdict
     * (one loop with the branch costs 5 more instructions per particle on the M7) */
    if (outlier) {
        for (uint32_t j = 0; j < m; j++) {
            const float w = (l[j] == l[j]) ? 1.0f : 0.0f; /* valid: not NaN */
            W[j] = (uint32_t)(w * (float)BR_PF_W_ONE);
            total += W[j];
            s1 += w;
            s2 += w * w;
        }
    } else {
        for (uint32_t j = 0; j < m; j++) {
            const float w = br_exp_neg(l[j] - lmax);
            W[j] = (uint32_t)(w * (float)BR_PF_W_ONE);
            total += W[j];
            s1 += w;
            s2 += w * w;
        }
    }
    *sw = s1;
    *sw2 = s2;
    return total;
}

/* Step 4's copy and step 5's sums: x_i <- xp_{idx_i}; s gets the sums of the
 * states, the return value the sum of f_nl over the resampled set. */
static float copy_resampled(br_pf_t *pf, float s[BR_NX])
{
    const uint32_t m = pf->cfg.n_particles;
    const uint16_t *const idx = pf->idx;
    float(*const xp)[BR_NX] = pf->xp; /* read only */
    const float *const fnl = pf->fnl;
    float(*const x)[BR_NX] = pf->x;
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f, s3 = 0.0f, sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        const uint32_t k = idx[j];
        const float a = xp[k][0], b = xp[k][1], c = xp[k][2], d = xp[k][3];
        x[j][0] = a;
        x[j][1] = b;
        x[j][2] = c;
        x[j][3] = d;
        s0 += a;
        s1 += b;
        s2 += c;
        s3 += d;
        sf += fnl[k];
    }
    s[0] = s0;
    s[1] = s1;
    s[2] = s2;
    s[3] = s3;
    return sf;
}

br_status_t br_pf_step(br_pf_t *pf, const br_meas_t *y, float u_prev_Nm)
{
    if (pf == NULL || y == NULL) {
        return BR_E_NULL;
    }
    if (!pf->ready) {
        return BR_E_STATE;
    }
    const br_status_t in = br_est_check_step(y, u_prev_Nm);
    if (in != BR_OK) {
        return in;
    }
    /* the torque that reached the axis over the last period (the command itself without a delay) */
    const float u_a = br_est_delay_apply(&pf->delay, u_prev_Nm);
    if (!pf->primed) {
        prime(pf, y);
        return BR_OK;
    }
    const uint32_t m = pf->cfg.n_particles;
    const float rpc = pf->cfg.est.rad_per_count;
    /* new integer origin: theta_j is re-expressed relative to y.counts */
    const float shift = (float)br_counts_delta(y->counts, pf->origin_counts) * rpc;
    const float y_rel = y->frac * rpc;
    float lmax;
    const uint32_t n_valid = predict_and_weigh(pf, u_a, shift, y_rel, &lmax);
    noise_advance(pf);
    if (n_valid == 0u) {
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* an outlier also when every valid particle's log-weight overflowed to -inf
     * (the max-shift needs a finite lmax) */
    const br_status_t verdict = (lmax < pf->outlier_l || lmax == -INFINITY) ? BR_W_OUTLIER : BR_OK;

    /* 3. max-shifted weights, quantised; an outlier gives every valid particle weight 1 */
    float sw, sw2;
    const uint32_t total = quantise_weights(pf, lmax, verdict == BR_W_OUTLIER, &sw, &sw2);
    /* 4. deterministic systematic resampling on the integer weights (total >= 2^16:
     * the best valid particle has W = 2^16) */
    resample(pf->W, m, total, pf->idx);
    /* 5. estimate over the resampled set: particle mean and the mean of f_nl (eq. 6) */
    float s[BR_NX];
    float sf = copy_resampled(pf, s);
    const float inv_m = 1.0f / (float)m;
    pf->n_outliers = (verdict == BR_W_OUTLIER) ? pf->n_outliers + 1u : 0u;
    if (pf->n_outliers >= pf->cfg.est.reanchor_after) {
        /* lost lock: re-anchor the cloud on the measurement, keeping its spread:
         * theta's mean moves to y, omega's mean to the measured velocity */
        const float periods = (float)pf->n_predicted + 1.0f;
        const float omega_meas = (shift + (y->frac - pf->prev_frac) * rpc) / (periods * pf->cfg.est.model.dt_s);
        const float d_th = y_rel - s[BR_X_THETA] * inv_m, d_om = omega_meas - s[BR_X_OMEGA] * inv_m;
        sf = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            pf->x[j][BR_X_THETA] += d_th;
            pf->x[j][BR_X_OMEGA] += d_om;
            /* f_nl depends on omega: the estimate is that of the moved cloud */
            sf += br_model_fcomp_N(&pf->model, pf->x[j], (float)y->counts * pf->m_per_count);
        }
        s[BR_X_THETA] += d_th * (float)m;
        s[BR_X_OMEGA] += d_om * (float)m;
    }
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->n_predicted = 0u;
    for (int i = 0; i < BR_NX; i++) {
        pf->est.mean[i] = s[i] * inv_m;
    }
    pf->est.F_hat_N = sf * inv_m;
    pf->est.origin_counts = y->counts;
    /* effective sample size of the weights, (sum w)^2 / sum w^2 */
    pf->est.ess = sw * sw / sw2;
    return verdict;
}

br_status_t br_pf_predict(br_pf_t *pf, float u_prev_Nm)
{
    if (pf == NULL) {
        return BR_E_NULL;
    }
    if (!pf->ready || !pf->primed) {
        return BR_E_STATE; /* nothing to predict from before the first measurement */
    }
    if (!isfinite(u_prev_Nm)) {
        return BR_E_INPUT;
    }
    const uint32_t m = pf->cfg.n_particles;
    /* step 1 only: the log-weights against a dummy measurement are not used */
    float lmax;
    const uint32_t n_valid = predict_and_weigh(pf, br_est_delay_apply(&pf->delay, u_prev_Nm), 0.0f, 0.0f, &lmax);
    noise_advance(pf);
    if (n_valid == 0u) {
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* every particle moves on unweighted (an invalid one kept its state in xp) */
    for (uint32_t j = 0; j < m; j++) {
        pf->idx[j] = (uint16_t)j;
    }
    float s[BR_NX];
    const float sf = copy_resampled(pf, s);
    const float inv_m = 1.0f / (float)m;
    for (int i = 0; i < BR_NX; i++) {
        pf->est.mean[i] = s[i] * inv_m;
    }
    pf->est.F_hat_N = sf * inv_m;
    pf->est.ess = (float)m;
    if (pf->n_predicted < UINT32_MAX) {
        pf->n_predicted++;
    }
    return BR_OK;
}

const br_pf_est_t *br_pf_estimate(const br_pf_t *pf) { return (pf != NULL) ? &pf->est : NULL; }

br_status_t br_pf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    br_pf_t *pf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    br_status_t st = br_pf_step(pf, y, u_prev_Nm);
    if (!BR_FAILED(st)) { /* an outlier step still predicts */
        *F_hat_N = pf->est.F_hat_N;
    }
    return st;
}
