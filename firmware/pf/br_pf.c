/* SPDX-License-Identifier: Apache-2.0 */
/* Particle filter for the friction of one axis, float32. See br_pf.h and
 * docs/modules/pf.md. */
#include "bristle/br_pf.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "bristle/br_encoder.h"
#include "br_check.h"
#include "br_inline.h"
#include "br_math.h"
#include "br_model_kernel.h"

/* BR_FLOAT_SIMD (br_inline.h): with float SIMD the weights' exponentials
 * run in a loop of their own (vectorised), the prediction loop is
 * branch-free and the resampling counts (resample_count, resample_forward);
 * without (the Cortex-M7) one fused weight loop, a prediction loop that
 * branches out to the fix-up and one resampling loop (resample_fused, the
 * indices and F_hat's sum) before the copy's two passes cost fewer
 * instructions. Both copy in place with branches that skip the
 * particles staying put. The results are the same either way. */

/* f_nl (eqs. 3, 4) of a predicted particle: eq. 4 with its k_p = sigma0 L / g_p */
static inline float fnl_kp(const br_model_k_t *k, float om, float z, float kg)
{
    return br_model_k_fnl(k, z, br_model_kp_zdot(k->L, kg, om, z));
}

/* BR_PF_CLONES: on x86-64 hosts (GCC), the vectorised loops are also compiled
 * for AVX-512F and AVX2 and picked at run time by the CPU (target_clones):
 * 16 or 8 lanes instead of SSE2's 4. The same IEEE operations lane by lane
 * (-ffp-contract=off holds in every clone: no FMA), so the results do not
 * depend on the clone. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__linux__)
#define BR_PF_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define BR_PF_CLONES
#endif

/* 1 for a valid particle (its log-weight l is not NaN), 0 for one kept at its state */
static inline float valid_weight(float l) { return (l == l) ? 1.0f : 0.0f; }

/* W of a particle of weight 1 (the best one after the max-shift) */
#define BR_PF_W_ONE (1u << BR_PF_W_BITS)


/* cfg.proposal: the step's constants (docs/modules/pf.md, "A proposal that
 * uses the measurement"). The prior of (theta, omega) around the particle's
 * noise-free prediction has the covariance
 *   S_tt = Q_t + c^2 Q_w,  S_tw = c Q_w,  S_ww = Q_w
 * with c = h/2 (OPT_HELD: omega's noise an acceleration held over the
 * period) or 0 (OPT); y measures theta with variance R, so S = S_tt + R,
 * the gains k_t = S_tt / S, k_w = S_tw / S, and given y the covariance
 *   P_tt = S_tt R / S,  P_tw = S_tw R / S,  P_ww = S_ww - S_tw^2 / S
 * whose Cholesky factor is l00 = sqrt(P_tt), l10 = P_tw / l00 and
 * l11 = sqrt(P_ww - l10^2) = sqrt(Q_w Q_t / S_tt) (S_tt > 0; sqrt(Q_w) when
 * S_tt = 0, where S_tw = 0 too). The gate then compares the predicted
 * residual with S instead of R. Returns BR_E_PARAM when a constant is not
 * finite (pf->cfg, q_std and r_gate are set). */
static br_status_t proposal_init(br_pf_t *pf)
{
    const float qt = pf->cfg.est.q_var[BR_X_THETA], qw = pf->cfg.est.q_var[BR_X_OMEGA];
    const float r = pf->cfg.est.r_var_rad2;
    const float c = (pf->cfg.proposal == BR_PF_PROPOSAL_OPT_HELD) ? 0.5f * pf->cfg.est.model.dt_s : 0.0f;
    const float s_tt = qt + c * c * qw, s_tw = c * qw;
    const float s = s_tt + r;
    const float r_s = r / s;
    pf->prop_k_th = s_tt / s;
    pf->prop_k_om = s_tw / s;
    pf->prop_l00 = sqrtf(s_tt * r_s);
    pf->prop_l10 = (s_tt > 0.0f) ? s_tw * sqrtf(r_s) / sqrtf(s_tt) : 0.0f;
    pf->prop_l11 = (s_tt > 0.0f) ? sqrtf(qw * (qt / s_tt)) : pf->q_std[BR_X_OMEGA];
    pf->prop_inv_2s = 0.5f / s;
    pf->prop_hold = c * pf->q_std[BR_X_OMEGA];
    /* outlier when min_j e_j^2 > g^2 (S + rpc^2 / 12): max_j l_j < -g^2 (S + rpc^2 / 12) / (2 S) */
    pf->outlier_l = -0.5f * pf->cfg.est.outlier_sigma * pf->cfg.est.outlier_sigma *
                    (1.0f + pf->cfg.est.rad_per_count * pf->cfg.est.rad_per_count * (1.0f / 12.0f) / s);
    const float k[] = {pf->prop_k_th, pf->prop_k_om, pf->prop_l00, pf->prop_l10,
                       pf->prop_l11,  pf->prop_inv_2s, pf->prop_hold, pf->outlier_l};
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++) {
        if (!isfinite(k[i])) {
            return BR_E_PARAM;
        }
    }
    return BR_OK;
}

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
    /* the innovation-driven noise: off (nis_ref = 0) or a finite positive
     * reference with alpha in (0, 1] and max_scale in [1, BR_EST_VAR_MAX] */
    const br_pf_adapt_t *ad = &cfg->adapt;
    if (!(ad->nis_ref == 0.0f ||
          (br_finite_nonneg(ad->nis_ref) && ad->nis_ref >= BR_PF_ADAPT_REF_MIN && ad->alpha > 0.0f &&
           ad->alpha <= 1.0f && ad->max_scale >= 1.0f && ad->max_scale <= BR_EST_VAR_MAX))) {
        return BR_E_PARAM;
    }
    if (cfg->proposal > BR_PF_PROPOSAL_OPT_HELD) {
        return BR_E_PARAM;
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
    br_est_dlyid_init(&pf->dlyid, &cfg->est);
    /* gate (docs/modules/pf.md): outlier when min_j e_j^2 > g^2 (R + rpc^2 / 12), R with
     * the encoder's quantisation; in log-weights l = -e^2 / (2 R): max_j l_j < -g^2 (R + rpc^2 / 12) / (2 R) */
    pf->outlier_l = -0.5f * cfg->est.outlier_sigma * cfg->est.outlier_sigma *
                    (1.0f + cfg->est.rad_per_count * cfg->est.rad_per_count * (1.0f / 12.0f) / cfg->est.r_var_rad2);
    pf->r_gate = cfg->est.r_var_rad2 + cfg->est.rad_per_count * cfg->est.rad_per_count * (1.0f / 12.0f);
    pf->nis_avg = 0.0f;
    pf->q_scale_std = 1.0f;
    if (cfg->proposal != BR_PF_PROPOSAL_PRIOR && proposal_init(pf) != BR_OK) {
        return BR_E_PARAM;
    }
    pf->noise_pos = 0u;
    pf->origin_counts = 0;
    pf->primed = 0;
    pf->n_outliers = 0u;
    pf->n_predicted = 0u;
    pf->est = (br_pf_est_t){0, 0.0f};
    pf->weighed = BR_PF_WEIGHED_EQUAL;
    pf->lmax = 0.0f;
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

/* the state vector of particle j */
static void particle_get(const br_pf_t *pf, uint32_t j, float x[BR_NX])
{
    for (int i = 0; i < BR_NX; i++) {
        x[i] = pf->x[i][j];
    }
}

/* Estimate of the freshly drawn set: the mean of f_nl (eq. 6) (its weights
 * all alike: pf->weighed as init left it) */
static void estimate_current(br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    float sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        float xj[BR_NX];
        particle_get(pf, j, xj);
        /* thesis estimate: the mean of f_nl (eq. 6) over the particles */
        sf += br_model_fcomp_N(&pf->model, xj, origin_pos_m(pf));
    }
    pf->est.F_hat_N = sf * (1.0f / (float)m);
    pf->est.origin_counts = pf->origin_counts;
}

