/* SPDX-License-Identifier: Apache-2.0 */
/* Static friction feedforward, float32. Equations in br_ff.h and docs/modules/ff.md. */
#include "bristle/br_ff.h"

#include <math.h>
#include <stddef.h>

#include "br_cause_terms.h"
#include "br_check.h"
#include "br_mslip_kernel.h"

static int causes_ok(const br_ff_cfg_t *c)
{
    const br_causes_t *k = &c->causes;
    if (!isfinite(k->offset_N) || !isfinite(k->ripple_amp_N) || !isfinite(k->ripple_phase_rad) ||
        !isfinite(k->grad_per_m) || !isfinite(k->delay_s) || !isfinite(k->ripple_period_m)) {
        return 0;
    }
    if (!(isfinite(k->dFc_neg_N) && c->Fc_N + k->dFc_neg_N > 0.0f)) {
        return 0;
    }
    if (!(isfinite(k->dsigma2_neg_Nspm) && c->sigma2_Nspm + k->dsigma2_neg_Nspm >= 0.0f)) {
        return 0;
    }
    if (k->ripple_amp_N != 0.0f && !(k->ripple_period_m > 0.0f)) {
        return 0;
    }
    return 1;
}

br_status_t br_ff_init(br_ff_t *ff, const br_ff_cfg_t *cfg)
{
    if (ff == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    ff->ready = 0;
    if (!br_finite_pos(cfg->Fc_N) || !isfinite(cfg->Fs_N) || cfg->Fs_N < cfg->Fc_N ||
        !br_finite_pos(cfg->vs_mps) || !br_finite_nonneg(cfg->sigma2_Nspm) || !br_finite_pos(cfg->v_eps_mps) ||
        !br_finite_nonneg(cfg->mass_kg) || !br_finite_pos(cfg->comp_max_N) || !causes_ok(cfg)) {
        return BR_E_PARAM;
    }
    /* the elements: a valid set whose viscous term is the feedforward's sigma2 (0 here) */
    if (br_mslip_cfg_check(&cfg->mslip) != BR_OK || cfg->mslip.sigma2_Nspm != 0.0f) {
        return BR_E_PARAM;
    }
    /* the prediction: off, or a horizon over the elements */
    if (!(cfg->pred_ahead_s == 0.0f ||
          (cfg->pred_ahead_s > 0.0f && cfg->pred_ahead_s <= BR_FF_PRED_MAX_S && cfg->mslip.n > 0))) {
        return BR_E_PARAM;
    }
    ff->cfg = *cfg;
    ff->c_neg = br_ct_asym_c_neg(cfg->Fc_N, cfg->causes.dFc_neg_N);
    ff->ripple_k_radpm = br_ct_ripple_k_radpm(cfg->causes.ripple_amp_N, cfg->causes.ripple_period_m);
    ff->in.v_mps = 0.0f;
    ff->in.a_mps2 = 0.0f;
    ff->in.p_m = 0.0f;
    int i;
    for (i = 0; i < BR_MSLIP_MAX; i++) {
        /* Delta_i = c_i g, c_i = share_i / k_i; undeflected at the start */
        ff->ms_c_mpN[i] = (i < cfg->mslip.n) ? cfg->mslip.share[i] / cfg->mslip.k_Npm[i] : 0.0f;
        ff->ms_z_m[i] = 0.0f;
    }
    ff->ready = 1;
    return BR_OK;
}

/* eq. 5, the Stribeck level at v (scaled by c in -x: asymmetric_friction) */
static float level_N(const br_ff_t *ff, float v)
{
    const br_ff_cfg_t *c = &ff->cfg;
    const float g = c->Fc_N + (c->Fs_N - c->Fc_N) * expf(-fabsf(v) / c->vs_mps);
    return br_ct_asym_level_N(g, ff->c_neg, v < 0.0f);
}

/* the elements of the stored reference moved to in's position at the level g:
 * z1_i = clamp(z_i + (p - p_stored), -c_i g, c_i g); returns sum k_i z1_i */
static float elements_N(const br_ff_t *ff, const br_ff_in_t *in, float g, float z1[BR_MSLIP_MAX])
{
    const br_mslip_cfg_t *m = &ff->cfg.mslip;
    return br_msk_move(m->n, m->k_Npm, ff->ms_c_mpN, ff->ms_z_m, z1, in->p_m - ff->in.p_m, g);
}

static int in_ok(const br_ff_in_t *in)
{
    return isfinite(in->v_mps) && isfinite(in->a_mps2) && isfinite(in->p_m);
}

br_status_t br_ff_step(const br_ff_t *ff, const br_ff_in_t *in, float *comp_N)
{
    if (ff == NULL || in == NULL || comp_N == NULL) {
        return BR_E_NULL;
    }
    *comp_N = 0.0f;
    if (!ff->ready) {
        return BR_E_STATE;
    }
    if (!in_ok(in)) {
        return BR_E_INPUT;
    }
    const br_ff_cfg_t *c = &ff->cfg;
    const br_causes_t *k = &c->causes;
    const float v = in->v_mps;
    const int neg = v < 0.0f;
    const float g = level_N(ff, v);
    /* the steady-state LuGre force with a smoothed sign (or the elements along the
     * reference's path), plus viscous friction */
    const float s2 = br_ct_asym_sigma2_Nspm(c->sigma2_Nspm, c->sigma2_Nspm + k->dsigma2_neg_Nspm, neg);
    float z1[BR_MSLIP_MAX];
    float f = ((c->mslip.n > 0) ? elements_N(ff, in, g, z1) : tanhf(v / c->v_eps_mps) * g) + s2 * v;
    /* the causes' terms (br_cause_terms.h): position gradient k(p) (1 without) and offset */
    f = br_ct_scaled_load_N(br_ct_lin_scale(k->grad_per_m, in->p_m), f, k->offset_N);
    /* position ripple (a cogging / lead-error map) */
    if (k->ripple_amp_N != 0.0f) {
        f += br_ct_ripple_N(k->ripple_amp_N,
                            br_ct_ripple_phase_rad(ff->ripple_k_radpm, k->ripple_period_m, k->ripple_phase_rad, in->p_m));
    }
    /* inertia */
    f += c->mass_kg * in->a_mps2;
    if (!isfinite(f)) {
        return BR_E_INPUT;
    }
    *comp_N = br_clampf(f, -c->comp_max_N, c->comp_max_N);
    return BR_OK;
}

br_status_t br_ff_set_ref(br_ff_t *ff, const br_ff_in_t *in)
{
    if (ff == NULL || in == NULL) {
        return BR_E_NULL;
    }
    if (!in_ok(in)) {
        return BR_E_INPUT;
    }
    if (ff->cfg.mslip.n > 0 && ff->ready) {
        /* the elements along the reference's travel since the stored one */
        float z1[BR_MSLIP_MAX];
        (void)elements_N(ff, in, level_N(ff, in->v_mps), z1);
        int i;
        for (i = 0; i < ff->cfg.mslip.n; i++) {
            ff->ms_z_m[i] = z1[i];
        }
    }
    ff->in = *in;
    return BR_OK;
}

br_status_t br_ff_pred_N(const br_ff_t *ff, const float *z_anchor_m, const float *g_anchor_N, float *dF_N)
{
    if (ff == NULL || dF_N == NULL) {
        return BR_E_NULL;
    }
    *dF_N = 0.0f;
    if (!ff->ready) {
        return BR_E_STATE;
    }
    const float tau = ff->cfg.pred_ahead_s;
    if (tau == 0.0f) {
        return BR_OK;
    }
    const br_mslip_cfg_t *m = &ff->cfg.mslip;
    const float *z = (z_anchor_m != NULL) ? z_anchor_m : ff->ms_z_m;
    int i;
    for (i = 0; i < m->n; i++) {
        if (!isfinite(z[i])) {
            return BR_E_INPUT;
        }
    }
    /* the reference's travel over the horizon (its Taylor polynomial): dp = v tau + a tau^2 / 2 */
    const float v = ff->in.v_mps, a = ff->in.a_mps2;
    const float dp = v * tau + 0.5f * a * tau * tau;
    /* the level at the horizon's end: g1 = g(v + a tau) (eq. 5), or the anchor's */
    const float g1 = (g_anchor_N != NULL) ? *g_anchor_N : level_N(ff, v + a * tau);
    if (!br_finite_pos(g1) || !isfinite(dp)) {
        return BR_E_INPUT;
    }
    /* dF = sum_i k_i clamp(z_i + dp, -c_i g1, c_i g1) - sum_i k_i z_i */
    float z1[BR_MSLIP_MAX];
    const float d = br_msk_move(m->n, m->k_Npm, ff->ms_c_mpN, z, z1, dp, g1) - br_msk_force(m->n, m->k_Npm, z);
    if (!isfinite(d)) {
        return BR_E_NUMERIC;
    }
    *dF_N = d;
    return BR_OK;
}

br_status_t br_ff_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    const br_ff_t *ff = (const br_ff_t *)ctx;
    br_status_t st = br_ff_step(ff, ff ? &ff->in : NULL, F_hat_N);
    if (st == BR_OK && ff->cfg.pred_ahead_s > 0.0f) {
        /* with a horizon: the map plus the elements' change over it */
        float dF = 0.0f;
        st = br_ff_pred_N(ff, NULL, NULL, &dF);
        *F_hat_N = (st == BR_OK) ? br_clampf(*F_hat_N + dF, -ff->cfg.comp_max_N, ff->cfg.comp_max_N) : 0.0f;
    }
    return st;
}
