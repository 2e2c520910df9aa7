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
    pf->n_load_undo = 0u;
    pf->load_alt = 0;
    pf->load_alt_nu1 = 0.0f;
    for (int i = 0; i < 3; i++) {
        pf->load_alt_e[i] = 0.0f;
    }
    for (int i = 0; i < 6; i++) {
        pf->load_P[i] = 0.0f;
        pf->load_alt_P[i] = 0.0f;
    }
    if (ld->q_N2 == 0.0f && ld->max_N == 0.0f) {
        return BR_OK; /* off */
    }
    /* on: q a normal float, max_N > 0 with 4 max_N^2 finite; the thesis model with the
     * bootstrap proposal (the cloud is moved and weighed again with eq. 6's f_nl and the
     * Gaussian likelihood), without Maxwell-slip elements (whose particles keep their
     * f_nl where the move makes the LuGre one again) */
    if (!br_est_var_ok(ld->q_N2, 0) || !br_est_var_ok(4.0f * ld->max_N * ld->max_N, 0) || !(ld->max_N > 0.0f) ||
        pf->model.extended || pf->model.cfg.mslip.n > 0 || pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR) {
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

/* The common error's covariance over one period (the cloud predicted with F_d):
 *   e <- Phi e + [0, 0, w],  Phi = [1 h -g; 0 1 -a; 0 0 1],  a = 2 g / h,  var w = q
 *   P <- Phi P Phi^T + diag(0, 0, q)  (P's upper triangle P00 P01 P02 P11 P12 P22) */
static void cov_predict(const br_pf_t *pf, float P[6])
{
    const float h = pf->cfg.est.model.dt_s, g = pf->load_g_radpN, a = 2.0f * g / h;
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
}

static int cov_finite(const float P[6])
{
    for (int i = 0; i < 6; i++) {
        if (!isfinite(P[i])) {
            return 0;
        }
    }
    return 1;
}

void br_pf_load_tick(br_pf_t *pf)
{
    if (!br_pf_load_on(pf)) {
        return;
    }
    cov_predict(pf, pf->load_P);
    /* F_d at the period's start: the compensation's second term (br_pf_load_comp_N) */
    pf->load_prev_N = pf->load_N;
    if (!cov_finite(pf->load_P)) {
        cov_reset(pf);
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

/* The best log-weight of the valid particles with theta moved by dth (step 2's l_j of the
 * nearest particle): whether such a cloud passes the gate */
static float probe_lmax(const br_pf_t *pf, float y_rel, float dth)
{
    const uint32_t m = pf->cfg.n_particles;
    float emin = INFINITY;
    for (uint32_t j = 0; j < m; j++) {
        if (pf->l[j] != pf->l[j]) {
            continue; /* invalid */
        }
        const float e = fabsf(pf->x[BR_X_THETA][j] + dth - y_rel);
        emin = (e < emin) ? e : emin;
    }
    return (emin < INFINITY) ? br_pf_loglik(emin, pf->inv_2r) : -INFINITY;
}

/* A glitch is not a load (docs/modules/pf.md): the last step re-acquired, this step's
 * innovation is gated. The re-acquisition's correction e, carried over the period, is
 * Phi e (theta by e0 + h e1 - g e2, omega by e1 - a e2); the cloud without it is the one
 * the filter would have had with the last measurement rejected. Spike: only the last
 * measurement was off, the cloud moved back by Phi e; slip: the counter stays off by the
 * last innovation nu1, theta (in the counter's frame) moved on by nu1 as well. The
 * smaller |mean innovation| first; the first whose best particle lies within twice
 * the gate's distance (BR_PF_LOAD_UNDO_GATE2: the glitch period's compensation moved
 * the real axis as well as the model knows the plant) is taken: F_d and its value
 * at the period's start without e2, P as the prediction left it carried over this
 * period, the cloud moved (its lmax returned, sums made again).
 * Neither passing: lmax unchanged (the re-acquisition stands). */
static float load_undo(br_pf_t *pf, float y_rel, float lmax, float sums[2], uint32_t n_valid)
{
    const float h = pf->cfg.est.model.dt_s, g = pf->load_g_radpN, a = 2.0f * g / h;
    const float *e = pf->load_alt_e;
    const float s_th = e[0] + h * e[1] - g * e[2], s_om = e[1] - a * e[2];
    /* the mean innovation's magnitude of each hypothesis: |mean theta_j + dth - y| */
    const float d = sums[0] / (float)n_valid;
    const float dth_spike = -s_th, dth_slip = -s_th + pf->load_alt_nu1;
    const int slip_first = fabsf(d + dth_slip) < fabsf(d + dth_spike);
    const float dth[2] = {slip_first ? dth_slip : dth_spike, slip_first ? dth_spike : dth_slip};
    for (int i = 0; i < 2; i++) {
        if (!(probe_lmax(pf, y_rel, dth[i]) >= BR_PF_LOAD_UNDO_GATE2 * pf->outlier_l)) {
            continue;
        }
        float P[6];
        for (int c = 0; c < 6; c++) {
            P[c] = pf->load_alt_P[c];
        }
        cov_predict(pf, P);
        if (!cov_finite(P)) {
            return lmax;
        }
        for (int c = 0; c < 6; c++) {
            pf->load_P[c] = P[c];
        }
        const float max_N = pf->cfg.load.max_N;
        pf->load_N = br_clampf(pf->load_N - e[2], -max_N, max_N);
        pf->load_prev_N = br_clampf(pf->load_prev_N - e[2], -max_N, max_N);
        if (pf->n_load_undo < UINT32_MAX) {
            pf->n_load_undo++;
        }
        return move_cloud(pf, y_rel, dth[i], -s_om, sums);
    }
    return lmax;
}

float br_pf_load_update(br_pf_t *pf, float y_rel, float lmax, float sums[2], uint32_t n_valid)
{
    if (!br_pf_load_on(pf)) {
        return lmax;
    }
    /* the last step's re-acquisition: tested here only, with no predict-only period between */
    if (pf->load_alt && pf->n_predicted == 0u && !(lmax >= pf->outlier_l)) {
        lmax = load_undo(pf, y_rel, lmax, sums, n_valid);
    }
    pf->load_alt = 0;
    const float max_N = pf->cfg.load.max_N;
    float *P = pf->load_P;
    /* the cloud's mean innovation and spread: d = mean theta_j - y, var theta_j */
    const float n = (float)n_valid;
    const float d = sums[0] / n;
    const float v = sums[1] / n - d * d;
    const float s0 = ((v > 0.0f) ? v : 0.0f) + pf->r_gate;
    int acq = 0;
    float P_pred[6];
    if (!(lmax >= pf->outlier_l)) {
        /* gated: re-acquired as a load when a change of at most 2 max_N over the k periods
         * since the last measurement (theta moved by -g k^2 dF) explains it, F_d's variance
         * inflated by that change squared; an outlier otherwise */
        const float k = (float)pf->n_predicted + 1.0f;
        const float df_raw = d / (pf->load_g_radpN * k * k);
        if (!(fabsf(df_raw) <= 2.0f * max_N)) {
            return lmax;
        }
        for (int i = 0; i < 6; i++) {
            P_pred[i] = P[i]; /* the undo's: P as an outlier would have left it */
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
        acq = 1;
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
    if (!isfinite(dF) || !isfinite(k0 * nu) || !isfinite(k1 * nu) || !cov_finite(np)) {
        return lmax; /* kept: no change */
    }
    for (int i = 0; i < 6; i++) {
        P[i] = np[i];
    }
    const float f = br_clampf(pf->load_N + dF, -max_N, max_N);
    if (acq) {
        /* kept for the next step's undo: the correction as applied, P as predicted, nu1 */
        pf->load_alt = 1;
        pf->load_alt_e[0] = k0 * nu;
        pf->load_alt_e[1] = k1 * nu;
        pf->load_alt_e[2] = f - pf->load_N;
        pf->load_alt_nu1 = nu;
        for (int i = 0; i < 6; i++) {
            pf->load_alt_P[i] = P_pred[i];
        }
    }
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