/* First measurement: particles drawn around [y, 0, 0, gp0]. */
static void prime(br_pf_t *pf, const br_meas_t *y)
{
    const uint32_t m = pf->cfg.n_particles;
    const float mean[BR_NX] = {y->frac * pf->cfg.est.rad_per_count, 0.0f, 0.0f, pf->cfg.est.gp0_N};
    for (uint32_t j = 0; j < m; j++) {
        for (uint32_t i = 0; i < BR_NX; i++) {
            pf->x[i][j] = mean[i] + pf->cfg.x0_std[i] * noise_at(pf, j, i);
        }
        pf->x[BR_X_GP][j] = br_clampf(pf->x[BR_X_GP][j], pf->cfg.est.gp_min_N, pf->cfg.est.gp_max_N);
        pf->kgp[j] = br_model_kp_of(&pf->model, pf->x[BR_X_GP][j]);
    }
    noise_advance(pf);
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->primed = 1;
    estimate_current(pf);
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

/* The same resampling without a data-dependent inner loop (the vector path
 * on hosts with SIMD, where resample()'s inner loop mispredicts), made by
 * counting: for each particle j the number of points below its cumulative
 * weight C,
 *   N(C) = #{i < m : t_i < C} = floor(X + 1/2), X = m C / C_m,
 * one less when X + 1/2 is an integer (t_i < C <=> (2 i + 1) C_m < 2 m C
 * for integer C, i.e. i < X - 1/2). The float estimate
 *   e = trunc(fl(fl(C) fl(m / C_m)) + (1/2 - 2^-9))
 * has |error| <= 2^-11 in the product (four roundings of 2^-24 relative,
 * X <= m <= 2^11) and 2^-13 in the sum (< 2^12), less than 2^-9 in all, so
 * its argument lies in (X + 1/2 - 2^-8, X + 1/2) and e is N or N - 1;
 * one exact 64-bit comparison, t_e < C, makes it N (for e = m it is false:
 * C <= C_m). Particle i copies the j with N(C_{j-1}) <= i < N(C_j): j is
 * written at i = N(C_{j-1}) (the last j written there is the one with
 * copies) and carried forward by a running maximum (resample_forward).
 * Gives resample()'s indices exactly (test_vector_path_is_scalar_path, whose
 * tie fails without the comparison; the estimate checked once against the
 * exact count over 1.75e8 cases, docs/bench.md). */
static inline uint32_t n_below(uint32_t c, uint64_t two_m, uint64_t cm, float m_over_cm)
{
    const float y = (float)(int32_t)c * m_over_cm + (0.5f - 1.0f / 512.0f);
    const uint32_t e = (uint32_t)(int32_t)y;
    return e + (uint32_t)((uint64_t)(2u * e + 1u) * cm < two_m * (uint64_t)c);
}

/* The quantised weights' total: W_j = floor(w_j 2^16) of the w_j parked in
 * W as bit patterns by exp_vec (any order: an integer sum) */
BR_PF_CLONES static uint32_t quant_total(const uint32_t *BR_RESTRICT W, uint32_t m)
{
    uint32_t total = 0u;
    for (uint32_t j = 0; j < m; j++) {
        float w;
        memcpy(&w, &W[j], sizeof w);
        total += (uint32_t)(w * (float)BR_PF_W_ONE);
    }
    return total;
}

/* The counting resampling's writes: idx[N(C_{j-1})] = j for every j with
 * copies, 0 elsewhere. floats != 0: W holds the w_j as bit patterns
 * (exp_vec), quantised here in place. Otherwise W holds the integer
 * weights already. total: the sum of the W_j. */
static void resample_count(uint32_t *BR_RESTRICT W, uint32_t m, uint32_t total, uint16_t *BR_RESTRICT idx,
                           const int floats)
{
    const uint64_t two_m = 2u * (uint64_t)m, cm = total;
    const float m_over_cm = (float)m / (float)total;
    uint16_t spare = 0u; /* the write of a particle whose N(C_{j-1}) = m (no copies) */
    for (uint32_t i = 0; i < m; i++) {
        idx[i] = 0u;
    }
    uint32_t c = 0u;
    if (floats) {
        for (uint32_t j = 0; j < m; j++) {
            const uint32_t n = n_below(c, two_m, cm, m_over_cm);
            uint16_t *const dst = (n < m) ? &idx[n] : &spare;
            *dst = (uint16_t)j;
            float w;
            memcpy(&w, &W[j], sizeof w);
            const uint32_t q = (uint32_t)(w * (float)BR_PF_W_ONE);
            W[j] = q;
            c += q;
        }
    } else {
        for (uint32_t j = 0; j < m; j++) {
            const uint32_t n = n_below(c, two_m, cm, m_over_cm);
            uint16_t *const dst = (n < m) ? &idx[n] : &spare;
            *dst = (uint16_t)j;
            c += W[j];
        }
    }
}

/* After resample_count: the running maximum that makes idx, fused with the
 * forward pass of the in-place copy (copy_back follows) and with step
 * 5's sum of f_nl over the resampled set in particle order (particle i is the
 * predicted particle k = idx_i). Reading x[k] at i gives the predicted
 * value: for k >= i, position k is written only at i' = k (after this read
 * when k = i); for k < i it is never written in this pass (idx_k <= k, the
 * indices never decrease). Particle i takes k now when k > i, an earlier
 * one in the backward pass. The copies branch: the sign of idx_i - i
 * changes in long runs (br_bench's recording: 49 % of the particles copy
 * forward, 50 % backward, yet only 53 % of the blocks of 8 hold a backward
 * copy), so the branch predicts well and half the loads and stores of a
 * branch-free copy go.
 * The same indices, states and sum (in the same order) as resample_fused. */
static float resample_forward(br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    uint16_t *BR_RESTRICT idx = pf->idx;
    float *BR_RESTRICT th = pf->x[BR_X_THETA];
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA];
    float *BR_RESTRICT zz = pf->x[BR_X_Z];
    float *BR_RESTRICT gg = pf->x[BR_X_GP];
    float *BR_RESTRICT ia = pf->kgp;
    const float *BR_RESTRICT fnl = pf->fnl;
    float sf = 0.0f;
    uint32_t run = 0u;
    for (uint32_t i = 0; i < m; i++) {
        const uint32_t w = idx[i];
        const uint32_t k = (w > run) ? w : run;
        run = k;
        idx[i] = (uint16_t)k;
        /* x[k], read once for the copy (held in registers: GCC reloads
         * them after the first store otherwise) */
        const float a0 = th[k], a1 = om[k], a2 = zz[k], a3 = gg[k];
        sf += fnl[k];
        if (k > i) {
            th[i] = a0;
            om[i] = a1;
            zz[i] = a2;
            gg[i] = a3;
            ia[i] = ia[k];
        }
    }
    return sf;
}

