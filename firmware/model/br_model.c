/* SPDX-License-Identifier: Apache-2.0 */
/* Four-state estimation model (thesis eq. 6) and its discretisation, float32.
 * See br_model.h and docs/modules/model.md. */
#include "bristle/br_model.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"
#include "bristle_gen/model/br_causes.h"
#include "br_lugre_kernel.h"
#include "br_model_kernel.h"

/* Fixed-point passes of the bounded scheme (contraction factor ~1e-2 per pass
 * at the reference machine's parameters, docs/modules/model.md). */
#define BR_MODEL_BOUNDED_PASSES 3

/* The sub-steps of one step of dt (docs/modules/model.md, "Sub-steps").
 * In presliding (a h small, dz/dt = v) eq. 6 on the load side is the
 * spring-damper  Meff v' = -(sigma1 + sigma2) v - sigma0 z,  Meff = Jeff / L^2,
 * whose eigenvalues solve s^2 + b s + wn^2 = 0 with wn^2 = sigma0 / Meff and
 * b = (sigma1 + sigma2) / Meff; their largest modulus is
 *   rho = wn                                 for b <= 2 wn (complex pair)
 *   rho = (b + sqrt(b^2 - 4 wn^2)) / 2       for b > 2 wn  (the fast real one)  (eq. S1)
 *   n   = max(1, ceil(rho dt / BR_MODEL_SUB_RH_MAX))                          (eq. S2)
 * With elements the model keeps one step (n = 1, rho h reported as 0). */
static br_status_t sub_steps(const br_model_cfg_t *cfg, float *rho_h, int *n)
{
    *rho_h = 0.0f;
    *n = 1;
    if (cfg->mslip.n > 0) {
        return BR_OK;
    }
    const float L2 = cfg->lead_mprad * cfg->lead_mprad;
    /* a lead whose square rounds to 0, or an inertia at the load that rounds to 0 or
     * beyond float range: no step to choose */
    if (!br_finite_pos(L2)) {
        return BR_E_PARAM;
    }
    const float meff = (cfg->J_kgm2 + L2 * cfg->M_kg) / L2;
    if (!br_finite_pos(meff)) {
        return BR_E_PARAM;
    }
    const float wn2 = cfg->lugre.sigma0_Npm / meff, b = (cfg->lugre.sigma1_Nspm + cfg->sigma2_Nspm) / meff;
    const float wn = sqrtf(wn2);
    /* eq. S1 */
    const float rho = (b <= 2.0f * wn) ? wn : 0.5f * (b + sqrtf(b * b - 4.0f * wn2));
    /* eq. S2; beyond BR_MODEL_SUB_MAX (or not finite) the configuration is refused */
    const float r = ceilf(rho * cfg->dt_s / BR_MODEL_SUB_RH_MAX);
    if (!(r <= (float)BR_MODEL_SUB_MAX)) {
        return BR_E_PARAM;
    }
    *rho_h = rho * cfg->dt_s;
    *n = (r >= 1.0f) ? (int)r : 1;
    return BR_OK;
}

/* 1 when a force term of the extended model is on: a field of a force cause
 * that switches it on (the registry's table, bristle_gen/model/br_causes.h) is not 0 */
static int force_terms_on(const br_causes_t *c)
{
#define BR_CAUSE_ON(field, cause, hook, on) || ((hook) == BR_CAUSE_FORCE && (on) && c->field != 0.0f)
    return 0 BR_CAUSE_FIELDS(BR_CAUSE_ON);
#undef BR_CAUSE_ON
}

