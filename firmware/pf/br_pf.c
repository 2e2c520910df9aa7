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
#include "br_math.h"
#include "br_model_kernel.h"
#include "br_pf_kernel.h"
#include "br_pf_load.h"

/* br_pf.c orchestrates one step; the hot loops of steps 1-5 are the kernel's
 * (br_pf_kernel.h: br_pf_kernel_* of the target, chosen by
 * firmware/CMakeLists.txt, or the reference br_pf_kref_* on the scalar
 * reference path). particle_one, the per-particle step, is the reference of
 * steps 1 and 2 for every model and proposal and the fix-up of the particles
 * a kernel leaves (the bounded scheme, an invalid prediction). */

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
    /* gate (eq. G1 with S for R): outlier when min_j e_j^2 > (g sqrt(S + rpc^2 / 12) + d)^2:
     * max_j l_j < -g^2 (S + rpc^2 / 12) f^2 / (2 S), f = 1 + d / (g sqrt(S + rpc^2 / 12)) */
    const float rpc2_12 = pf->cfg.est.rad_per_count * pf->cfg.est.rad_per_count * (1.0f / 12.0f);
    pf->outlier_l = -0.5f * pf->cfg.est.outlier_sigma * pf->cfg.est.outlier_sigma * (1.0f + rpc2_12 / s) *
                    br_est_gate_f2(&pf->cfg.est, s + rpc2_12);
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
    /* Maxwell-slip elements (docs/modules/pf.md): each particle's n deflections
     * must fit the storage (n m <= BR_PF_MS_SLOTS), and the look-ahead, which
     * steps the LuGre state, must be off (br_model_init checks the set itself) */
    const uint32_t n_el = (cfg->est.model.mslip.n > 0) ? (uint32_t)cfg->est.model.mslip.n : 0u;
    if (n_el > 0u && (n_el * cfg->n_particles > BR_PF_MS_SLOTS || cfg->est.comp_ahead_periods != 0.0f)) {
        return BR_E_PARAM;
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
    /* g_p along the curve: off, or on with rho in [0, 1] */
    if (cfg->gp_curve.on > 1u || (cfg->gp_curve.on && !(cfg->gp_curve.rho >= 0.0f && cfg->gp_curve.rho <= 1.0f))) {
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
    /* gate (eq. G1, docs/modules/pf.md): outlier when min_j e_j^2 > (g sqrt(R + rpc^2 / 12) + d)^2,
     * R with the encoder's quantisation, d the transient term; in log-weights l = -e^2 / (2 R):
     * max_j l_j < -g^2 (R + rpc^2 / 12) f^2 / (2 R), f = 1 + d / (g sqrt(R + rpc^2 / 12)) */
    pf->r_gate = cfg->est.r_var_rad2 + cfg->est.rad_per_count * cfg->est.rad_per_count * (1.0f / 12.0f);
    const float f2 = br_est_gate_f2(&cfg->est, pf->r_gate);
    pf->outlier_l = -0.5f * cfg->est.outlier_sigma * cfg->est.outlier_sigma *
                    (1.0f + cfg->est.rad_per_count * cfg->est.rad_per_count * (1.0f / 12.0f) / cfg->est.r_var_rad2) * f2;
    /* eq. G2: cfg.adapt's NIS cap, the NIS of a step at the gate, (g + d / sqrt(R + rpc^2 / 12))^2 */
    pf->gate_nis = cfg->est.outlier_sigma * cfg->est.outlier_sigma * f2;
    /* a gate beyond the float range (a tiny outlier_sigma with a transient term: f^2 = inf);
     * gate_nis, at most twice |outlier_l|, is finite with it */
    if (!isfinite(pf->outlier_l)) {
        return BR_E_PARAM;
    }
    pf->nis_avg = 0.0f;
    pf->q_scale_std = 1.0f;
    if (cfg->proposal != BR_PF_PROPOSAL_PRIOR && proposal_init(pf) != BR_OK) {
        return BR_E_PARAM;
    }
    /* cfg.load: the shared external force (off: all 0) */
    if (br_pf_load_init(pf) != BR_OK) {
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

/* the particles carry Maxwell-slip elements (est.model.mslip.n >= 1) */
static int has_elements(const br_pf_t *pf) { return pf->model.cfg.mslip.n > 0; }

/* Particle j's elements moved by the travel dx_m and clamped at its g_p
 * (eq. MS1); its force sum_i k_i e_ji (eq. MS2) kept in kgp and returned */
static float elements_move(br_pf_t *pf, uint32_t j, float dx_m)
{
    const br_model_km_t km = br_model_km(&pf->model);
    const uint32_t m = pf->cfg.n_particles;
    float e[BR_MSLIP_MAX];
    for (int i = 0; i < km.n; i++) {
        e[i] = pf->ms[(uint32_t)i * m + j];
    }
    const float f = br_pf_ms_noise(&km, e, dx_m, pf->x[BR_X_GP][j]);
    for (int i = 0; i < km.n; i++) {
        pf->ms[(uint32_t)i * m + j] = e[i];
    }
    pf->kgp[j] = f;
    return f;
}

/* Estimate of the freshly drawn set: the mean of f_nl (eq. 6; with elements
 * sum_i k_i e_ji, eq. MS2) (its weights all alike: pf->weighed as init left it) */
static void estimate_current(br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    float sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        float xj[BR_NX];
        particle_get(pf, j, xj);
        /* thesis estimate: the mean of f_nl (eq. 6) over the particles */
        sf += has_elements(pf) ? pf->kgp[j] : br_model_fcomp_N(&pf->model, xj, origin_pos_m(pf));
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
        if (has_elements(pf)) {
            /* the elements drawn relaxed but for z's draw, their common deflection
             * (clamped at the particle's g_p, eq. MS1); z itself stays 0 */
            for (int i = 0; i < pf->model.cfg.mslip.n; i++) {
                pf->ms[(uint32_t)i * m + j] = 0.0f;
            }
            (void)elements_move(pf, j, pf->x[BR_X_Z][j]);
            pf->x[BR_X_Z][j] = 0.0f;
        }
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

/* The constants of one prediction pass (steps 1 and 2), for every particle:
 * the thesis model's (the kernels'), and what the per-particle step adds */
typedef struct {
    br_pf_kc_t k;     /* the thesis model's pass: kernel constants, noise, g_p range, 1/(2R), origin, y */
    br_model_kx_t mx; /* the extended model's (theta relative to the origin at its p0) */
    float u;          /* torque over the period, N m */
    int prop;         /* cfg.proposal on a measured step: theta and omega drawn given y */
    float hold;       /* the prior's coupling of omega's sample into theta (OPT_HELD), else 0 */
} pred_t;

/* g_p limited to [lo, hi] by selects: br_clampf's result for every input,
 * 0 < lo < hi finite (br_est.c); a NaN gives lo, as fmaxf */
static inline float clamp_sel(float v, float lo, float hi)
{
    const float a = (v > lo) ? v : lo;
    return (a < hi) ? a : hi;
}

/* cfg.gp_curve: the model's Stribeck level at motor speed w, g(L w) = Fc +
 * (Fs - Fc) e^(-|L w| / vs) (eq. 5) */
static float gp_curve_N(const br_pf_t *pf, float w)
{
    const br_lugre_cfg_t *lg = &pf->model.cfg.lugre;
    return lg->Fc_N + (lg->Fs_N - lg->Fc_N) * br_exp_neg(-fabsf(pf->model.cfg.lead_mprad * w) / lg->vs_mps);
}

/* cfg.gp_curve: g_p moved from speed w0 to w1, its offset from the curve
 * times k (rho over a step, 1 for a re-anchoring's shift) */
static float gp_along_curve(const br_pf_t *pf, float gp, float w0, float w1, float k)
{
    return gp_curve_N(pf, w1) + k * (gp - gp_curve_N(pf, w0));
}

/* A valid particle's log-weight l and innovation e = theta_j - y added to
 * the pass's sums (br_pf_lsum_t: the largest l, the count of valid particles,
 * cfg.adapt's sums of d_j = e and d_j^2 in particle order) */
static inline void lsum_add(br_pf_lsum_t *s, float l, float e)
{
    s->lmax = (l > s->lmax) ? l : s->lmax; /* fmaxf for l not NaN */
    s->n_valid++;
    s->s1 += e;
    s->s2 += e * e;
}

/* an invalid particle (kept at theta_j): d_j = (theta_j - y) 0, as
 * adapt_sums adds it (it changes the sums only when theta_j - y is not finite) */
static inline void lsum_skip(br_pf_lsum_t *s, float th, float y_rel)
{
    const float d = (th - y_rel) * 0.0f;
    s->s1 += d;
    s->s2 += d * d;
}

/* Steps 1 and 2 for particle j, one at a time: the scalar reference path,
 * and the fix-up of the kernel's rare cases (the bounded scheme, an
 * invalid prediction). n: its BR_NX standard-normal samples. The particle is
 * overwritten by its prediction when that is valid and added to *ls
 * (lsum_add); otherwise it keeps its state, f_nl = 0, l = NaN (lsum_skip).
 * kind: the model's kernel, MODEL_THESIS, MODEL_EXT or MODEL_MS (a constant
 * at each call site). */
#define MODEL_THESIS 0
#define MODEL_EXT 1
#define MODEL_MS 2
static void particle_one(br_pf_t *pf, const pred_t *c, const int kind, uint32_t j, const float n[BR_NX],
                         br_pf_lsum_t *ls)
{
    const int ext = kind == MODEL_EXT, ms = kind == MODEL_MS;
    const uint32_t m = pf->cfg.n_particles;
    float x[BR_NX], xn[BR_NX];
    float e1[BR_MSLIP_MAX];
    particle_get(pf, j, x);
    /* 1. predict: eq. 6 by RK4 (the PF's form with k_p, or the extended
     * model's), or the bounded scheme beyond the a h limit; the particles are
     * finite with g_p >= gp_min > 0. With elements the trapezoidal step with
     * the clamps (eqs. MS1, MS2; the particle's force f0 in kgp) */
    if (ms) {
        float el[BR_MSLIP_MAX];
        for (int i = 0; i < c->k.km.n; i++) {
            el[i] = pf->ms[(uint32_t)i * m + j];
        }
        memcpy(xn, x, sizeof xn);
        br_pf_ms_det(&c->k.km, c->k.uh, &xn[BR_X_THETA], &xn[BR_X_OMEGA], x[BR_X_GP], pf->kgp[j], el, e1);
    } else {
        /* n_sub sub-steps, each by RK4 or the bounded scheme (docs/modules/model.md, "Sub-steps") */
        br_model_sub_steps(&pf->model, ext ? &c->mx : NULL, ext ? NULL : &c->k.kp, pf->kgp[j], x, c->u, xn);
    }
    float th_old, th, om, l_prop = 0.0f, th_a;
    if (c->prop) {
        /* cfg.proposal, a measured step: (theta, omega) drawn from their Gaussian
         * given y around the noise-free prediction mu (proposal_init); the
         * weight is the predictive likelihood of y, -e^2 / (2 S), e = mu - y */
        const float mu = xn[BR_X_THETA] - c->k.shift;
        const float e = mu - c->k.y_rel;
        th = (mu - pf->prop_k_th * e) + pf->prop_l00 * n[0];
        th_old = th + c->k.shift;
        om = ((xn[BR_X_OMEGA] - pf->prop_k_om * e) + pf->prop_l10 * n[0]) + pf->prop_l11 * n[1];
        l_prop = -(e * e) * pf->prop_inv_2s;
        /* the prior's draw of theta with the same samples: cfg.adapt's
         * innovation of the predicted cloud is the prior's */
        th_a = ((mu + c->k.q[0] * n[0]) + c->hold * n[1]);
    } else if (c->hold != 0.0f) {
        /* OPT_HELD without a measurement: the prior, omega's sample moving theta by h/2 of it */
        th_old = (xn[BR_X_THETA] + c->k.q[0] * n[0]) + c->hold * n[1];
        th = th_old - c->k.shift;
        om = xn[BR_X_OMEGA] + c->k.q[1] * n[1];
        th_a = th;
    } else {
        /* process noise sqrt(Q) n */
        th_old = xn[BR_X_THETA] + c->k.q[0] * n[0]; /* relative to the last origin */
        th = th_old - c->k.shift;
        om = xn[BR_X_OMEGA] + c->k.q[1] * n[1];
        th_a = th;
    }
    /* z's noise (with elements z stays 0: its sample moves the elements, below) */
    const float z = ms ? xn[BR_X_Z] : xn[BR_X_Z] + c->k.q[2] * n[2];
    /* g_p's random walk (g_p' = 0), or with cfg.gp_curve on its offset from the Stribeck curve */
    const float gp0 = pf->cfg.gp_curve.on ? gp_along_curve(pf, xn[BR_X_GP], x[BR_X_OMEGA], om, pf->cfg.gp_curve.rho) : xn[BR_X_GP];
    const float gp = clamp_sel(gp0 + c->k.q[3] * n[3], c->k.gp_min, c->k.gp_max);
    /* the particle's one division, k_p = sigma0 L / g_p for eq. 4 here and in the next step
     * (with elements, the element force instead: below) */
    float kg = ms ? 0.0f : c->k.s0L / gp;
    /* the force to compensate of the predicted particle: eq. 6's f_nl, or
     * the extended model's (at its position relative to the last origin), or
     * with elements z's sample on every element, clamped at the new g_p,
     * f_nl = sum k_i e_i (eqs. MS1, MS2) */
    float fnl;
    if (ms) {
        fnl = br_pf_ms_noise(&c->k.km, e1, c->k.q[2] * n[2], gp);
        kg = fnl;
    } else if (ext) {
        const float xe[BR_NX] = {th_old, om, z, gp};
        fnl = br_model_kx_fcomp_N(&c->mx, xe);
    } else {
        fnl = br_pf_fnl_kp(&c->k.mk, om, z, kg);
    }
    /* Validity: x - x is 0 for finite x and NaN otherwise. g_p is finite after
     * the clamp; a non-finite omega or z makes f_nl non-finite (inf - inf,
     * 0 * inf or inf in eqs. 3-4), so theta and f_nl tell all four states.
     * With elements f_nl does not depend on omega: omega is tested too. */
    const float v_om = ms ? (om - om) : 0.0f;
    if ((th - th) + v_om + (fnl - fnl) == 0.0f) {
        pf->x[BR_X_THETA][j] = th;
        pf->x[BR_X_OMEGA][j] = om;
        pf->x[BR_X_Z][j] = z;
        pf->x[BR_X_GP][j] = gp;
        pf->kgp[j] = kg;
        if (ms) {
            for (int i = 0; i < c->k.km.n; i++) {
                pf->ms[(uint32_t)i * m + j] = e1[i];
            }
        }
        pf->fnl[j] = fnl;
        /* 2. Gaussian log-likelihood of the measurement, -(theta_j - y)^2 / (2 R);
         * may be -inf for a particle far from y: still valid (NaN marks invalid) */
        const float e = th - c->k.y_rel;
        const float l = c->prop ? l_prop : br_pf_loglik(e, c->k.inv_2r);
        pf->l[j] = l;
        /* cfg.adapt's sums take the prior's innovation (e itself without cfg.proposal) */
        lsum_add(ls, l, c->prop ? th_a - c->k.y_rel : e);
        return;
    }
    /* unusable: the particle keeps its state and gets weight 0; its log-weight
     * is NaN, which no valid particle's can be */
    pf->fnl[j] = 0.0f;
    pf->l[j] = NAN;
    lsum_skip(ls, x[BR_X_THETA], c->k.y_rel);
}

/* the BR_NX samples of particle j, read round the end of the table */
static void noise_wrapped(const br_pf_t *pf, uint32_t j, float n[BR_NX])
{
    for (uint32_t i = 0; i < BR_NX; i++) {
        n[i] = noise_at(pf, j, i);
    }
}

/* cfg.adapt's sums over particles k0 .. k1 - 1 in their order, from the
 * predicted set (the fix-up's runs): d = (theta_k - y) v with v = 1 for a
 * valid particle (l not NaN) and 0 for one kept at its state: the same
 * additions of the same values as lsum_add and lsum_skip (e 1 = e). */
static void adapt_sums(const br_pf_t *pf, float y_rel, uint32_t k0, uint32_t k1, br_pf_lsum_t *ls)
{
    const float *const th = pf->x[BR_X_THETA], *const l = pf->l;
    float s1 = ls->s1, s2 = ls->s2;
    for (uint32_t k = k0; k < k1; k++) {
        const float v = br_pf_valid_weight(l[k]);
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
    c.k.mk = br_model_k(&pf->model);
    c.k.kp = br_model_kp(&pf->model, u_prev_Nm);
    c.k.n_sub = pf->model.n_sub;
    c.k.s0L = pf->model.cfg.lugre.sigma0_Npm * pf->model.cfg.lead_mprad;
    /* the extended kernel's constants (a few operations per step; unused by the thesis model) */
    c.mx = br_model_kx(&pf->model, origin_pos_m(pf));
    /* with elements: the clamp model's constants and u h (eqs. MS1, MS2, 6) */
    c.k.km = br_model_km(&pf->model);
    c.k.uh = u_prev_Nm * c.k.km.h;
    for (int i = 0; i < BR_NX; i++) {
        c.k.q[i] = pf->q_std[i];
    }
    /* cfg.adapt: omega's, z's and g_p's noise scaled (by exactly 1 while the smoothed NIS stays
     * below its reference); omega's only for the bootstrap draw: cfg.proposal draws omega from
     * its own constants (proposal_init), with which its held theta term stays consistent */
    if (pf->cfg.proposal == BR_PF_PROPOSAL_PRIOR) {
        c.k.q[BR_X_OMEGA] *= pf->q_scale_std;
    }
    c.k.q[BR_X_Z] *= pf->q_scale_std;
    c.k.q[BR_X_GP] *= pf->q_scale_std;
    c.k.gp_min = pf->cfg.est.gp_min_N;
    c.k.gp_max = pf->cfg.est.gp_max_N;
    c.k.inv_2r = pf->inv_2r;
    c.u = u_prev_Nm;
    c.k.shift = shift;
    c.k.y_rel = y_rel;
    c.prop = measured && pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR;
    c.hold = (pf->cfg.proposal == BR_PF_PROPOSAL_OPT_HELD) ? pf->prop_hold : 0.0f;
    const uint32_t m = pf->cfg.n_particles, mask = pf->cfg.noise_len - 1u;
    br_pf_lsum_t ls = {-INFINITY, 0u, 0.0f, 0.0f};
    float n[BR_NX];
    const int ms = has_elements(pf);
    if (pf->model.extended || pf->cfg.scalar_path || pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR ||
        pf->cfg.gp_curve.on) {
        /* one particle at a time (the extended model always: its kernel branches;
         * cfg.proposal always: the kernels draw from the prior; cfg.gp_curve:
         * the kernels' g_p is the thesis's random walk) */
        for (uint32_t j = 0; j < m; j++) {
            noise_wrapped(pf, j, n);
            if (pf->model.extended) {
                particle_one(pf, &c, MODEL_EXT, j, n, &ls);
            } else if (ms) {
                particle_one(pf, &c, MODEL_MS, j, n, &ls);
            } else {
                particle_one(pf, &c, MODEL_THESIS, j, n, &ls);
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
                if (ms) {
                    particle_one(pf, &c, MODEL_MS, j, n, &ls);
                } else {
                    particle_one(pf, &c, MODEL_THESIS, j, n, &ls);
                }
                j++;
                continue;
            }
            const uint32_t j1 = (m - j < room) ? m : j + room;
            const float *const nz = pf->cfg.noise + p;
            const float s1 = ls.s1, s2 = ls.s2;
            const uint32_t left = ms ? br_pf_kernel_predict_ms(pf, &c.k, j, j1, nz, &ls)
                                     : br_pf_predict_run(pf, &c.k, j, j1, nz, &ls);
            if (left > 0u) {
                /* the fix-up: the particles the kernel left (l = NaN), one at a time */
                for (uint32_t k = j; k < j1; k++) {
                    if (pf->l[k] != pf->l[k]) {
                        if (ms) {
                            particle_one(pf, &c, MODEL_MS, k, nz + BR_NX * (k - j), &ls);
                        } else {
                            particle_one(pf, &c, MODEL_THESIS, k, nz + BR_NX * (k - j), &ls);
                        }
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

/* w_j of the last step's weighing (every kernel's: the same value, br_math.h),
 * from the log-weight it left */
static float step_weight(const br_pf_t *pf, uint32_t j)
{
    const float l = pf->l[j];
    return (pf->weighed == BR_PF_WEIGHED_VALID) ? br_pf_valid_weight(l) : br_exp_neg(l - pf->lmax);
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
 * sums s1, s2 predict_and_weigh makes), limited to the gate's, gate_nis (eq. G2; also
 * for a NaN or an overflow); then E and the factor on omega's, z's and g_p's
 * noise std for the next predictions. */
static void adapt_update(br_pf_t *pf, float s1, float s2, uint32_t n_valid)
{
    const float n = (float)n_valid; /* exact: n_valid <= BR_PF_MAX_PARTICLES */
    /* n >= 1: called with at least one valid particle */
    const float mean = s1 / n;
    const float var = s2 / n - mean * mean;
    float nis = (mean * mean) / (((var > 0.0f) ? var : 0.0f) + pf->r_gate);
    nis = (nis <= pf->gate_nis) ? nis : pf->gate_nis; /* a NaN too */
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
    br_pf_load_tick(pf);
    /* with cfg.load the particles are predicted with u - L F_d */
    const uint32_t n_valid = predict_and_weigh(pf, br_pf_load_torque(pf, u_a), shift, y_rel, 1, &lmax, sums);
    noise_advance(pf);
    if (n_valid == 0u) {
        pf->weighed = BR_PF_WEIGHED_NONE;
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* cfg.load: F_d's update on the cloud's innovation, the cloud moved by its change */
    lmax = br_pf_load_update(pf, y_rel, lmax, sums, n_valid);
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
    /* the kernel's (the reference's on the scalar reference path) */
    const int outlier = verdict == BR_W_OUTLIER;
    float sf = pf->cfg.scalar_path ? br_pf_kref_resample(pf, lmax, outlier) : br_pf_kernel_resample(pf, lmax, outlier);
    const float inv_m = 1.0f / (float)m;
    pf->n_outliers = (verdict == BR_W_OUTLIER) ? pf->n_outliers + 1u : 0u;
    if (pf->n_outliers >= pf->cfg.est.reanchor_after) {
        /* lost lock: re-anchor the cloud on the measurement, keeping its spread:
         * theta's mean moves to y, omega's mean to the measured velocity */
        const float periods = (float)pf->n_predicted + 1.0f;
        const float omega_meas = (shift + (y->frac - pf->prev_frac) * rpc) / (periods * pf->cfg.est.model.dt_s);
        const float d_th = y_rel - sum_state(pf, BR_X_THETA) * inv_m;
        const float d_om = omega_meas - sum_state(pf, BR_X_OMEGA) * inv_m;
        /* cfg.load: a re-acquisition of this step is not undone on a re-anchored cloud */
        pf->load_alt = 0;
        sf = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            pf->x[BR_X_THETA][j] += d_th;
            if (pf->cfg.gp_curve.on) {
                /* g_p moves along the curve with the velocity (its offset kept) */
                const float w0 = pf->x[BR_X_OMEGA][j];
                pf->x[BR_X_GP][j] = br_clampf(gp_along_curve(pf, pf->x[BR_X_GP][j], w0, w0 + d_om, 1.0f),
                                              pf->cfg.est.gp_min_N, pf->cfg.est.gp_max_N);
                pf->kgp[j] = br_model_kp_of(&pf->model, pf->x[BR_X_GP][j]);
            }
            pf->x[BR_X_OMEGA][j] += d_om;
            if (has_elements(pf)) {
                /* the elements moved by the position's jump L d_theta (eq. MS1) */
                sf += elements_move(pf, j, pf->model.cfg.lead_mprad * d_th);
                continue;
            }
            /* f_nl depends on omega: the estimate is that of the moved cloud */
            float xj[BR_NX];
            particle_get(pf, j, xj);
            sf += br_model_fcomp_N(&pf->model, xj, (float)y->counts * pf->m_per_count);
        }
    }
    pf->origin_counts = y->counts;
    pf->prev_frac = y->frac;
    pf->n_predicted = 0u;
    /* the compensation: the mean f_nl, with cfg.load plus F_d */
    pf->est.F_hat_N = br_pf_load_comp_N(pf, sf * inv_m);
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
    br_pf_load_tick(pf);
    const uint32_t n_valid = predict_and_weigh(pf, br_pf_load_torque(pf, br_est_delay_apply(&pf->delay, u_prev_Nm)),
                                               0.0f, 0.0f, 0, &lmax, sums);
    noise_advance(pf);
    if (n_valid == 0u) {
        pf->weighed = BR_PF_WEIGHED_NONE;
        return BR_E_NUMERIC; /* nothing usable: the previous set is kept */
    }
    /* every particle moves on unweighted (an invalid one kept its state) */
    for (uint32_t j = 0; j < m; j++) {
        pf->idx[j] = (uint16_t)j;
    }
    pf->est.F_hat_N = br_pf_load_comp_N(pf, sum_set(pf) * (1.0f / (float)m));
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
                                     pf->load_N, pf->est.F_hat_N);
        }
    }
    return st;
}

br_status_t br_pf_est_predict(void *ctx, float u_prev_Nm, float *F_hat_N)
{
    br_pf_t *pf = ctx;
    if (F_hat_N == NULL) {
        return BR_E_NULL;
    }
    const br_status_t st = br_pf_predict(pf, u_prev_Nm);
    if (!BR_FAILED(st)) {
        *F_hat_N = pf->est.F_hat_N;
    }
    return st;
}

br_status_t br_pf_est_reset(void *ctx)
{
    br_pf_t *pf = ctx;
    if (pf == NULL) {
        return BR_E_NULL;
    }
    const br_pf_cfg_t c = pf->cfg; /* init reads the configuration it overwrites */
    return br_pf_init(pf, &c);
}

br_est_t br_pf_est(br_pf_t *pf)
{
    const br_est_t e = {pf, br_pf_est_step, br_pf_est_predict, br_pf_est_reset};
    return e;
}
