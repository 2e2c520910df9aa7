/* SPDX-License-Identifier: Apache-2.0 */
/* Reversal (quadrant-error) compensation, float32. Equations in br_qec.h and
 * docs/modules/qec.md. */
#include "bristle/br_qec.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"

br_status_t br_qec_init(br_qec_t *q, const br_qec_cfg_t *cfg)
{
    if (q == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    q->ready = 0;
    if (!br_finite_nonneg(cfg->A0_N) || !isfinite(cfg->A1_kg) || !br_finite_pos(cfg->tau_s) ||
        !br_finite_pos(cfg->dt_s) || !br_finite_pos(cfg->comp_max_N) || (cfg->with_ff != 0 && cfg->with_ff != 1)) {
        return BR_E_PARAM;
    }
    if (cfg->with_ff && br_ff_init(&q->ff, &cfg->ff) != BR_OK) {
        return BR_E_PARAM;
    }
    q->cfg = *cfg;
    /* the decay per period: rho = exp(-dt / tau) */
    q->rho = expf(-cfg->dt_s / cfg->tau_s);
    q->pulse_N = 0.0f;
    q->dir = 0;
    q->in = (br_ff_in_t){0.0f, 0.0f, 0.0f};
    q->ready = 1;
    return BR_OK;
}

br_status_t br_qec_set_ref(br_qec_t *q, const br_ff_in_t *in)
{
    if (q == NULL || in == NULL) {
        return BR_E_NULL;
    }
    if (!q->ready) {
        return BR_E_STATE;
    }
    if (!isfinite(in->v_mps) || !isfinite(in->a_mps2) || !isfinite(in->p_m)) {
        return BR_E_INPUT;
    }
    /* s_k = sgn(v_k), 0 at rest */
    const int s = (in->v_mps > 0.0f) - (in->v_mps < 0.0f);
    if (s != 0 && s != q->dir) {
        /* a reversal (or a start from rest): p_k = s_k max(0, A0 + A1 |a_k|) */
        const float A = fmaxf(0.0f, q->cfg.A0_N + q->cfg.A1_kg * fabsf(in->a_mps2));
        q->pulse_N = (s > 0) ? A : -A;
        q->dir = s;
    } else {
        /* p_k = rho p_{k-1} */
        q->pulse_N *= q->rho;
    }
    if (q->cfg.with_ff) {
        (void)br_ff_set_ref(&q->ff, in); /* finite: checked above */
    }
    q->in = *in;
    return BR_OK;
}

br_status_t br_qec_comp(const br_qec_t *q, float *comp_N)
{
    if (q == NULL || comp_N == NULL) {
        return BR_E_NULL;
    }
    *comp_N = 0.0f;
    if (!q->ready) {
        return BR_E_STATE;
    }
    float f = q->pulse_N;
    if (q->cfg.with_ff) {
        /* the pulse on top of the static feedforward at the stored reference */
        float ff = 0.0f;
        const br_status_t st = br_ff_step(&q->ff, &q->in, &ff);
        if (st != BR_OK) {
            return st;
        }
        f += ff;
    }
    if (!isfinite(f)) {
        return BR_E_INPUT;
    }
    *comp_N = br_clampf(f, -q->cfg.comp_max_N, q->cfg.comp_max_N);
    return BR_OK;
}

br_status_t br_qec_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    return br_qec_comp((const br_qec_t *)ctx, F_hat_N);
}
