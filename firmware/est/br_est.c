/* SPDX-License-Identifier: Apache-2.0 */
/* Configuration and step-input checks shared by the friction estimators. See br_est.h. */
#include "bristle/br_est.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

#include "br_check.h"

int br_est_var_ok(float v, int zero_ok)
{
    if (v == 0.0f) {
        return zero_ok;
    }
    return isfinite(v) && v >= FLT_MIN && v <= BR_EST_VAR_MAX;
}

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
    if (!br_finite_pos(cfg->rad_per_count) || !br_finite_pos(cfg->outlier_sigma) ||
        cfg->outlier_sigma > BR_EST_GATE_MAX_SIGMA || cfg->reanchor_after < 1u) {
        return BR_E_PARAM;
    }
    if (!(cfg->model.causes.delay_s <= (float)(BR_EST_DELAY_HIST - 2u) * cfg->model.dt_s)) {
        return BR_E_PARAM;
    }
    for (int i = 0; i < BR_NX; i++) {
        if (!br_est_var_ok(cfg->q_var[i], 1)) {
            return BR_E_PARAM;
        }
    }
    const float rpc2 = cfg->rad_per_count * cfg->rad_per_count;
    if (!br_est_var_ok(cfg->r_var_rad2, 0) || !(cfg->r_var_rad2 >= BR_EST_R_MIN_COUNTS2 * rpc2)) {
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

void br_est_delay_init(br_est_delay_t *d, const br_est_cfg_t *cfg)
{
    const float q = cfg->model.causes.delay_s / cfg->model.dt_s;
    d->m = (uint32_t)q;
    d->f = q - (float)d->m;
    d->on = cfg->model.causes.delay_s > 0.0f;
    d->head = 0u;
    d->n = 0u;
    for (uint32_t i = 0; i < BR_EST_DELAY_HIST; i++) {
        d->u[i] = 0.0f;
    }
}

/* the command j periods before the newest (j = 0: the newest), 0 before the first */
static float cmd_ago(const br_est_delay_t *d, uint32_t j)
{
    return (j < d->n) ? d->u[(d->head + BR_EST_DELAY_HIST - j) % BR_EST_DELAY_HIST] : 0.0f;
}

float br_est_delay_apply(br_est_delay_t *d, float u_prev_Nm)
{
    if (!d->on) {
        return u_prev_Nm;
    }
    d->head = (d->head + 1u) % BR_EST_DELAY_HIST;
    d->u[d->head] = u_prev_Nm;
    if (d->n < BR_EST_DELAY_HIST) {
        d->n++;
    }
    /* u_a = (1 - f) u[k-1-m] + f u[k-2-m] */
    return (1.0f - d->f) * cmd_ago(d, d->m) + d->f * cmd_ago(d, d->m + 1u);
}
