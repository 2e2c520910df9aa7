/* Four-state estimation model (thesis eq. 6) and its discretisation, float32.
 * See br_model.h and docs/modules/model.md. */
#include "bristle/br_model.h"

#include <math.h>
#include <stddef.h>

/* Fixed-point passes of the bounded scheme (contraction factor ~1e-2 per pass
 * at the reference machine's parameters, docs/modules/model.md). */
#define BR_MODEL_BOUNDED_PASSES 3

static int finite_pos(float v) { return isfinite(v) && v > 0.0f; }

br_status_t br_model_init(br_model_t *m, const br_model_cfg_t *cfg)
{
    if (m == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    m->ready = 0;
    if (!finite_pos(cfg->J_kgm2) || !finite_pos(cfg->lead_mprad) || !finite_pos(cfg->dt_s)) {
        return BR_E_PARAM;
    }
    if (!isfinite(cfg->M_kg) || cfg->M_kg < 0.0f || !isfinite(cfg->sigma2_Nspm) || cfg->sigma2_Nspm < 0.0f) {
        return BR_E_PARAM;
    }
    br_status_t st = br_lugre_cfg_check(&cfg->lugre);
    if (st != BR_OK) {
        return st;
    }
    m->cfg = *cfg;
    float L = cfg->lead_mprad;
    /* eq. 1: effective inertia on the motor side, J + L^2 M */
    m->inv_Jeff = 1.0f / (cfg->J_kgm2 + L * L * cfg->M_kg);
    m->visc_Nmsprad = L * L * cfg->sigma2_Nspm;
    m->ready = 1;
    return BR_OK;
}

/* eq. 4 with g = g_p: load-side bristle rate */
static float model_zdot(const br_model_t *m, const float x[BR_NX])
{
    const br_lugre_cfg_t *c = &m->cfg.lugre;
    float v = m->cfg.lead_mprad * x[BR_X_OMEGA];
    return br_lugre_zdot_mps(c, x[BR_X_Z], v, x[BR_X_GP]);
}

float br_model_fnl_N(const br_model_t *m, const float x[BR_NX])
{
    /* eq. 6: f_nl = sigma0 z + sigma1 dz/dt */
    return br_lugre_force_N(&m->cfg.lugre, x[BR_X_Z], model_zdot(m, x));
}

void br_model_deriv(const br_model_t *m, const float x[BR_NX], float u_Nm, float dx[BR_NX])
{
    float L = m->cfg.lead_mprad;
    float zdot = model_zdot(m, x);
    float fnl = br_lugre_force_N(&m->cfg.lugre, x[BR_X_Z], zdot);
    /* eq. 6: theta' = omega; omega' = (u - L (sigma2 L omega + f_nl)) / Jeff; z' = eq. 4; g_p' = 0 */
    dx[BR_X_THETA] = x[BR_X_OMEGA];
    dx[BR_X_OMEGA] = (u_Nm - m->visc_Nmsprad * x[BR_X_OMEGA] - L * fnl) * m->inv_Jeff;
    dx[BR_X_Z] = zdot;
    dx[BR_X_GP] = 0.0f;
}

/* a h = sigma0 L |omega| h / g_p <= BR_MODEL_RK4_AH_MAX, without a division:
 * sigma0 L |omega| h <= BR_MODEL_RK4_AH_MAX g_p (g_p > 0) */
static int rk4_stable(const br_model_t *m, float omega, float g_p)
{
    return m->cfg.lugre.sigma0_Npm * m->cfg.lead_mprad * fabsf(omega) * m->cfg.dt_s <= BR_MODEL_RK4_AH_MAX * g_p;
}

static void rk4_step(const br_model_t *m, const float x[BR_NX], float u, float out[BR_NX])
{
    float h = m->cfg.dt_s;
    float k1[BR_NX], k2[BR_NX], k3[BR_NX], k4[BR_NX], xs[BR_NX];
    int i;
    /* classic RK4 on eq. 6 */
    br_model_deriv(m, x, u, k1);
    for (i = 0; i < BR_NX; i++) {
        xs[i] = x[i] + 0.5f * h * k1[i];
    }
    br_model_deriv(m, xs, u, k2);
    for (i = 0; i < BR_NX; i++) {
        xs[i] = x[i] + 0.5f * h * k2[i];
    }
    br_model_deriv(m, xs, u, k3);
    for (i = 0; i < BR_NX; i++) {
        xs[i] = x[i] + h * k3[i];
    }
    br_model_deriv(m, xs, u, k4);
    for (i = 0; i < BR_NX; i++) {
        out[i] = x[i] + (h / 6.0f) * (k1[i] + 2.0f * k2[i] + 2.0f * k3[i] + k4[i]);
    }
}

/* Bounded scheme: z exact over the displacement (eq. 4 with g_p held), friction
 * impulse in closed form, trapezoidal rigid body solved by fixed-point passes. */
static void bounded_step(const br_model_t *m, const float x[BR_NX], float u, float out[BR_NX])
{
    const br_lugre_cfg_t *c = &m->cfg.lugre;
    float h = m->cfg.dt_s;
    float L = m->cfg.lead_mprad;
    float w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    float wm = w0, dth = 0.0f, z1 = z0, w1 = w0;
    int pass;
    for (pass = 0; pass < BR_MODEL_BOUNDED_PASSES; pass++) {
        dth = wm * h;
        float dx = L * dth;
        float zint;
        if (dx != 0.0f) {
            /* eq. 4 over displacement: z1 = zss + (z0 - zss) e^{-r}, r = sigma0 |dx| / g_p */
            float zss = copysignf(gp / c->sigma0_Npm, dx);
            float r = c->sigma0_Npm * fabsf(dx) / gp;
            float one_minus_e = -expm1f(-r);
            z1 = z0 + (zss - z0) * one_minus_e; /* same, without cancellation for small r */
            /* integral of z over the step: h (zss + (z0 - zss) (1 - e^{-r}) / r);
             * (1 - e^{-r}) / r by its series where r would underflow the division */
            float q = (r > 1e-6f) ? one_minus_e / r : 1.0f - 0.5f * r;
            zint = h * (zss + (z0 - zss) * q);
        } else {
            z1 = z0;
            zint = z0 * h;
        }
        /* eq. 6 integrated: Jeff dw = u h - L^2 sigma2 dtheta - L (sigma0 int z + sigma1 dz) */
        w1 = w0 + (u * h - m->visc_Nmsprad * dth - L * (c->sigma0_Npm * zint + c->sigma1_Nspm * (z1 - z0))) * m->inv_Jeff;
        wm = 0.5f * (w0 + w1);
    }
    out[BR_X_THETA] = x[BR_X_THETA] + dth;
    out[BR_X_OMEGA] = w1;
    out[BR_X_Z] = z1;
    out[BR_X_GP] = gp;
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

br_status_t br_model_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float x_next[BR_NX])
{
    if (m == NULL || x == NULL || x_next == NULL) {
        return BR_E_NULL;
    }
    if (!m->ready) {
        return BR_E_STATE;
    }
    float tmp[BR_NX];
    if (!all_finite(x) || !isfinite(u_Nm) || !(x[BR_X_GP] > 0.0f)) {
        copy_state(x, x_next);
        return BR_E_INPUT;
    }
    rk4_step(m, x, u_Nm, tmp);
    /* RK4 only where both ends of the step are inside its stability region. */
    if (!(rk4_stable(m, x[BR_X_OMEGA], x[BR_X_GP]) && rk4_stable(m, tmp[BR_X_OMEGA], x[BR_X_GP]))) {
        bounded_step(m, x, u_Nm, tmp);
    }
    if (!all_finite(tmp)) {
        copy_state(x, x_next);
        return BR_E_NUMERIC;
    }
    copy_state(tmp, x_next);
    return BR_OK;
}