br_status_t br_model_init(br_model_t *m, const br_model_cfg_t *cfg)
{
    if (m == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    m->ready = 0;
    if (!br_finite_pos(cfg->J_kgm2) || !br_finite_pos(cfg->lead_mprad) || !br_finite_pos(cfg->dt_s)) {
        return BR_E_PARAM;
    }
    if (!br_finite_nonneg(cfg->M_kg) || !br_finite_nonneg(cfg->sigma2_Nspm)) {
        return BR_E_PARAM;
    }
    br_status_t st = br_lugre_cfg_check(&cfg->lugre);
    if (st != BR_OK) {
        return st;
    }
    const br_causes_t *c = &cfg->causes;
    if (!isfinite(c->offset_N) || !isfinite(c->dFc_neg_N) || !isfinite(c->dsigma2_neg_Nspm) ||
        !isfinite(c->ripple_amp_N) || !isfinite(c->ripple_phase_rad) || !isfinite(c->grad_per_m) ||
        !br_finite_nonneg(c->delay_s) || !isfinite(c->drift_per_s)) {
        return BR_E_PARAM;
    }
    /* the level in -x stays positive, the viscous friction in -x not negative,
     * and a ripple has a period */
    if (!(cfg->lugre.Fc_N + c->dFc_neg_N > 0.0f) || !(cfg->sigma2_Nspm + c->dsigma2_neg_Nspm >= 0.0f) ||
        (c->ripple_amp_N != 0.0f && !br_finite_pos(c->ripple_period_m))) {
        return BR_E_PARAM;
    }
    /* the Maxwell-slip friction: a valid element set, its viscous term the model's
     * sigma2 (one home), and no cause beyond the delay (not combined yet) */
    st = br_mslip_cfg_check(&cfg->mslip);
    if (st != BR_OK) {
        return st;
    }
    const int force_on = force_terms_on(c);
    if (cfg->mslip.n > 0 && (cfg->mslip.sigma2_Nspm != 0.0f || force_on)) {
        return BR_E_PARAM;
    }
    st = sub_steps(cfg, &m->rho_h, &m->n_sub);
    if (st != BR_OK) {
        return st;
    }
    m->cfg = *cfg;
    m->h_sub_s = cfg->dt_s / (float)m->n_sub;
    float L = cfg->lead_mprad;
    int i;
    for (i = 0; i < BR_MSLIP_MAX; i++) {
        /* Delta_i = c_i g_p, c_i = share_i / k_i */
        m->ms_c_mpN[i] = (i < cfg->mslip.n) ? cfg->mslip.share[i] / cfg->mslip.k_Npm[i] : 0.0f;
    }
    /* eq. 1: effective inertia on the motor side, J + L^2 M */
    m->inv_Jeff = 1.0f / (cfg->J_kgm2 + L * L * cfg->M_kg);
    m->visc_Nmsprad = L * L * cfg->sigma2_Nspm;
    m->extended = force_on;
    m->c_neg = br_ct_asym_c_neg(cfg->lugre.Fc_N, c->dFc_neg_N);
    m->sigma2_neg_Nspm = cfg->sigma2_Nspm + c->dsigma2_neg_Nspm;
    m->ripple_k_radpm = br_ct_ripple_k_radpm(c->ripple_amp_N, c->ripple_period_m);
    br_model_set_clock(m, 0u);
    m->ready = 1;
    return BR_OK;
}

void br_model_set_clock(br_model_t *m, uint32_t n_steps)
{
    m->n_steps = n_steps;
    /* friction_drift: s(t) = max(0, 1 + drift t), t = n dt (the count is exact in
     * float up to 2^24 steps, to 6e-8 of t beyond) */
    const float t = (float)n_steps * m->cfg.dt_s;
    m->drift_k = (m->cfg.causes.drift_per_s != 0.0f) ? br_ct_lin_scale(m->cfg.causes.drift_per_s, t) : 1.0f;
}

void br_model_tick(br_model_t *m)
{
    br_model_set_clock(m, (m->n_steps < UINT32_MAX) ? m->n_steps + 1u : m->n_steps);
}

float br_model_fnl_N(const br_model_t *m, const float x[BR_NX])
{
    const br_model_k_t k = br_model_k(m);
    /* eq. 3 with dz/dt from eq. 4, g = g_p (c g_p moving towards -x) */
    const float gp = br_ct_asym_level_N(x[BR_X_GP], m->c_neg, x[BR_X_OMEGA] < 0.0f);
    return br_model_k_fnl(&k, x[BR_X_Z], br_model_k_zdot(&k, x[BR_X_OMEGA], x[BR_X_Z], gp));
}

float br_model_fcomp_N(const br_model_t *m, const float x[BR_NX], float p0_m)
{
    if (!m->extended) {
        return br_model_fnl_N(m, x);
    }
    const br_model_kx_t k = br_model_kx(m, p0_m);
    return br_model_kx_fcomp_N(&k, x);
}

void br_model_deriv(const br_model_t *m, const float x[BR_NX], float u_Nm, float dx[BR_NX])
{
    dx[BR_X_THETA] = x[BR_X_OMEGA];
    dx[BR_X_GP] = 0.0f;
    if (m->extended) {
        /* the load force at the absolute position L theta (the expansion at its origin) */
        const br_model_kx_t k = br_model_kx(m, m->cfg.lead_mprad * x[BR_X_THETA]);
        const float F = br_model_kx_load_N(&k, 0.0f, x[BR_X_OMEGA], x[BR_X_Z], x[BR_X_GP], &dx[BR_X_Z]);
        dx[BR_X_OMEGA] = (u_Nm - k.n.L * F) * k.n.inv_Jeff;
        return;
    }
    const br_model_k_t k = br_model_k(m);
    const float zdot = br_model_k_zdot(&k, x[BR_X_OMEGA], x[BR_X_Z], x[BR_X_GP]);
    /* eq. 6: omega' = (u - L (sigma2 L omega + f_nl)) / Jeff; z' = eq. 4 */
    dx[BR_X_OMEGA] = br_model_k_omega_dot(&k, x[BR_X_OMEGA], br_model_k_fnl(&k, x[BR_X_Z], zdot), u_Nm);
    dx[BR_X_Z] = zdot;
}

/* Bounded scheme: z exact over the displacement (eq. 4 with g_p held), friction
 * impulse in closed form, trapezoidal rigid body solved by fixed-point passes. */
void br_model_bounded_step(const br_model_t *m, const float x[BR_NX], float u, float out[BR_NX])
{
    const br_lugre_cfg_t *c = &m->cfg.lugre;
    float h = m->h_sub_s;
    float L = m->cfg.lead_mprad;
    float w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    float wm = w0, dth = 0.0f, z1 = z0, w1 = w0;
    int pass;
    for (pass = 0; pass < BR_MODEL_BOUNDED_PASSES; pass++) {
        dth = wm * h;
        /* eq. 4 over the displacement with g = g_p: exact, bounded; and the integral of z */
        const br_lk_step_t ls = br_lk_move_over(c->sigma0_Npm, z0, L * dth, gp, h);
        const float zint = ls.zint_ms;
        z1 = ls.z1_m;
        /* eq. 6 integrated: Jeff dw = u h - L^2 sigma2 dtheta - L (sigma0 int z + sigma1 dz) */
        w1 = w0 + (u * h - m->visc_Nmsprad * dth - L * (c->sigma0_Npm * zint + c->sigma1_Nspm * (z1 - z0))) * m->inv_Jeff;
        wm = 0.5f * (w0 + w1);
    }
    out[BR_X_THETA] = x[BR_X_THETA] + dth;
    out[BR_X_OMEGA] = w1;
    out[BR_X_Z] = z1;
    out[BR_X_GP] = gp;
}

/* The bounded scheme of the extended model: as above with the level c g_p
 * and sigma2_d by the direction of the move, the friction impulse scaled by
 * k(p) s(t) and the offset and ripple impulses added, k and the ripple taken at
 * the middle of the move. */
void br_model_bounded_step_x(const br_model_kx_t *k, const float x[BR_NX], float u, float out[BR_NX])
{
    const float h = k->n.h, L = k->n.L, s0 = k->n.s0;
    const float t0 = x[BR_X_THETA], w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    float wm = w0, dth = 0.0f, z1 = z0, w1 = w0;
    int pass;
    for (pass = 0; pass < BR_MODEL_BOUNDED_PASSES; pass++) {
        dth = wm * h;
        const float dx = L * dth;
        const int neg = dx < 0.0f;
        /* eq. 4 over the displacement with the direction's level, exact and bounded */
        const br_lk_step_t ls = br_lk_move_over(s0, z0, dx, br_ct_asym_level_N(gp, k->c_neg, neg), h);
        const float zint = ls.zint_ms;
        z1 = ls.z1_m;
        const float tm = t0 + 0.5f * dth;
        const float kp = br_ct_lin_scale(k->grad, k->p0 + L * tm) * k->ks;
        /* the load impulse: k (sigma2_d dx + sigma0 int z + sigma1 dz) + (offset + ripple) h */
        const float imp = kp * (br_ct_asym_sigma2_Nspm(k->s2, k->s2_neg, neg) * dx + s0 * zint + k->n.s1 * (z1 - z0)) +
                          (k->off + br_model_kx_ripple_N(k, tm)) * h;
        w1 = w0 + (u * h - L * imp) * k->n.inv_Jeff;
        wm = 0.5f * (w0 + w1);
    }
    out[BR_X_THETA] = t0 + dth;
    out[BR_X_OMEGA] = w1;
    out[BR_X_Z] = z1;
    out[BR_X_GP] = gp;
}

void br_model_sub_steps(const br_model_t *m, const br_model_kx_t *kx, const br_model_kp_t *kp, float kp_p,
                        const float x[BR_NX], float u_Nm, float out[BR_NX])
{
    const br_model_k_t k = br_model_k(m);
    float xs[BR_NX] = {x[0], x[1], x[2], x[3]};
    int s, i;
    for (s = 0; s < m->n_sub; s++) {
        /* RK4 only where the sub-step's ends (and, but for the PF's, its
         * stages) are inside its stability region */
        if (kx != NULL) {
            if (!br_model_kx_rk4(kx, xs, u_Nm, out)) {
                br_model_bounded_step_x(kx, xs, u_Nm, out);
            }
        } else if (kp != NULL) {
            if (!br_model_kp_rk4(kp, xs, kp_p, out)) {
                br_model_bounded_step(m, xs, u_Nm, out);
            }
        } else if (!br_model_k_rk4(&k, xs, u_Nm, out)) {
            br_model_bounded_step(m, xs, u_Nm, out);
        }
        for (i = 0; i < BR_NX; i++) {
            xs[i] = out[i];
        }
    }
}

static int all_finite(const float x[BR_NX])
{
    return isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(x[3]);
}

static void copy_state(const float src[BR_NX], float dst[BR_NX])
{
    int i;
    for (i = 0; i < BR_NX; i++) {
        dst[i] = src[i];
    }
}

br_status_t br_model_step_at(const br_model_t *m, const float x[BR_NX], float p0_m, float u_Nm,
                             float x_next[BR_NX])
{
    if (m == NULL || x == NULL || x_next == NULL) {
        return BR_E_NULL;
    }
    if (!m->ready) {
        return BR_E_STATE;
    }
    float tmp[BR_NX];
    if (!all_finite(x) || !isfinite(u_Nm) || !isfinite(p0_m) || !(x[BR_X_GP] > 0.0f)) {
        copy_state(x, x_next);
        return BR_E_INPUT;
    }
    if (m->extended) {
        const br_model_kx_t k = br_model_kx(m, p0_m);
        br_model_sub_steps(m, &k, NULL, 0.0f, x, u_Nm, tmp);
    } else {
        br_model_sub_steps(m, NULL, NULL, 0.0f, x, u_Nm, tmp);
    }
    if (!all_finite(tmp)) {
        copy_state(x, x_next);
        return BR_E_NUMERIC;
    }
    copy_state(tmp, x_next);
    return BR_OK;
}

br_status_t br_model_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float x_next[BR_NX])
{
    if (m == NULL || x == NULL || x_next == NULL || !m->ready || !m->extended) {
        return br_model_step_at(m, x, 0.0f, u_Nm, x_next);
    }
    /* extended: step about the state's own position (theta = 0 at p0 = L theta);
     * x may be x_next */
    const float th0 = x[BR_X_THETA];
    const float rel[BR_NX] = {0.0f, x[BR_X_OMEGA], x[BR_X_Z], x[BR_X_GP]};
    float out[BR_NX];
    const br_status_t st = br_model_step_at(m, rel, m->cfg.lead_mprad * th0, u_Nm, out);
    if (st != BR_OK) {
        copy_state(x, x_next); /* x_next = x, as for every failed step */
        return st;
    }
    out[BR_X_THETA] += th0;
    copy_state(out, x_next);
    return BR_OK;
}

