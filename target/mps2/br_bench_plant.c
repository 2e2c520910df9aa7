/* SPDX-License-Identifier: Apache-2.0 */
/* The bench images' plant (br_bench_plant.h). */
#include "br_bench_plant.h"

#include <math.h>
#include <string.h>

#include "bristle_gen/machine/br_machine.h"

br_status_t br_bench_plant_init(br_bench_plant_t *p, float dt_s)
{
    const br_lugre_cfg_t fc = {BR_MACHINE_SIGMA0_NPM_F, BR_MACHINE_SIGMA1_NSPM_F, BR_MACHINE_FC_N_F,
                               BR_MACHINE_FS_N_F, BR_MACHINE_VS_MPS_F};
    memset(p, 0, sizeof *p);
    p->dt_s = dt_s;
    return br_lugre_init(&p->fr, &fc);
}

br_status_t br_bench_plant_period(br_bench_plant_t *p)
{
    const float L = BR_MACHINE_LEAD_MPRAD_F;
    const float jeff = BR_MACHINE_J_KGM2_F + BR_MACHINE_M_KG_F * L * L;
    const float h = p->dt_s / (float)BR_BENCH_PLANT_SUBSTEPS;
    const float tau = p->duty * BR_MACHINE_TAU_PER_DUTY_NM_F;
    for (uint32_t i = 0u; i < BR_BENCH_PLANT_SUBSTEPS; ++i) {
        const float v = L * p->omega_radps;
        float fnl = 0.0f;
        /* eqs. 3-5: z advanced over the substep's move at v (exact in the
         * displacement, bounded at any speed), F_nl = sigma0 z + sigma1 z' */
        const br_status_t st = br_lugre_step(&p->fr, v, h, &fnl);
        if (st != BR_OK) {
            return st;
        }
        /* eq. 1: J_eff w' = tau - L (sigma2 v + F_nl); semi-implicit Euler
         * (w first, theta with the new w) keeps the presliding spring stable */
        p->omega_radps += h * (tau - L * (BR_MACHINE_SIGMA2_NSPM_F * v + fnl)) / jeff;
        p->theta_rad += h * p->omega_radps;
    }
    p->counts = (int32_t)floorf(p->theta_rad / BR_MACHINE_RAD_PER_COUNT_F + 0.5f);
    return BR_OK;
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
