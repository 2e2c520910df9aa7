/* SPDX-License-Identifier: Apache-2.0 */
/* The measurement of an axis held still for 0.1 s, then pushed by an external
 * force F_N (toward -x: a force against +x, as friction) with no torque:
 * theta(t) = -L F_N t^2 / (2 J_eff) from t0, frictionless (the model's
 * friction and the load then share the force a filter sees). Period k of the
 * model m, encoder resolution rpc (rad per count). The load tests of the UKF
 * and the PF (test_ukf_load, test_pf_load). */
#ifndef BR_TEST_PUSH_H
#define BR_TEST_PUSH_H

#include <math.h>

#include "br_test.h"
#include "bristle/br_est.h"
#include "bristle/br_model.h"

static inline br_meas_t br_test_pushed_meas(const br_model_cfg_t *m, double rpc, double F_N, int k)
{
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const double t = (double)k * m->dt_s - 0.1;
    const double th = (t > 0.0) ? -L * F_N * t * t / (2.0 * Jeff) : 0.0;
    const double cts = th / rpc + 0.5;
    const double whole = floor(cts);
    const br_meas_t y = {(int32_t)whole, (float)(cts - whole)};
    return y;
}

/* n periods of that push through the estimator e; returns the number of outlier
 * steps (every step BR_OK or BR_W_OUTLIER), *F_comp the last compensation */
static inline int br_test_run_pushed(const br_est_t *e, const br_model_cfg_t *m, double rpc, double F_N, int n,
                                     float *F_comp)
{
    int outliers = 0;
    for (int k = 0; k < n; k++) {
        const br_meas_t y = br_test_pushed_meas(m, rpc, F_N, k);
        const br_status_t st = e->step(e->ctx, &y, 0.0f, F_comp);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        outliers += st == BR_W_OUTLIER;
    }
    return outliers;
}

#endif
