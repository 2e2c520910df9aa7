/* SPDX-License-Identifier: Apache-2.0 */
/* The small float plant the bench images close their loop on
 * (ukf_bench_main.c, link_bench_main.c; docs/target.md): the machine's
 * inertia, viscous and smoothed Coulomb friction, explicit Euler in
 * BR_BENCH_PLANT_SUBSTEPS substeps per period, and a HAL over it (the
 * encoder reads its count, the PWM sets its duty). Consistent data, so no
 * guard trips; the estimators' work per period does not depend on it. */
#ifndef BR_BENCH_PLANT_H
#define BR_BENCH_PLANT_H

#include <stdint.h>

#include "bristle/br_hal.h"

#define BR_BENCH_PLANT_SUBSTEPS 10u

typedef struct {
    int32_t counts;
    float duty;
    float theta_rad; /* motor angle and speed */
    float omega_radps;
    float dt_s;      /* the control period */
} br_bench_plant_t;

/* the axis under the last period's duty, one control period on */
void br_bench_plant_period(br_bench_plant_t *p);

/* encoder_read and pwm_write over p (ctx); tick_wait returns at once */
br_status_t br_bench_plant_enc_read(void *ctx, int32_t *counts);
br_status_t br_bench_plant_pwm_write(void *ctx, float duty);
br_status_t br_bench_plant_tick_wait(void *ctx, uint32_t *tick);

#endif
