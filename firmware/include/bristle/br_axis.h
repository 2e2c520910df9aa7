/* SPDX-License-Identifier: Apache-2.0 */
/* The control loop of one axis over the HAL: read the encoder, let the
 * friction estimator (if any) update, run the controller with its estimate as
 * the compensation, write the PWM. */
#ifndef BR_AXIS_H
#define BR_AXIS_H

#include "bristle/br_ctrl.h"
#include "bristle/br_est.h"
#include "bristle/br_hal.h"
#include "bristle/br_ref.h"

typedef struct {
    const br_hal_t *hal;
    br_est_t est;        /* est.step == NULL: no compensation (H-inf only) */
    br_ctrl_t ctrl;
    float F_hat_N;       /* last estimate used as compensation */
    br_ctrl_out_t last;
    int ready;
} br_axis_t;

/* est may be NULL (no compensation); the estimator must run at the
 * controller's period. */
br_status_t br_axis_init(br_axis_t *a, const br_hal_t *hal, const br_ctrl_cfg_t *ctrl_cfg, const br_est_t *est);

/* One period after the tick: encoder -> estimator -> controller (with the
 * estimate as compensation) -> PWM. An estimator error is passed up after a
 * zero-duty write; the caller decides whether to go on without it. */
br_status_t br_axis_step(br_axis_t *a, const br_ref_t *ref);

#endif
