/* Configuration and step-input checks shared by the friction estimators. See br_est.h. */
#include "bristle/br_est.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"

br_status_t br_est_cfg_check(const br_est_cfg_t *cfg)
{
    if (cfg == NULL) {
        return BR_E_NULL;
    }
    br_model_t model;
    const br_status_t st = br_model_init(&model, &cfg->model);
    if (st != BR_OK) {
        return st;
    }
    for (int i = 0; i < BR_NX; i++) {
        if (!br_finite_nonneg(cfg->q_var[i])) {
            return BR_E_PARAM;
        }
    }
    if (!br_finite_pos(cfg->r_var_rad2) || !br_finite_pos(cfg->outlier_sigma) || !br_finite_pos(cfg->rad_per_count) ||
        cfg->reanchor_after < 1u) {
        return BR_E_PARAM;
    }
    if (!br_finite_pos(cfg->gp_min_N) || !isfinite(cfg->gp_max_N) || !(cfg->gp_max_N > cfg->gp_min_N) ||
        !(cfg->gp0_N >= cfg->gp_min_N && cfg->gp0_N <= cfg->gp_max_N)) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

br_status_t br_est_check_step(const br_meas_t *y, float u_prev_Nm)
{
    if (!isfinite(u_prev_Nm) || !isfinite(y->frac) || y->frac < 0.0f || y->frac > 1.0f) {
        return BR_E_INPUT;
    }
    return BR_OK;
}