/* resample()'s indices, fused with step 5's sum of f_nl (sum_set), for
 * targets without float SIMD (one loop instead of two): particle i is the
 * predicted particle j = idx_i, so the sum over the resampled set, in
 * particle order, adds the predicted j's f_nl, held in a register while j
 * stays. The in-place copy follows (copy_fwd_soa, copy_back_soa). The same
 * indices and sum as the two loops.
 * total is the sum of W[0 .. m - 1] (quantise_weights' return), so every
 * t_i = floor((2 i + 1) total / (2 m)) <= floor(total - total / (2 m)) is
 * below C_{m-1} = total: the search for j stops by j = m - 1 without a test
 * of j (resample(), for any W, tests it). */
static float resample_fused(br_pf_t *pf, uint32_t total)
{
    const uint32_t m = pf->cfg.n_particles;
    const uint32_t *BR_RESTRICT W = pf->W;
    uint16_t *BR_RESTRICT idx = pf->idx;
    const float *const fnl = pf->fnl;
    const uint32_t den = 2u * m;
    const uint32_t dq = (2u * total) / den, dr = (2u * total) % den;
    uint32_t t = total / den;
    /* t_i's remainder less den, in [-den, 0): its sign is the carry below
     * (the M7's add sets the flag; no compare with den) */
    int32_t rn = (int32_t)(total % den) - (int32_t)den;
    uint32_t j = 0u, c = W[0];
    float af = fnl[0];
    float sf = 0.0f;
    for (uint32_t i = 0; i < m; i++) {
        /* no j + 1 < m test: t_i < C_{m-1} (above), so the search stops by j = m - 1 */
        if (c <= t) {
            do {
                j++;
                c += W[j];
            } while (c <= t);
            af = fnl[j];
        }
        idx[i] = (uint16_t)j;
        sf += af;
        /* t_{i+1} = t_i + dq, plus 1 when the remainder carries */
        t += dq;
        rn += (int32_t)dr;
        if (rn >= 0) {
            t++;
            rn -= (int32_t)den;
        }
    }
    return sf;
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

/* The constants of one prediction pass (steps 1 and 2), for every particle. */
typedef struct {
    br_model_k_t mk;  /* the thesis model's kernel constants */
    br_model_kp_t kp; /* the PF's RK4 constants (br_model_kp_rk4) */
    float s0L;        /* sigma0 L: k_p = s0L / g_p */
    br_model_kx_t mx; /* the extended model's (theta relative to the origin at its p0) */
    float q[BR_NX];   /* process noise standard deviations */
    float gp_min, gp_max, inv_2r;
    float u;          /* torque over the period, N m */
    float shift;      /* theta of the new origin relative to the old one, rad */
    float y_rel;      /* the measurement relative to the new origin, rad */
    int prop;         /* cfg.proposal on a measured step: theta and omega drawn given y */
    float hold;       /* the prior's coupling of omega's sample into theta (OPT_HELD), else 0 */
} pred_t;

/* g_p limited to [lo, hi] with selects (fmaxf/fminf are library calls on
 * some hosts): br_clampf's result for every input, lo > 0; with
 * BR_FPU_MAXNM (br_inline.h) fmaxf and fminf themselves, one instruction
 * each (the same result: lo and hi are finite, 0 < lo < hi, br_est.c) */
static inline float clamp_sel(float v, float lo, float hi)
{
#if BR_FPU_MAXNM
    return fminf(fmaxf(v, lo), hi);
#else
    const float a = (v > lo) ? v : lo; /* a NaN gives lo, as fmaxf */
    return (a < hi) ? a : hi;
#endif
}

/* Largest log-weight so far and the count of valid particles. l <= -0 for a
 * valid particle, so its bit pattern as int32 (its key) is negative and
 * orders the other way round: the largest l has the smallest key (the vector
 * loop reduces the keys with an integer min, which vectorises where fmaxf
 * does not). s1, s2: cfg.adapt's sums over the particles in their order, of
 * d_j = theta_j - y and of d_j^2, made from the innovation the log-weight
 * forms (adapt_update). */
typedef struct {
    float lmax;
    uint32_t n_valid;
    float s1, s2;
} lsum_t;

/* a valid particle: log-weight l, innovation e = theta_j - y (d_j = e 1 = e) */
static inline void lsum_add(lsum_t *s, float l, float e)
{
    s->lmax = (l > s->lmax) ? l : s->lmax; /* fmaxf for l not NaN */
    s->n_valid++;
    s->s1 += e;
    s->s2 += e * e;
}

/* an invalid particle (kept at theta_j): d_j = (theta_j - y) 0, as
 * adapt_sums adds it (it changes the sums only when theta_j - y is not finite) */
static inline void lsum_skip(lsum_t *s, float th, float y_rel)
{
    const float d = (th - y_rel) * 0.0f;
    s->s1 += d;
    s->s2 += d * d;
}

/* Steps 1 and 2 for particle j, one at a time: the scalar reference path,
 * and the fix-up of the vector loop's rare cases (the bounded scheme, an
 * invalid prediction). n: its BR_NX standard-normal samples. The particle is
 * overwritten by its prediction when that is valid and added to *ls
 * (lsum_add); otherwise it keeps its state, f_nl = 0, l = NaN (lsum_skip).
 * ext: the extended model's kernel (a constant at each call site). */
BR_INLINE void particle_one(br_pf_t *pf, const pred_t *c, const int ext, uint32_t j, const float n[BR_NX], lsum_t *ls)
{
    float x[BR_NX], xn[BR_NX];
    particle_get(pf, j, x);
    /* 1. predict: eq. 6 by RK4 (the PF's form with k_p, or the extended
     * model's), or the bounded scheme beyond the a h limit; the particles are
     * finite with g_p >= gp_min > 0 */
    if (ext ? !br_model_kx_rk4(&c->mx, x, c->u, xn) : !br_model_kp_rk4(&c->kp, x, pf->kgp[j], xn)) {
        if (ext) {
            br_model_bounded_step_x(&c->mx, x, c->u, xn);
        } else {
            br_model_bounded_step(&pf->model, x, c->u, xn);
        }
    }
    float th_old, th, om, l_prop = 0.0f, th_a;
    if (c->prop) {
        /* cfg.proposal, a measured step: (theta, omega) drawn from their Gaussian
         * given y around the noise-free prediction mu (proposal_init); the
         * weight is the predictive likelihood of y, -e^2 / (2 S), e = mu - y */
        const float mu = xn[BR_X_THETA] - c->shift;
        const float e = mu - c->y_rel;
        th = (mu - pf->prop_k_th * e) + pf->prop_l00 * n[0];
        th_old = th + c->shift;
        om = ((xn[BR_X_OMEGA] - pf->prop_k_om * e) + pf->prop_l10 * n[0]) + pf->prop_l11 * n[1];
        l_prop = -(e * e) * pf->prop_inv_2s;
        /* the prior's draw of theta with the same samples: cfg.adapt's
         * innovation of the predicted cloud is the prior's */
        th_a = ((mu + c->q[0] * n[0]) + c->hold * n[1]);
    } else if (c->hold != 0.0f) {
        /* OPT_HELD without a measurement: the prior, omega's sample moving theta by h/2 of it */
        th_old = (xn[BR_X_THETA] + c->q[0] * n[0]) + c->hold * n[1];
        th = th_old - c->shift;
        om = xn[BR_X_OMEGA] + c->q[1] * n[1];
        th_a = th;
    } else {
        /* process noise sqrt(Q) n */
        th_old = xn[BR_X_THETA] + c->q[0] * n[0]; /* relative to the last origin */
        th = th_old - c->shift;
        om = xn[BR_X_OMEGA] + c->q[1] * n[1];
        th_a = th;
    }
    const float z = xn[BR_X_Z] + c->q[2] * n[2];
    const float gp = clamp_sel(xn[BR_X_GP] + c->q[3] * n[3], c->gp_min, c->gp_max);
    /* the particle's one division, k_p = sigma0 L / g_p for eq. 4 here and in the next step */
    const float kg = c->s0L / gp;
    /* the force to compensate of the predicted particle: eq. 6's f_nl, or
     * the extended model's (at its position relative to the last origin) */
    float fnl;
    if (ext) {
        const float xe[BR_NX] = {th_old, om, z, gp};
        fnl = br_model_kx_fcomp_N(&c->mx, xe);
    } else {
        fnl = fnl_kp(&c->mk, om, z, kg);
    }
    /* Validity: x - x is 0 for finite x and NaN otherwise. g_p is finite after
     * the clamp; a non-finite omega or z makes f_nl non-finite (inf - inf,
     * 0 * inf or inf in eqs. 3-4), so theta and f_nl tell all four states. */
    if ((th - th) + (fnl - fnl) == 0.0f) {
        pf->x[BR_X_THETA][j] = th;
        pf->x[BR_X_OMEGA][j] = om;
        pf->x[BR_X_Z][j] = z;
        pf->x[BR_X_GP][j] = gp;
        pf->kgp[j] = kg;
        pf->fnl[j] = fnl;
        /* 2. Gaussian log-likelihood of the measurement, -(theta_j - y)^2 / (2 R);
         * may be -inf for a particle far from y: still valid (NaN marks invalid) */
        const float e = th - c->y_rel;
        const float l = c->prop ? l_prop : -(e * e) * c->inv_2r;
        pf->l[j] = l;
        /* cfg.adapt's sums take the prior's innovation (e itself without cfg.proposal) */
        lsum_add(ls, l, c->prop ? th_a - c->y_rel : e);
        return;
    }
    /* unusable: the particle keeps its state and gets weight 0; its log-weight
     * is NaN, which no valid particle's can be */
    pf->fnl[j] = 0.0f;
    pf->l[j] = NAN;
    lsum_skip(ls, x[BR_X_THETA], c->y_rel);
}

/* the BR_NX samples of particle j, read round the end of the table */
static void noise_wrapped(const br_pf_t *pf, uint32_t j, float n[BR_NX])
{
    for (uint32_t i = 0; i < BR_NX; i++) {
        n[i] = noise_at(pf, j, i);
    }
}

/* Steps 1 and 2, thesis model, particles j0 .. j1 - 1 whose noise samples
 * are the contiguous nz[BR_NX (j - j0) + i]: branch-free, so that the
 * compiler vectorises it. A particle that needs the bounded scheme or whose
 * prediction is not valid keeps its state here (l = NaN) and is redone by
 * particle_one afterwards. Adds its valid particles to *ls; returns the
 * number of particles left for the fix-up. cfg.adapt's sums take every
 * particle's innovation in order, so they hold only when no particle is
 * left (the caller makes them again after a fix-up). */
BR_PF_CLONES static uint32_t predict_vec(br_pf_t *pf, const pred_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                         lsum_t *ls)
{
    const br_model_kp_t kp = c->kp;
    /* f_nl's L taken from kp (the same value): one constant fewer in the loop */
    br_model_k_t mk = c->mk;
    mk.L = kp.L;
    const float s0L = c->s0L;
    const float q0 = c->q[0], q1 = c->q[1], q2 = c->q[2], q3 = c->q[3];
    const float gp_min = c->gp_min, gp_max = c->gp_max, inv_2r = c->inv_2r;
    const float shift = c->shift, y_rel = c->y_rel;
#if BR_FPU_MAXNM && !BR_FLOAT_SIMD
    uint32_t ah_lim_bits;
    memcpy(&ah_lim_bits, &kp.ah_lim, sizeof ah_lim_bits);
#endif
    float *BR_RESTRICT th = pf->x[BR_X_THETA] + j0;
    float *BR_RESTRICT om = pf->x[BR_X_OMEGA] + j0;
    float *BR_RESTRICT zz = pf->x[BR_X_Z] + j0;
    float *BR_RESTRICT gg = pf->x[BR_X_GP] + j0;
    float *BR_RESTRICT ka = pf->kgp + j0;
    float *BR_RESTRICT fo = pf->fnl + j0;
    float *BR_RESTRICT lo = pf->l + j0;
    const float *BR_RESTRICT nn = nz;
    const size_t n = j1 - j0;
#if BR_FPU_MAXNM
    float lm = -INFINITY; /* the largest valid l by fmaxf (one instruction there) instead of the keys */
#else
    int32_t kmin = INT32_MAX;
#endif
#if BR_FLOAT_SIMD
    uint32_t n_ok = 0u;
#else
    uint32_t n_ok = (uint32_t)n; /* less one for each particle that branches out */
#endif
    float s1 = ls->s1, s2 = ls->s2;
#if !BR_FLOAT_SIMD
    const float *np = nn; /* particle j's samples, BR_NX = 4 of them */
    float *fp = fo, *lp = lo; /* f_nl and l stored by br_store_f_inc (vstmia with write-back) */
#endif
    for (size_t j = 0; j < n; j++) {
        const float x[BR_NX] = {th[j], om[j], zz[j], gg[j]};
        float xn[BR_NX];
        /* 1. predict (RK4 of eq. 6; ok_rk = 0 where the bounded scheme is needed) */
        const float kg0 = ka[j];
#if BR_FPU_MAXNM
        /* the a h test as one compare of the larger product (vmaxnm): the
         * start's, k_p |omega_0|, is finite (a finite particle, k_p > 0), so
         * the larger is NaN never, and it is <= the limit exactly when both
         * are, unless the end's is NaN (fmaxf passes over it): then the
         * predicted omega is NaN, so is f_nl (eq. 4 propagates it), and the
         * validity test below sends the particle to the fix-up, whose
         * particle_one makes the test of both (br_model_kp_rk4). The same
         * particles reach the fix-up either way. */
        float ah0, ah1;
        br_model_kp_rk4_step(&kp, x, kg0, xn, &ah0, &ah1);
        const float ahm = fmaxf(ah0, ah1);
#if BR_FLOAT_SIMD
        const int ok_rk = ahm <= kp.ah_lim;
#endif
#else
        const int ok_rk = br_model_kp_rk4(&kp, x, kg0, xn);
#endif
        /* process noise sqrt(Q) n */
#if BR_FLOAT_SIMD
        const float *const nj = nn + BR_NX * j;
#else
        float nj[BR_NX];
        br_load4_f(&np, nj); /* the M7: one vldmia for the four samples */
#endif
        const float t = (xn[BR_X_THETA] + q0 * nj[0]) - shift;
        const float w = xn[BR_X_OMEGA] + q1 * nj[1];
        const float z = xn[BR_X_Z] + q2 * nj[2];
        const float g = clamp_sel(xn[BR_X_GP] + q3 * nj[3], gp_min, gp_max);
        /* the particle's one division */
        const float kg = s0L / g;
        /* f_nl of the predicted particle (eqs. 3, 4) */
        const float f = fnl_kp(&mk, w, z, kg);
        /* 2. log-likelihood */
        const float e = t - y_rel;
        const float l = -(e * e) * inv_2r;
        s1 += e;
        s2 += e * e;
        /* validity as particle_one's */
#if BR_FLOAT_SIMD
        const int ok = ok_rk & ((t - t) + (f - f) == 0.0f);
#else
        /* without float SIMD (the Cortex-M7) nothing is gained by a
         * branch-free body: a particle for the fix-up (the bounded scheme, or
         * not valid) branches out, keeping its state in place (f_nl = 0,
         * l = NaN), and the selects below fold away for the valid ones */
#if BR_FPU_MAXNM
        /* the a h test and the validity test as one compare, on the bit
         * patterns: v - v with v = t + f is +0 when t and f are finite (and
         * v does not overflow), NaN otherwise, so c_ah = ahm + (v - v) is
         * ahm (>= +0: k_p > 0) or a NaN. As unsigned integers the patterns
         * of floats >= +0 order as the floats do and every NaN's, of either
         * sign, lies above the limit's, so c_bits <= ah_lim_bits exactly
         * when the particle is inside the RK4 limit and valid; the limit
         * sits in an integer register, one float register more for the
         * loop's constants. An overflow of t + f alone (both finite) sends
         * a valid particle to the fix-up, which makes the same prediction
         * (particle_one): the same results either way. */
        const float v = t + f, c_ah = ahm + (v - v);
        uint32_t c_bits;
        memcpy(&c_bits, &c_ah, sizeof c_bits);
        if (!(c_bits <= ah_lim_bits)) {
#else
        if (!ok_rk || !((t - t) + (f - f) == 0.0f)) {
#endif
            br_store_f_inc(&fp, 0.0f);
            br_store_f_inc(&lp, NAN);
            n_ok--;
            continue;
        }
        const int ok = 1;
#endif
        th[j] = ok ? t : x[BR_X_THETA];
        om[j] = ok ? w : x[BR_X_OMEGA];
        zz[j] = ok ? z : x[BR_X_Z];
        gg[j] = ok ? g : x[BR_X_GP];
        ka[j] = ok ? kg : kg0;
        const float lk = ok ? l : NAN;
#if BR_FLOAT_SIMD
        fo[j] = ok ? f : 0.0f;
        lo[j] = lk;
#else
        br_store_f_inc(&fp, f);
        br_store_f_inc(&lp, lk);
#endif
#if BR_FPU_MAXNM
        lm = fmaxf(lm, lk); /* fmaxf passes over a NaN */
#else
        /* NAN is a positive NaN: its key is above every valid one */
        int32_t key;
        memcpy(&key, &lk, sizeof key);
        kmin = (key < kmin) ? key : kmin;
#endif
#if BR_FLOAT_SIMD
        n_ok += (uint32_t)ok;
#endif
    }
    ls->s1 = s1;
    ls->s2 = s2;
    if (n_ok > 0u) {
#if !BR_FPU_MAXNM
        float lm;
        memcpy(&lm, &kmin, sizeof lm);
#endif
        ls->lmax = (lm > ls->lmax) ? lm : ls->lmax;
        ls->n_valid += n_ok;
    }
    return (uint32_t)n - n_ok;
}

/* cfg.adapt's sums over particles k0 .. k1 - 1 in their order, from the
 * predicted set (the fix-up's runs): d = (theta_k - y) v with v = 1 for a
 * valid particle (l not NaN) and 0 for one kept at its state: the same
 * additions of the same values as lsum_add and lsum_skip (e 1 = e). */
static void adapt_sums(const br_pf_t *pf, float y_rel, uint32_t k0, uint32_t k1, lsum_t *ls)
{
    const float *const th = pf->x[BR_X_THETA], *const l = pf->l;
    float s1 = ls->s1, s2 = ls->s2;
    for (uint32_t k = k0; k < k1; k++) {
        const float v = valid_weight(l[k]);
        const float d = (th[k] - y_rel) * v;
        s1 += d;
        s2 += d * d;
    }
    ls->s1 = s1;
    ls->s2 = s2;
}

/* Steps 1 and 2 for every particle: prediction in place, the force to
 * compensate (f_nl for the thesis model), log-weight. Returns the number of
 * valid (finite) predicted particles, their largest log-weight in *lmax and
 * cfg.adapt's sums of d_j = theta_j - y_rel and d_j^2 in sums[0], sums[1]
 * (adapt_sums' over all particles; with cfg.proposal, theta_j of the prior's
 * draw). measured: 0 for br_pf_predict's step without a measurement. */
static uint32_t predict_and_weigh(br_pf_t *pf, float u_prev_Nm, float shift, float y_rel, int measured,
                                  float *lmax, float sums[2])
{
    /* the model's clock moves on by one period (friction_drift) */
    br_model_tick(&pf->model);
    pred_t c;
    c.mk = br_model_k(&pf->model);
    c.kp = br_model_kp(&pf->model, u_prev_Nm);
    c.s0L = pf->model.cfg.lugre.sigma0_Npm * pf->model.cfg.lead_mprad;
    /* the extended kernel's constants (a few operations per step; unused by the thesis model) */
    c.mx = br_model_kx(&pf->model, origin_pos_m(pf));
    for (int i = 0; i < BR_NX; i++) {
        c.q[i] = pf->q_std[i];
    }
    /* cfg.adapt: omega's, z's and g_p's noise scaled (by exactly 1 while the smoothed NIS stays
     * below its reference); omega's only for the bootstrap draw: cfg.proposal draws omega from
     * its own constants (proposal_init), with which its held theta term stays consistent */
    if (pf->cfg.proposal == BR_PF_PROPOSAL_PRIOR) {
        c.q[BR_X_OMEGA] *= pf->q_scale_std;
    }
    c.q[BR_X_Z] *= pf->q_scale_std;
    c.q[BR_X_GP] *= pf->q_scale_std;
    c.gp_min = pf->cfg.est.gp_min_N;
    c.gp_max = pf->cfg.est.gp_max_N;
    c.inv_2r = pf->inv_2r;
    c.u = u_prev_Nm;
    c.shift = shift;
    c.y_rel = y_rel;
    c.prop = measured && pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR;
    c.hold = (pf->cfg.proposal == BR_PF_PROPOSAL_OPT_HELD) ? pf->prop_hold : 0.0f;
    const uint32_t m = pf->cfg.n_particles, mask = pf->cfg.noise_len - 1u;
    lsum_t ls = {-INFINITY, 0u, 0.0f, 0.0f};
    float n[BR_NX];
    if (pf->model.extended || pf->cfg.scalar_path || pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR) {
        /* one particle at a time (the extended model always: its kernel branches;
         * cfg.proposal always: the vector loop draws from the prior) */
        for (uint32_t j = 0; j < m; j++) {
            noise_wrapped(pf, j, n);
            if (pf->model.extended) {
                particle_one(pf, &c, 1, j, n, &ls);
            } else {
                particle_one(pf, &c, 0, j, n, &ls);
            }
        }
    } else {
        /* runs of particles whose samples lie in one block of the table; a
         * particle whose samples wrap round its end on its own */
        uint32_t j = 0u;
        while (j < m) {
            const uint32_t p = (pf->noise_pos + BR_NX * j) & mask;
            const uint32_t room = (mask + 1u - p) / BR_NX; /* particles before the wrap */
            if (room == 0u) {
                noise_wrapped(pf, j, n);
                particle_one(pf, &c, 0, j, n, &ls);
                j++;
                continue;
            }
            const uint32_t j1 = (m - j < room) ? m : j + room;
            const float *const nz = pf->cfg.noise + p;
            const float s1 = ls.s1, s2 = ls.s2;
            if (predict_vec(pf, &c, j, j1, nz, &ls) > 0u) {
                /* the fix-up: redo the particles the vector loop left (l = NaN) in scalar */
                for (uint32_t k = j; k < j1; k++) {
                    if (pf->l[k] != pf->l[k]) {
                        particle_one(pf, &c, 0, k, nz + BR_NX * (k - j), &ls);
                    }
                }
                /* cfg.adapt's sums over the run again, in particle order */
                ls.s1 = s1;
                ls.s2 = s2;
                adapt_sums(pf, y_rel, j, j1, &ls);
            }
            j = j1;
        }
    }
    *lmax = ls.lmax;
    sums[0] = ls.s1;
    sums[1] = ls.s2;
    return ls.n_valid;
}

/* w_j = e^(l_j - lmax) for j < m, stored as their bit patterns in W */
BR_PF_CLONES static void exp_vec(const float *BR_RESTRICT l, uint32_t *BR_RESTRICT W, float lmax, uint32_t m)
{
    for (uint32_t j = 0; j < m; j++) {
        const float w = br_exp_neg(l[j] - lmax);
        memcpy(&W[j], &w, sizeof w);
    }
}

/* Step 3: max-shifted weights w_j = e^(l_j - lmax), quantised to W_j (an invalid
 * particle has l_j = NaN and br_exp_neg gives 0 for it); on an outlier every
 * valid particle (l_j not NaN, even -inf when its residual overflowed) gets w = 1
 * (step_weight: these w_j, for br_pf_stats). Returns the total of W. */
static uint32_t quantise_weights(br_pf_t *pf, float lmax, int outlier)
{
    const uint32_t m = pf->cfg.n_particles;
    const float *BR_RESTRICT l = pf->l;
    uint32_t *BR_RESTRICT W = pf->W;
    uint32_t total = 0u;
    if (outlier) {
        for (uint32_t j = 0; j < m; j++) {
            const float w = valid_weight(l[j]);
            W[j] = (uint32_t)(w * (float)BR_PF_W_ONE);
            total += W[j];
        }
    } else {
        /* (the vector path's weights: exp_vec, quant_total and resample_count);
         * br_exp_neg's constants taken once, held in registers over the loop */
        const br_exp_k_t k = br_exp_k();
        for (uint32_t j = 0; j < m; j++) {
            /* W_j = floor(w_j 2^16), the scale in the exponent (br_exp_neg_w16_k) */
            W[j] = (uint32_t)br_exp_neg_w16_k(l[j] - lmax, k);
            total += W[j];
        }
    }
    return total;
}

/* w_j of the last step's weighing (quantise_weights' and exp_vec's: the same
 * value, br_math.h), from the log-weight it left */
static float step_weight(const br_pf_t *pf, uint32_t j)
{
    const float l = pf->l[j];
    return (pf->weighed == BR_PF_WEIGHED_VALID) ? valid_weight(l) : br_exp_neg(l - pf->lmax);
}

/* Step 4's copy, in place: particle i becomes the predicted particle idx_i.
 * The indices never decrease (systematic resampling), so a forward pass can
 * take every particle from a later one (not yet overwritten) and a backward
 * pass every particle from an earlier one (idx_k <= k there, so its source
 * was left alone by the forward pass); a particle with idx_i = i copies
 * itself. Each pass skips the particles that stay (on hosts too: the
 * branch predicts well, see resample_forward). The arrays are parameters
 * of a function of its own and each value is copied as its bit pattern
 * (memcpy): the Cortex-M7 then holds the five arrays in registers and
 * addresses them by index (integer loads and stores take a register offset,
 * float ones do not), where with pf->x it formed the 8 KiB-apart addresses
 * anew for every particle (docs/target.md). Both passes are compiled
 * without GCC's induction variable optimisation (BR_NO_IVOPTS): each
 * access then takes the index i itself as its register offset.
 * The forward pass, after resample_fused (the host's vector path makes it in
 * resample_forward): from i = 0 up to m - 2 (particle m - 1 has no later one). */
static inline void move_particle(uint32_t i, uint32_t k, float *th, float *om, float *zz, float *gg, float *ia)
{
    memcpy(&th[i], &th[k], sizeof th[i]);
    memcpy(&om[i], &om[k], sizeof om[i]);
    memcpy(&zz[i], &zz[k], sizeof zz[i]);
    memcpy(&gg[i], &gg[k], sizeof gg[i]);
    memcpy(&ia[i], &ia[k], sizeof ia[i]);
}

BR_NO_IVOPTS BR_NOINLINE void copy_fwd_soa(const uint16_t *BR_RESTRICT idx, uint32_t m, float *th, float *om,
                                           float *zz, float *gg, float *ia)
{
    const uint32_t last = m - 1u; /* m >= 1; the bound once, not i + 1 < m per particle */
    for (uint32_t i = 0u; i < last; i++) {
        const uint32_t k = idx[i];
        if (k > i) {
            move_particle(i, k, th, om, zz, gg, ia);
        }
    }
}

/* The backward pass, after copy_fwd_soa or resample_forward: from i = m - 1
 * down to 1 (particle 0 has no earlier one). */
BR_NO_IVOPTS BR_NOINLINE void copy_back_soa(const uint16_t *BR_RESTRICT idx, uint32_t m, float *th, float *om,
                                            float *zz, float *gg, float *ia)
{
    for (uint32_t i = m - 1u; i > 0u; i--) {
        const uint32_t k = idx[i];
        if (k < i) {
            move_particle(i, k, th, om, zz, gg, ia);
        }
    }
}

/* copy_fwd_soa and copy_back_soa on pf's particles */
static void copy_fwd(br_pf_t *pf)
{
    copy_fwd_soa(pf->idx, pf->cfg.n_particles, pf->x[BR_X_THETA], pf->x[BR_X_OMEGA], pf->x[BR_X_Z],
                 pf->x[BR_X_GP], pf->kgp);
}

static void copy_back(br_pf_t *pf)
{
    copy_back_soa(pf->idx, pf->cfg.n_particles, pf->x[BR_X_THETA], pf->x[BR_X_OMEGA], pf->x[BR_X_Z],
                  pf->x[BR_X_GP], pf->kgp);
}

/* Step 5's sum over the set, in particle order: f_nl of the set's predicted
 * particles idx_j. */
static float sum_set(const br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    const uint16_t *const idx = pf->idx;
    const float *const fnl = pf->fnl;
    float sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        sf += fnl[idx[j]];
    }
    return sf;
}

/* The sum of state i over the set, in particle order (br_pf_stats' mean; the
 * re-anchoring's theta and omega) */
static float sum_state(const br_pf_t *pf, int i)
{
    const uint32_t m = pf->cfg.n_particles;
    const float *const x = pf->x[i];
    float s = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        s += x[j];
    }
    return s;
}

