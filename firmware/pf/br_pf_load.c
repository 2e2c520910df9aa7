/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's shared external force, cfg.load (docs/modules/pf.md,
 * "External force"): one load force F_d beside the particles, a scalar Kalman
 * filter on the cloud's mean innovation. */
#include "br_pf_load.h"

#include <math.h>

#include "br_check.h"
#include "br_model_kernel.h"
#include "br_pf_kernel.h"

/* the common error's covariance at rest: theta and omega as the particles have them, F_d
 * unknown within the actuator's force */
static void cov_reset(br_pf_t *pf)
{
    for (int i = 0; i < 6; i++) {
        pf->load_P[i] = 0.0f;
    }
    pf->load_P[5] = pf->cfg.load.max_N * pf->cfg.load.max_N;
}

br_status_t br_pf_load_init(br_pf_t *pf)
{
    const br_pf_load_t *ld = &pf->cfg.load;
    pf->load_N = 0.0f;
    pf->load_prev_N = 0.0f;
    pf->load_comp_N = 0.0f;
    pf->load_g_radpN = 0.0f;
    pf->n_load_acq = 0u;
    for (int i = 0; i < 6; i++) {
        pf->load_P[i] = 0.0f;
    }
    if (ld->q_N2 == 0.0f && ld->max_N == 0.0f) {
        return BR_OK; /* off */
    }
    /* on: q a normal float, max_N > 0 with 4 max_N^2 finite; the thesis model with the
     * bootstrap proposal (the cloud is moved and weighed again with eq. 6's f_nl and the
     * Gaussian likelihood) */
    if (!br_est_var_ok(ld->q_N2, 0) || !br_est_var_ok(4.0f * ld->max_N * ld->max_N, 0) || !(ld->max_N > 0.0f) ||
        pf->model.extended || pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR) {
        return BR_E_PARAM;
    }
    const float h = pf->cfg.est.model.dt_s;
    /* g = L h^2 / (2 J_eff): theta's change over one period under one newton on the load side */
    pf->load_g_radpN = 0.5f * pf->model.cfg.lead_mprad * h * h * pf->model.inv_Jeff;
    cov_reset(pf);
    return (isfinite(pf->load_g_radpN) && pf->load_g_radpN > 0.0f) ? BR_OK : BR_E_PARAM;
}

float br_pf_load_torque(const br_pf_t *pf, float u_Nm)
{
    /* eq. 1 with the load: J_eff omega' = u - L (sigma2 L omega + f_nl + F_d) */
    return br_pf_load_on(pf) ? u_Nm - pf->model.cfg.lead_mprad * pf->load_N : u_Nm;
}

void br_pf_load_tick(br_pf_t *pf)
{
    if (!br_pf_load_on(pf)) {
        return;
    }
    /* the common error e = [dtheta, domega, dF] over one period (the cloud predicted with F_d):
     *   e <- Phi e + [0, 0, w],  Phi = [1 h -g; 0 1 -a; 0 0 1],  a = 2 g / h,  var w = q
     * P <- Phi P Phi^T + diag(0, 0, q) */
    const float h = pf->cfg.est.model.dt_s, g = pf->load_g_radpN, a = 2.0f * g / h;
    float *P = pf->load_P;
    const float p00 = P[0], p01 = P[1], p02 = P[2], p11 = P[3], p12 = P[4], p22 = P[5];
    /* rows of Phi P: r0 = [p00 + h p01 - g p02, p01 + h p11 - g p12, p02 + h p12 - g p22],
     * r1 = [p01 - a p02, p11 - a p12, p12 - a p22], r2 = [p02, p12, p22] */
    const float r00 = p00 + h * p01 - g * p02, r01 = p01 + h * p11 - g * p12, r02 = p02 + h * p12 - g * p22;
    const float r11 = p11 - a * p12, r12 = p12 - a * p22;
    P[0] = r00 + h * r01 - g * r02;
    P[1] = r01 - a * r02;
    P[2] = r02;
    P[3] = r11 - a * r12;
    P[4] = r12;
    P[5] = p22 + pf->cfg.load.q_N2;
    /* F_d at the period's start: the compensation's second term (br_pf_load_comp_N) */
    pf->load_prev_N = pf->load_N;
    for (int i = 0; i < 6; i++) {
        if (!isfinite(P[i])) {
            cov_reset(pf);
            return;
        }
    }
}

/* The cloud moved by the common error's correction: theta by dth, omega by dom, each
 * valid particle's f_nl (eqs. 3, 4) and log-weight made again, with cfg.adapt's sums;
 * returns the largest log-weight. A particle whose moved state is not finite keeps its
 * predicted one and becomes invalid. */