float br_model_ms_fnl_N(const br_model_t *m, const float z_m[])
{
    return br_msk_force(m->cfg.mslip.n, m->cfg.mslip.k_Npm, z_m);
}

br_status_t br_model_ms_step(const br_model_t *m, const float x[BR_NX], const float z_m[], float u_Nm,
                             float x_next[BR_NX], float z_next_m[])
{
    if (m == NULL || x == NULL || z_m == NULL || x_next == NULL || z_next_m == NULL) {
        return BR_E_NULL;
    }
    if (!m->ready || m->cfg.mslip.n < 1) {
        return BR_E_STATE;
    }
    const int n = m->cfg.mslip.n;
    float xo[BR_NX], zo[BR_MSLIP_MAX];
    int ok = all_finite(x) && isfinite(u_Nm) && x[BR_X_GP] > 0.0f;
    int i;
    for (i = 0; i < n; i++) {
        ok = ok && isfinite(z_m[i]);
    }
    if (!ok) {
        copy_state(x, x_next);
        for (i = 0; i < n; i++) {
            z_next_m[i] = z_m[i];
        }
        return BR_E_INPUT;
    }
    const br_model_km_t k = br_model_km(m);
    br_model_km_step(&k, x, z_m, u_Nm, xo, zo);
    const int fin = all_finite(xo) && isfinite(br_msk_force(n, k.k, zo));
    copy_state(fin ? xo : x, x_next);
    for (i = 0; i < n; i++) {
        z_next_m[i] = fin ? zo[i] : z_m[i];
    }
    return fin ? BR_OK : BR_E_NUMERIC;
}
