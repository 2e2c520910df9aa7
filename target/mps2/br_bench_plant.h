/* SPDX-License-Identifier: Apache-2.0 */
/* The small float plant the bench images close their loop on
 * (ukf_bench_main.c, link_bench_main.c; docs/target.md): the machine's
 * inertia, viscous friction and LuGre friction (thesis eqs. 1, 3-5, the
 * friction the machine file declares and the estimators model: presliding
 * stiffness sigma0, damping sigma1, Stribeck level g(v)), in
 * BR_BENCH_PLANT_SUBSTEPS substeps per period, and a HAL over it (the encoder
 * reads its count, rounded, the PWM sets its duty). Consistent data, so no
 * guard trips; the estimators' work per period does not depend on it.
 *
 * Before 2026-11-27 the friction was sigma2 v + Fc v / (|v| + vs), no
 * presliding: at standstill a damper that holds no force, so the axis crept
 * under any force and, with the compensation, a held reference hunted over
 * +-800 counts until the PF lost lock (docs/link.md, "Cost on the M7"). */
#ifndef BR_BENCH_PLANT_H
#define BR_BENCH_PLANT_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_lugre.h"

#define BR_BENCH_PLANT_SUBSTEPS 10u

typedef struct {
    int32_t counts;
    float duty;
    float theta_rad; /* motor angle and speed */
    float omega_radps;
    float dt_s;      /* the control period */
    br_lugre_t fr;   /* the machine's LuGre friction: the bristle deflection z */
} br_bench_plant_t;

/* at rest at count 0, duty 0, the bristles undeflected; control period dt_s
 * (> 0). BR_OK, or br_lugre_init's error for the machine's friction. */
br_status_t br_bench_plant_init(br_bench_plant_t *p, float dt_s);

/* the axis under the last period's duty, one control period on; BR_OK, or
 * br_lugre_step's error (the state is then not to be used) */
br_status_t br_bench_plant_period(br_bench_plant_t *p);

/* encoder_read and pwm_write over p (ctx); tick_wait returns at once */
br_status_t br_bench_plant_enc_read(void *ctx, int32_t *counts);
br_status_t br_bench_plant_pwm_write(void *ctx, float duty);
br_status_t br_bench_plant_tick_wait(void *ctx, uint32_t *tick);

#endif
