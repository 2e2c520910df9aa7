/* SPDX-License-Identifier: Apache-2.0 */
/* One axis's control loop over the HAL. */
#include "bristle/br_axis.h"

#include <stddef.h>

br_status_t br_axis_init(br_axis_t *a, const br_hal_t *hal, const br_ctrl_cfg_t *ctrl_cfg, const br_est_t *est)
{
    if (a == NULL || hal == NULL || hal->encoder_read == NULL || hal->pwm_write == NULL ||
        hal->tick_wait == NULL) {
        return BR_E_NULL;
    }
    a->ready = 0;
    br_status_t st = br_ctrl_init(&a->ctrl, ctrl_cfg);
    if (st != BR_OK) {
        return st;
    }
    if (est != NULL && est->step == NULL) {
        return BR_E_NULL;
    }
    a->hal = hal;
    a->est = (est != NULL) ? *est : (br_est_t){NULL, NULL, NULL, NULL};
    a->F_hat_N = 0.0f;
    a->last = (br_ctrl_out_t){0};
    a->ready = 1;
    return BR_OK;
}

br_status_t br_axis_step(br_axis_t *a, const br_ref_t *ref)
{
    if (a == NULL || ref == NULL) {
        return BR_E_NULL;
    }
    if (!a->ready) {
        return BR_E_STATE;
    }
    int32_t counts = 0;
    br_status_t st = a->hal->encoder_read(a->hal->ctx, &counts);
    if (st != BR_OK) {
        /* no position: command zero torque rather than act on stale data */
        (void)a->hal->pwm_write(a->hal->ctx, 0.0f);
        return st;
    }
    if (a->est.step != NULL) {
        /* the estimator sees the count's centre and the torque of the last period */
        const br_meas_t y = {counts, 0.5f};
        st = a->est.step(a->est.ctx, &y, a->last.tau_Nm, &a->F_hat_N);
        /* a warning (an outlier measurement skipped by the estimator, whose
         * prediction stays usable): control goes on and the status is passed up */
        if (BR_FAILED(st)) {
            (void)a->hal->pwm_write(a->hal->ctx, 0.0f);
            a->last.tau_Nm = 0.0f;
            return st;
        }
    }
    const br_status_t est_st = st;
    br_ctrl_in_t in = {counts, ref->ref_counts, ref->ref_frac_counts, ref->ref_omega_radps, a->F_hat_N};
    st = br_ctrl_step(&a->ctrl, &in, &a->last);
    if (st != BR_OK) {
        (void)a->hal->pwm_write(a->hal->ctx, 0.0f);
        return st;
    }
    st = a->hal->pwm_write(a->hal->ctx, a->last.duty);
    return (st != BR_OK) ? st : est_st;
}
