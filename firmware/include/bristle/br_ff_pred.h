/* SPDX-License-Identifier: Apache-2.0 */
/* Compensation that predicts (docs/modules/ff-pred.md): an estimator's F_hat
 * at t_k plus the Maxwell-slip elements' change over the coming horizon,
 * driven by the reference's motion (br_ff_pred_N):
 *
 *   F_comp = F_hat_k + [F_el(z advanced by the reference's travel over tau) - F_el(z_k)]
 *
 * The reference is the feedforward's (br_ff_set_ref, once a period before the
 * application's step), so the prediction lives beside it: the estimators'
 * interface (br_est_t) sees the measurement and the command, never the
 * reference. The elements z_k are the feedforward's (driven by the reference)
 * or an anchor the caller names (an estimator's own elements and level, e.g.
 * a Maxwell-slip UKF's br_ukf_est_t elem_m and mean[BR_X_GP]). The result is
 * a br_est_t the application drives like any estimator (BR_APP_EST_EXTERN). */
#ifndef BR_FF_PRED_H
#define BR_FF_PRED_H

#include "bristle/br_est.h"
#include "bristle/br_ff.h"
#include "bristle/br_status.h"

typedef struct {
    br_est_t inner;          /* the estimator whose F_hat the prediction is added to */
    const br_ff_t *ff;       /* the reference and the elements; cfg.pred_ahead_s > 0 */
    const float *z_anchor_m; /* NULL: the feedforward's elements; else the anchor's (ff's mslip.n of them) */
    const float *g_anchor_N; /* NULL: the level g(v + a tau); else the anchor's level */
    int ready;
} br_ff_pred_t;

/* BR_OK; BR_E_NULL (p, ff or inner.step NULL); BR_E_PARAM (ff not initialised
 * or without a horizon: a prediction that would add nothing is a mistake). */
br_status_t br_ff_pred_init(br_ff_pred_t *p, br_est_t inner, const br_ff_t *ff, const float *z_anchor_m,
                            const float *g_anchor_N);

/* The interface: step = inner's step, then F += dF when it gave an estimate
 * (BR_OK or BR_W_OUTLIER); predict likewise (inner's predict NULL: F held);
 * reset = inner's. A failing prediction returns its status (the application
 * stops the axis) with F = the inner's F_hat. */
br_est_t br_ff_pred_est(br_ff_pred_t *p);

#endif
