/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's shared external force, cfg.load (docs/modules/pf.md,
 * "External force"): one load force F_d beside the particles, a scalar Kalman
 * filter on the cloud's mean innovation. */
#include "br_pf_load.h"

#include <math.h>

#include "br_check.h"
#include "br_model_kernel.h"
#include "br_pf_kernel.h"

br_status_t br_pf_load_init(br_pf_t *pf)
{
    const br_pf_load_t *ld = &pf->cfg.load;
    pf->load_N = 0.0f;
    pf->load_P_N2 = 0.0f;
    pf->load_g_radpN = 0.0f;
    pf->n_load_acq = 0u;
    if (ld->q_N2 == 0.0f && ld->max_N == 0.0f) {
        return BR_OK; /* off */
    }
    /* on: q a normal float, max_N > 0 with max_N^2 and 4 max_N^2 finite; the thesis
     * model with the bootstrap proposal (the cloud is moved and weighed again with
     * eq. 6's f_nl and the Gaussian likelihood) */
    if (!br_est_var_ok(ld->q_N2, 0) || !br_est_var_ok(4.0f * ld->max_N * ld->max_N, 0) || !(ld->max_N > 0.0f) ||
        pf->model.extended || pf->cfg.proposal != BR_PF_PROPOSAL_PRIOR) {
        return BR_E_PARAM;
    }
    const float h = pf->cfg.est.model.dt_s;
    /* g = L h^2 / (2 J_eff): theta's change over one period under one newton on the load side */
    pf->load_g_radpN = 0.5f * pf->model.cfg.lead_mprad * h * h * pf->model.inv_Jeff;
    pf->load_P_N2 = ld->max_N * ld->max_N;
    return (isfinite(pf->load_g_radpN) && pf->load_g_radpN > 0.0f) ? BR_OK : BR_E_PARAM;
}

float br_pf_load_torque(const br_pf_t *pf, float u_Nm)
{
    /* eq. 1 with the load: J_eff omega' = u - L (sigma2 L omega + f_nl + F_d) */
    return br_pf_load_on(pf) ? u_Nm - pf->model.cfg.lead_mprad * pf->load_N : u_Nm;
}

void br_pf_load_tick(br_pf_t *pf)
{
    if (br_pf_load_on(pf)) {
        /* F_d' = 0 + a random walk: P <- P + q, at most max_N^2 (its prior) */
        const float p = pf->load_P_N2 + pf->cfg.load.q_N2;
        const float p0 = pf->cfg.load.max_N * pf->cfg.load.max_N;
        pf->load_P_N2 = (p < p0) ? p : p0;
    }
}

/* The cloud moved by a change dF of the load over the last k periods: theta by
 * dth, omega by dom, each valid particle's f_nl (eqs. 3, 4) and log-weight made
 * again, with cfg.adapt's sums; returns the largest log-weight. A particle whose
 * moved state is not finite keeps its predicted one and becomes invalid. */
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
    const float k = (float)pf->n_predicted + 1.0f; /* periods since the last measurement */
    /* a constant change dF over k periods moves theta by -g k^2 dF: H = -g k^2 */
    const float gk2 = pf->load_g_radpN * k * k;
    /* the cloud's mean innovation and spread: d = mean theta_j - y, var theta_j */
    const float n = (float)n_valid;
    const float d = sums[0] / n;
    const float v = sums[1] / n - d * d;
    const float s0 = ((v > 0.0f) ? v : 0.0f) + pf->r_gate;
    float p = pf->load_P_N2;
    if (!(lmax >= pf->outlier_l)) {
        /* gated: re-acquired as a load when a change of at most 2 max_N explains it,
         * its variance inflated by that change squared; an outlier otherwise */
        const float df_raw = d / gk2;
        if (!(fabsf(df_raw) <= 2.0f * max_N)) {
            return lmax;
        }
        p += df_raw * df_raw;
        pf->n_load_acq++;
    }
    /* the scalar Kalman update: S = g^2 k^4 P + var + R + rpc^2/12, dF = (g k^2 P / S) d,
     * P <- P (var + R + rpc^2/12) / S */
    const float s = gk2 * gk2 * p + s0;
    const float inc = (gk2 * p / s) * d;
    const float p_new = p * (s0 / s);
    if (!isfinite(inc) || !isfinite(p_new)) {
        return lmax; /* kept: no change */
    }
    const float f = br_clampf(pf->load_N + inc, -max_N, max_N);
    const float df = f - pf->load_N;
    pf->load_N = f;
    pf->load_P_N2 = (p_new < max_N * max_N) ? p_new : max_N * max_N;
    /* the period predicted again with F_d + dF, to first order: theta by -g k^2 dF, omega by
     * BR_PF_LOAD_OMEGA_SHARE of -L h k dF / J_eff = -(2 g k / h) dF (docs/modules/pf.md: the
     * whole of it makes the closed loop ring at the PF's period) */
    return move_cloud(pf, y_rel, -gk2 * df,
                      -BR_PF_LOAD_OMEGA_SHARE * 2.0f * pf->load_g_radpN * k / pf->cfg.est.model.dt_s * df, sums);
}

float br_pf_load_comp_N(const br_pf_t *pf, float F_N)
{
    if (!br_pf_load_on(pf)) {
        return F_N;
    }
    return br_clampf(F_N + pf->load_N, -pf->cfg.load.max_N, pf->cfg.load.max_N);
}
