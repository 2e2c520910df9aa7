/* SPDX-License-Identifier: Apache-2.0 */
/* Host HAL port bound to the double-precision plant simulator: the encoder
 * reads the plant's quantised position, the PWM sets the amplifier duty, and
 * each tick advances the plant by one control period with the duty held. */
#ifndef BR_HAL_SIM_H
#define BR_HAL_SIM_H

#include "bristle/br_hal.h"
#include "plant/br_sim_plant.h"

typedef struct {
    br_plant_t *plant;
    double dt_s;
    double duty;      /* last duty written, applied over the next period */
    uint32_t tick;
    int started;      /* the first tick_wait starts the clock without advancing */
} br_hal_sim_t;

/* Binds port to plant with control period dt_s and fills hal. */
br_status_t br_hal_sim_init(br_hal_sim_t *port, br_plant_t *plant, double dt_s, br_hal_t *hal);

#endif
