/* SPDX-License-Identifier: Apache-2.0 */
/* Compensation that predicts, float32. Equations in br_ff_pred.h, br_ff.h and docs/modules/ff-pred.md. */
#include "bristle/br_ff_pred.h"

#include <stddef.h>

br_status_t br_ff_pred_init(br_ff_pred_t *p, br_est_t inner, const br_ff_t *ff, const float *z_anchor_m,
                            const float *g_anchor_N)
{
    if (p == NULL || ff == NULL || inner.step == NULL) {
        return BR_E_NULL;
    }
    p->ready = 0;
    if (!ff->ready || !(ff->cfg.pred_ahead_s > 0.0f)) {
        return BR_E_PARAM;
    }
    p->inner = inner;
    p->ff = ff;
    p->z_anchor_m = z_anchor_m;
    p->g_anchor_N = g_anchor_N;
    p->ready = 1;
    return BR_OK;
}

/* F_comp = F_hat + dF after an inner call that gave an estimate (status st) */
static br_status_t add_pred(const br_ff_pred_t *p, br_status_t st, float *F_hat_N)
{
    if (st != BR_OK && st != BR_W_OUTLIER) {
        return st;
    }
    float dF = 0.0f;
    const br_status_t ps = br_ff_pred_N(p->ff, p->z_anchor_m, p->g_anchor_N, &dF);
    if (ps != BR_OK) {
        return ps;
    }
    *F_hat_N += dF;
    return st;
}

static br_status_t pred_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    const br_ff_pred_t *p = ctx;
    if (p == NULL || F_hat_N == NULL) {
        return BR_E_NULL;
    }
    if (!p->ready) {
        return BR_E_STATE;
    }
    return add_pred(p, p->inner.step(p->inner.ctx, y, u_prev_Nm, F_hat_N), F_hat_N);
}

static br_status_t pred_predict(void *ctx, float u_prev_Nm, float *F_hat_N)
{
    const br_ff_pred_t *p = ctx;
    if (p == NULL || F_hat_N == NULL) {
        return BR_E_NULL;
    }
    if (!p->ready) {
        return BR_E_STATE;
    }
    if (p->inner.predict == NULL) {
        return BR_OK; /* the estimate held, as br_est_period holds it */
    }
    return add_pred(p, p->inner.predict(p->inner.ctx, u_prev_Nm, F_hat_N), F_hat_N);
}

static br_status_t pred_reset(void *ctx)
{
    const br_ff_pred_t *p = ctx;
    if (p == NULL) {
        return BR_E_NULL;
    }
    return (p->ready && p->inner.reset != NULL) ? p->inner.reset(p->inner.ctx) : BR_OK;
}

br_est_t br_ff_pred_est(br_ff_pred_t *p)
{
    return (br_est_t){p, pred_step, pred_predict, pred_reset};
}