static float move_cloud(br_pf_t *pf, float y_rel, float dth, float dom, float sums[2])
{
    const br_model_k_t mk = br_model_k(&pf->model);
    const uint32_t m = pf->cfg.n_particles;
    float lmax = -INFINITY, s1 = 0.0f, s2 = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        if (pf->l[j] != pf->l[j]) {
            continue; /* invalid: kept, weight 0 */
        }
        const float th = pf->x[BR_X_THETA][j] + dth, om = pf->x[BR_X_OMEGA][j] + dom;
        const float fnl = br_pf_fnl_kp(&mk, om, pf->x[BR_X_Z][j], pf->kgp[j]);
        if ((th - th) + (fnl - fnl) != 0.0f) {
            pf->fnl[j] = 0.0f;
            pf->l[j] = NAN;
            continue;
        }
        pf->x[BR_X_THETA][j] = th;
        pf->x[BR_X_OMEGA][j] = om;
        pf->fnl[j] = fnl;
        /* step 2 again: l_j = -(theta_j - y)^2 / (2 R) */
        const float e = th - y_rel;
        const float l = br_pf_loglik(e, pf->inv_2r);
        pf->l[j] = l;
        lmax = (l > lmax) ? l : lmax;
        s1 += e;
        s2 += e * e;
    }
    sums[0] = s1;
    sums[1] = s2;
    return lmax;
}

float br_pf_load_update(br_pf_t *pf, float y_rel, float lmax, float sums[2], uint32_t n_valid)
{
    if (!br_pf_load_on(pf)) {
        return lmax;
    }
    const float max_N = pf->cfg.load.max_N;
    float *P = pf->load_P;
    /* the cloud's mean innovation and spread: d = mean theta_j - y, var theta_j */
    const float n = (float)n_valid;
    const float d = sums[0] / n;
    const float v = sums[1] / n - d * d;
    const float s0 = ((v > 0.0f) ? v : 0.0f) + pf->r_gate;
    if (!(lmax >= pf->outlier_l)) {
        /* gated: re-acquired as a load when a change of at most 2 max_N over the k periods
         * since the last measurement (theta moved by -g k^2 dF) explains it, F_d's variance
         * inflated by that change squared; an outlier otherwise */
        const float k = (float)pf->n_predicted + 1.0f;
        const float df_raw = d / (pf->load_g_radpN * k * k);
        if (!(fabsf(df_raw) <= 2.0f * max_N)) {
            return lmax;
        }
        /* as if F_d's variance had been larger by df_raw^2 k periods ago: P += df_raw^2 b b^T,
         * b = [-g k^2, -2 g k / h, 1] the error a change of F_d then makes now */
        const float b[3] = {-pf->load_g_radpN * k * k, -2.0f * pf->load_g_radpN * k / pf->cfg.est.model.dt_s, 1.0f};
        const float dv = df_raw * df_raw;
        P[0] += dv * b[0] * b[0];
        P[1] += dv * b[0] * b[1];
        P[2] += dv * b[0] * b[2];
        P[3] += dv * b[1] * b[1];
        P[4] += dv * b[1] * b[2];
        P[5] += dv;
        pf->n_load_acq++;
    }
    /* the Kalman update of the common error on theta's innovation nu = y - mean theta = -d
     * (H = [1 0 0], variance var + R + rpc^2/12): S = P00 + s0, K = P[:, 0] / S,
     * e = K nu, P <- P - K P[0, :] */
    const float s = P[0] + s0;
    const float k0 = P[0] / s, k1 = P[1] / s, k2 = P[2] / s;
    const float nu = -d;
    const float p00 = P[0], p01 = P[1], p02 = P[2], p11 = P[3], p12 = P[4], p22 = P[5];
    const float dF = k2 * nu;
    const float np[6] = {p00 - k0 * p00, p01 - k0 * p01, p02 - k0 * p02,
                         p11 - k1 * p01, p12 - k1 * p02, p22 - k2 * p02};
    if (!isfinite(dF) || !isfinite(k0 * nu) || !isfinite(k1 * nu)) {
        return lmax; /* kept: no change */
    }
    for (int i = 0; i < 6; i++) {
        if (!isfinite(np[i])) {
            return lmax;
        }
        P[i] = np[i];
    }
    const float f = br_clampf(pf->load_N + dF, -max_N, max_N);
    pf->load_N = f;
    /* the cloud carries theta and omega: moved by the correction's share of them */
    return move_cloud(pf, y_rel, k0 * nu, k1 * nu, sums);
}

float br_pf_load_comp_N(br_pf_t *pf, float F_N)
{
    if (!br_pf_load_on(pf)) {
        return F_N;
    }
    /* (L1) F_d through a notch at the PF's Nyquist frequency, unit gain at rest:
     * y_k = (1 + r)/2 (F_d,k + F_d,k-1) - r y_k-1; a period-2 swing of F_d does not reach the axis
     * (the loop's mode near -1 with an actuator delay of a period or more) */
    const float r = BR_PF_LOAD_NOTCH_R, c = 0.5f * (1.0f + r);
    const float y = c * (pf->load_N + pf->load_prev_N) - r * pf->load_comp_N;
    pf->load_comp_N = br_clampf(y, -pf->cfg.load.max_N, pf->cfg.load.max_N);
    /* (L2) the compensation: the mean f_nl plus the filtered F_d */
    return br_clampf(F_N + pf->load_comp_N, -pf->cfg.load.max_N, pf->cfg.load.max_N);
}