/* cfg.adapt: the normalised innovation squared of the predicted cloud,
 * (y - mean theta_j)^2 / (var theta_j + R + rpc^2 / 12) over the n valid
 * particles (theta relative to the new origin; d_j = theta_j - y, whose
 * sums s1, s2 predict_and_weigh makes), limited to outlier_sigma^2 (also
 * for a NaN or an overflow); then E and the factor on omega's, z's and g_p's
 * noise std for the next predictions. */
static void adapt_update(br_pf_t *pf, float s1, float s2, uint32_t n_valid)
{
    const float n = (float)n_valid; /* exact: n_valid <= BR_PF_MAX_PARTICLES */
    /* n >= 1: called with at least one valid particle */
    const float mean = s1 / n;
    const float var = s2 / n - mean * mean;
    float nis = (mean * mean) / (((var > 0.0f) ? var : 0.0f) + pf->r_gate);
    const float nis_max = pf->cfg.est.outlier_sigma * pf->cfg.est.outlier_sigma; /* <= 1e8 */
    nis = (nis <= nis_max) ? nis : nis_max; /* a NaN too */
    const br_pf_adapt_t *ad = &pf->cfg.adapt;
    pf->nis_avg += ad->alpha * (nis - pf->nis_avg);
    const float s = pf->nis_avg / ad->nis_ref;
    pf->q_scale_std = (s > 1.0f) ? sqrtf((s < ad->max_scale) ? s : ad->max_scale) : 1.0f;
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
    /* the delay's identification (off unless cfg.est.delay_id.n_cand): from the next period on,
     * the torque with the delay it finds */
    br_est_dlyid_step(&pf->dlyid, &pf->cfg.est, y, &pf->delay);
    if (!pf->primed) {
        prime(pf, y);
        return BR_OK;
    }
    const uint32_t m = pf->cfg.n_particles;
    const float rpc = pf->cfg.est.rad_per_count;
    /* new integer origin: theta_j is re-expressed relative to y.counts */
    const float shift = (float)br_counts_delta(y->counts, pf->origin_counts) * rpc;
    const float y_rel = y->frac * rpc;
    float lmax, sums[2];
    const uint32_t n_valid = predict_and_weigh(pf, u_a, shift, y_rel, 1, &lmax, sums);
    noise_advance(pf);
    if (n_valid == 0u) {
        pf->weighed = BR_PF_WEIGHED_NONE;
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* an outlier also when every valid particle's log-weight overflowed to -inf
     * (the max-shift needs a finite lmax) */
    const br_status_t verdict = (lmax < pf->outlier_l || lmax == -INFINITY) ? BR_W_OUTLIER : BR_OK;
    if (pf->cfg.adapt.nis_ref > 0.0f) {
        adapt_update(pf, sums[0], sums[1], n_valid);
    }

    /* 3. max-shifted weights, quantised; an outlier gives every valid particle weight 1 */
    /* 4. deterministic systematic resampling on the integer weights (total >= 2^16:
     * the best valid particle has W = 2^16) */
    /* 5. estimate over the resampled set: the mean of f_nl (eq. 6); the
     * particle mean and the ESS on request (br_pf_stats, from the set and l) */
    pf->weighed = (verdict == BR_W_OUTLIER) ? BR_PF_WEIGHED_VALID : BR_PF_WEIGHED_LOG;
    pf->lmax = lmax;
    float sf;
    if (BR_FLOAT_SIMD && !pf->cfg.scalar_path) {
        if (verdict == BR_W_OUTLIER) {
            const uint32_t total = quantise_weights(pf, lmax, 1);
            resample_count(pf->W, m, total, pf->idx, 0);
        } else {
            /* the exponentials in a loop of their own (vectorised), w parked
             * in W's storage as its bit pattern; the total of the quantised
             * weights (vectorised); then the quantisation in place, in the
             * counting loop */
            exp_vec(pf->l, pf->W, lmax, m);
            const uint32_t total = quant_total(pf->W, m);
            resample_count(pf->W, m, total, pf->idx, 1);
        }
        sf = resample_forward(pf);
        copy_back(pf);
    } else {
        const uint32_t total = quantise_weights(pf, lmax, verdict == BR_W_OUTLIER);
        /* one loop for the indices and the sum, then the copy's forward and backward passes */
        sf = resample_fused(pf, total);
        copy_fwd(pf);
        copy_back(pf);
    }
    const float inv_m = 1.0f / (float)m;
    pf->n_outliers = (verdict == BR_W_OUTLIER) ? pf->n_outliers + 1u : 0u;
    if (pf->n_outliers >= pf->cfg.est.reanchor_after) {
        /* lost lock: re-anchor the cloud on the measurement, keeping its spread:
         * theta's mean moves to y, omega's mean to the measured velocity */
        const float periods = (float)pf->n_predicted + 1.0f;
        const float omega_meas = (shift + (y->frac - pf->prev_frac) * rpc) / (periods * pf->cfg.est.model.dt_s);
        const float d_th = y_rel - sum_state(pf, BR_X_THETA) * inv_m;
        const float d_om = omega_meas - sum_state(pf, BR_X_OMEGA) * inv_m;
        sf = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            pf->x[BR_X_THETA][j] += d_th;
            pf->x[BR_X_OMEGA][j] += d_om;
            /* f_nl depends on omega: the estimate is that of the moved cloud */
            float xj[BR_NX];
            particle_get(pf, j, xj);
            sf += br_model_fcomp_N(&pf->model, xj, (float)y->counts * pf->m_per_count);
        }
    }
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->n_predicted = 0u;
    pf->est.F_hat_N = sf * inv_m;
    pf->est.origin_counts = y->counts;
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
    float lmax, sums[2];
    /* no measurement: the delay's identification starts again at the next one */
    pf->dlyid.primed = 0;
    const uint32_t n_valid = predict_and_weigh(pf, br_est_delay_apply(&pf->delay, u_prev_Nm), 0.0f, 0.0f, 0, &lmax,
                                               sums);
    noise_advance(pf);
    if (n_valid == 0u) {
        pf->weighed = BR_PF_WEIGHED_NONE;
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* every particle moves on unweighted (an invalid one kept its state) */
    for (uint32_t j = 0; j < m; j++) {
        pf->idx[j] = (uint16_t)j;
    }
    pf->est.F_hat_N = sum_set(pf) * (1.0f / (float)m);
    pf->weighed = BR_PF_WEIGHED_EQUAL;
    if (pf->n_predicted < UINT32_MAX) {
        pf->n_predicted++;
    }
    return BR_OK;
}

/* The particle mean of the set (equal weights after every step), each state
 * summed in particle order */
static void set_mean(const br_pf_t *pf, float mean[BR_NX])
{
    const float inv_m = 1.0f / (float)pf->cfg.n_particles;
    for (int i = 0; i < BR_NX; i++) {
        mean[i] = sum_state(pf, i) * inv_m;
    }
}

const br_pf_est_t *br_pf_estimate(const br_pf_t *pf) { return (pf != NULL) ? &pf->est : NULL; }

br_status_t br_pf_stats(const br_pf_t *pf, br_pf_stats_t *out)
{
    if (pf == NULL || out == NULL) {
        return BR_E_NULL;
    }
    if (!pf->ready || !pf->primed) {
        return BR_E_STATE; /* no set: before the first measurement, or after a failed init */
    }
    const uint32_t m = pf->cfg.n_particles;
    set_mean(pf, out->mean);
    if (pf->weighed == BR_PF_WEIGHED_EQUAL) {
        out->ess = (float)m;
    } else if (pf->weighed == BR_PF_WEIGHED_NONE) {
        out->ess = 0.0f;
    } else {
        /* effective sample size of the step's weights, (sum w)^2 / sum w^2,
         * the sums in particle order; sum w >= 1 (the best valid particle has w = 1) */
        float sw = 0.0f, sw2 = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            const float w = step_weight(pf, j);
            sw += w;
            sw2 += w * w;
        }
        out->ess = sw * sw / sw2;
    }
    return BR_OK;
}

br_status_t br_pf_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    br_pf_t *pf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    br_status_t st = br_pf_step(pf, y, u_prev_Nm);
    if (!BR_FAILED(st)) { /* an outlier step still predicts */
        /* the compensation: F_hat, or the force predicted ahead from the
         * particle mean (cfg.est.comp_ahead_periods) */
        *F_hat_N = pf->est.F_hat_N;
        if (pf->cfg.est.comp_ahead_periods > 0.0f) {
            float mean[BR_NX];
            set_mean(pf, mean);
            *F_hat_N = br_est_comp_N(&pf->cfg.est, &pf->model, &pf->delay, mean, origin_pos_m(pf), u_prev_Nm,
                                     pf->est.F_hat_N);
        }
    }
    return st;
}
