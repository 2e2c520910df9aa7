/* Inline kernel of the eq. 6 model's RK4 step (private to the firmware).
 *
 * br_model_step and the particle filter's prediction loop both step through
 * these functions. The model's constants are copied once into a local
 * br_model_k_t, so that after inlining they sit in FPU registers for the whole
 * particle loop (a pointer into br_model_t would be reloaded after every store
 * to the particle arrays, both being float). The operations and their order
 * are those of eqs. 3, 4 and 6 as documented in docs/modules/model.md; with
 * -ffp-contract=off every caller gets bit-identical results.
 * Only the RK4 path lives here; the bounded scheme stays out of line. */
#ifndef BR_MODEL_KERNEL_H
#define BR_MODEL_KERNEL_H

#include <math.h>

#include "bristle/br_model.h"
#include "br_lugre_kernel.h"

typedef struct {
    float L;        /* lead, m/rad */
    float s0;       /* sigma0, N/m */
    float s1;       /* sigma1, N s/m */
    float s0Lh;     /* sigma0 L h, for the a h test */
    float visc;     /* L^2 sigma2, N m s/rad */
    float inv_Jeff; /* 1 / (J + L^2 M) */
    float h;        /* step, s */
    float h_half;   /* h / 2 */
    float h_6;      /* h / 6 */
} br_model_k_t;

static inline br_model_k_t br_model_k(const br_model_t *m)
{
    const br_model_k_t k = {m->cfg.lead_mprad,
                            m->cfg.lugre.sigma0_Npm,
                            m->cfg.lugre.sigma1_Nspm,
                            m->cfg.lugre.sigma0_Npm * m->cfg.lead_mprad * m->cfg.dt_s,
                            m->visc_Nmsprad,
                            m->inv_Jeff,
                            m->cfg.dt_s,
                            0.5f * m->cfg.dt_s,
                            m->cfg.dt_s / 6.0f};
    return k;
}

/* eq. 4 with g = g_p: dz/dt = v - sigma0 |v| z / g_p, v = L omega */
static inline float br_model_k_zdot(const br_model_k_t *k, float omega, float z, float gp)
{
    return br_lk_zdot_mps(k->s0, k->L * omega, z, gp);
}

/* eq. 3: f_nl = sigma0 z + sigma1 dz/dt */
static inline float br_model_k_fnl(const br_model_k_t *k, float z, float zdot)
{
    return br_lk_force_N(k->s0, k->s1, z, zdot);
}

/* eq. 6: domega/dt = (u - L^2 sigma2 omega - L f_nl) / Jeff */
static inline float br_model_k_omega_dot(const br_model_k_t *k, float omega, float fnl, float u)
{
    return (u - k->visc * omega - k->L * fnl) * k->inv_Jeff;
}

/* a h = sigma0 L |omega| h / g_p <= BR_MODEL_RK4_AH_MAX, without a division */
static inline int br_model_k_rk4_ok(const br_model_k_t *k, float omega, float gp)
{
    return k->s0Lh * fabsf(omega) <= BR_MODEL_RK4_AH_MAX * gp;
}

/* Classic RK4 on eq. 6 over h with u held. theta does not enter the
 * right-hand side and g_p' = 0, so the stages carry (omega, z) only:
 * theta' of a stage is its omega, and g_p comes out unchanged.
 * Returns 1 when a h is inside the RK4 limit at both ends of the step
 * (the result is then the step), 0 when the caller must use the bounded
 * scheme instead. */
static inline int br_model_k_rk4(const br_model_k_t *k, const float x[BR_NX], float u, float out[BR_NX])
{
    const float w0 = x[BR_X_OMEGA], z0 = x[BR_X_Z], gp = x[BR_X_GP];
    /* stage 1 at x */
    const float zd1 = br_model_k_zdot(k, w0, z0, gp);
    const float wd1 = br_model_k_omega_dot(k, w0, br_model_k_fnl(k, z0, zd1), u);
    /* stage 2 at x + h/2 k1 */
    const float w2 = w0 + k->h_half * wd1, z2 = z0 + k->h_half * zd1;
    const float zd2 = br_model_k_zdot(k, w2, z2, gp);
    const float wd2 = br_model_k_omega_dot(k, w2, br_model_k_fnl(k, z2, zd2), u);
    /* stage 3 at x + h/2 k2 */
    const float w3 = w0 + k->h_half * wd2, z3 = z0 + k->h_half * zd2;
    const float zd3 = br_model_k_zdot(k, w3, z3, gp);
    const float wd3 = br_model_k_omega_dot(k, w3, br_model_k_fnl(k, z3, zd3), u);
    /* stage 4 at x + h k3 */
    const float w4 = w0 + k->h * wd3, z4 = z0 + k->h * zd3;
    const float zd4 = br_model_k_zdot(k, w4, z4, gp);
    const float wd4 = br_model_k_omega_dot(k, w4, br_model_k_fnl(k, z4, zd4), u);
    /* x + h/6 (k1 + 2 k2 + 2 k3 + k4) */
    out[BR_X_THETA] = x[BR_X_THETA] + k->h_6 * (w0 + 2.0f * w2 + 2.0f * w3 + w4);
    out[BR_X_OMEGA] = w0 + k->h_6 * (wd1 + 2.0f * wd2 + 2.0f * wd3 + wd4);
    out[BR_X_Z] = z0 + k->h_6 * (zd1 + 2.0f * zd2 + 2.0f * zd3 + zd4);
    out[BR_X_GP] = gp;
    return br_model_k_rk4_ok(k, w0, gp) && br_model_k_rk4_ok(k, out[BR_X_OMEGA], gp);
}

/* The bounded scheme of br_model_step (out of line: not reached at circle speeds). */
void br_model_bounded_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float out[BR_NX]);

#endif
