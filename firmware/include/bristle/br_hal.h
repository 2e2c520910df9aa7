/* SPDX-License-Identifier: Apache-2.0 */
/* The hardware abstraction: encoder counts in, PWM duty out, a control tick.
 * A port fills the function pointers and owns ctx; conversions (counts to
 * radians, torque to duty) live in the firmware core, not in a port. */
#ifndef BR_HAL_H
#define BR_HAL_H

#include <stdint.h>
#include "bristle/br_status.h"

typedef struct {
    void *ctx;
    /* Free-running encoder position in counts; wraps modulo 2^32. */
    br_status_t (*encoder_read)(void *ctx, int32_t *counts);
    /* Duty in [-1, 1]; a port clamps and rejects non-finite values. */
    br_status_t (*pwm_write)(void *ctx, float duty);
    /* Blocks until the next control tick; returns the tick index. */
    br_status_t (*tick_wait)(void *ctx, uint32_t *tick);
    /* Optional (NULL: the port has none; the application then relies on
     * pwm_write(0)). Outputs off: duty 0 and the power stage disabled
     * (STM32H7: TIM1 BDTR.MOE and CCER off); and back on, duty 0, at an arm. */
    br_status_t (*pwm_disable)(void *ctx);
    br_status_t (*pwm_enable)(void *ctx);
} br_hal_t;

#endif
