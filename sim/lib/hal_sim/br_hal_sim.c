/* SPDX-License-Identifier: Apache-2.0 */
/* Host HAL port bound to the plant simulator. */
#include "br_hal_sim.h"

#include <math.h>
#include <stddef.h>

static br_status_t sim_encoder_read(void *ctx, int32_t *counts)
{
    br_hal_sim_t *s = ctx;
    if (counts == NULL) return BR_E_NULL;
    *counts = br_plant_encoder(s->plant);
    return BR_OK;
}

static br_status_t sim_pwm_write(void *ctx, float duty)
{
    br_hal_sim_t *s = ctx;
    if (!isfinite(duty)) {
        s->duty = 0.0;
        return BR_E_INPUT;
    }
    s->duty = fmin(fmax((double)duty, -1.0), 1.0);
    return BR_OK;
}

static br_status_t sim_tick_wait(void *ctx, uint32_t *tick)
{
    br_hal_sim_t *s = ctx;
    if (s->started) {
        br_plant_step(s->plant, s->duty, s->dt_s);
        s->tick++;
    }
    s->started = 1;
    if (tick != NULL) *tick = s->tick;
    return BR_OK;
}

br_status_t br_hal_sim_init(br_hal_sim_t *port, br_plant_t *plant, double dt_s, br_hal_t *hal)
{
    if (port == NULL || plant == NULL || hal == NULL) return BR_E_NULL;
    if (!(isfinite(dt_s) && dt_s > 0.0)) return BR_E_PARAM;
    port->plant = plant;
    port->dt_s = dt_s;
    port->duty = 0.0;
    port->tick = 0;
    port->started = 0;
    hal->ctx = port;
    hal->encoder_read = sim_encoder_read;
    hal->pwm_write = sim_pwm_write;
    hal->tick_wait = sim_tick_wait;
    hal->pwm_disable = NULL; /* the simulated amplifier has no enable: duty 0 is off */
    hal->pwm_enable = NULL;
    return BR_OK;
}
