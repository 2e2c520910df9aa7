/* SPDX-License-Identifier: Apache-2.0 */
/* The bench images' plant (br_bench_plant.h). */
#include "br_bench_plant.h"

#include <math.h>

#include "bristle_gen/machine/br_machine.h"

/* J_eff w' = tau - L (sigma2 L w + Fc v / (|v| + vs)), v = L w; explicit Euler */
void br_bench_plant_period(br_bench_plant_t *p)
{
    const float L = BR_MACHINE_LEAD_MPRAD_F;
    const float jeff = BR_MACHINE_J_KGM2_F + BR_MACHINE_M_KG_F * L * L;
    const float h = p->dt_s / (float)BR_BENCH_PLANT_SUBSTEPS;
    const float tau = p->duty * BR_MACHINE_TAU_PER_DUTY_NM_F;
    for (uint32_t i = 0u; i < BR_BENCH_PLANT_SUBSTEPS; ++i) {
        const float v = L * p->omega_radps;
        const float f = BR_MACHINE_SIGMA2_NSPM_F * v + BR_MACHINE_FC_N_F * v / (fabsf(v) + BR_MACHINE_VS_MPS_F);
        p->theta_rad += h * p->omega_radps;
        p->omega_radps += h * (tau - L * f) / jeff;
    }
    p->counts = (int32_t)floorf(p->theta_rad / BR_MACHINE_RAD_PER_COUNT_F + 0.5f);
}

br_status_t br_bench_plant_enc_read(void *ctx, int32_t *counts)
{
    *counts = ((br_bench_plant_t *)ctx)->counts;
    return BR_OK;
}

br_status_t br_bench_plant_pwm_write(void *ctx, float duty)
{
    ((br_bench_plant_t *)ctx)->duty = duty;
    return BR_OK;
}

br_status_t br_bench_plant_tick_wait(void *ctx, uint32_t *tick)
{
    (void)ctx;
    *tick = 0u;
    return BR_OK;
}
