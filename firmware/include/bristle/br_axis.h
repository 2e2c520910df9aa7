/* The control loop of one axis over the HAL: read the encoder, run the
 * controller with the friction compensation, write the PWM. */
#ifndef BR_AXIS_H
#define BR_AXIS_H

#include "bristle/br_ctrl.h"
#include "bristle/br_hal.h"

typedef struct {
    int32_t ref_counts;
    float ref_frac_counts;
    float ref_omega_radps;
} br_ref_t;

typedef struct {
    const br_hal_t *hal;
    br_ctrl_t ctrl;
    br_ctrl_out_t last;
    int ready;
} br_axis_t;

br_status_t br_axis_init(br_axis_t *a, const br_hal_t *hal, const br_ctrl_cfg_t *ctrl_cfg);

/* One period after the tick: encoder -> controller (with comp_N) -> PWM. */
br_status_t br_axis_step(br_axis_t *a, const br_ref_t *ref, float comp_N);

#endif
