/* SPDX-License-Identifier: Apache-2.0 */
/* UKF bench image for QEMU's mps2 boards (docs/target.md, "The UKF on both
 * cores"): the STM32G4 image's application (H-inf + UKF at the control
 * period, the machine's tuned settings, hal/stm32g4/image/main.c) run for
 * BR_UKF_BENCH_STEPS periods on the circle reference, each br_app_step timed
 * with SysTick as the replay image does (calibrated, `-icount shift=0`).
 * The encoder reads a small float plant closing the loop (the machine's
 * inertia, viscous and smoothed Coulomb friction, 10 Euler substeps per
 * period): consistent data, so no guard trips; the UKF's work per step (its
 * sigma points through the model, a Cholesky factor) does not depend on it.
 *
 *   qemu-system-arm -M mps2-an386 -nographic -icount shift=0 \
 *     -semihosting-config enable=on,target=native -kernel br_ukf_bench_mps2.elf
 *
 * Prints "calib insns=... ticks=..." and "ukf steps=... sum_ticks=...
 * max_ticks=... sizeof_ukf=..."; exit status 0, or 1 on a failed step. */
#include <stdint.h>

#include "br_bench_clock.h"
#include "br_bench_plant.h"
#include "br_semihost.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_refgen.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

#define BR_UKF_BENCH_STEPS 2000u
#define BR_UKF_BENCH_DT_S BR_MACHINE_CTRL_PERIOD_S_F

static const br_ctrl_cfg_t bench_ctrl = BR_MACHINE_CTRL_CFG(BR_UKF_BENCH_DT_S);

static const br_ukf_cfg_t bench_ukf_cfg = BR_MACHINE_UKF_CFG_TUNED(BR_UKF_BENCH_DT_S);

static const br_refgen_cfg_t bench_ref = {
    .amplitude_m = 5.0e-3f,
    .period_s = 2.0f,
    .phase_rad = 0.0f,
    .dt_s = BR_UKF_BENCH_DT_S,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
};

int main(void)
{
    br_bench_plant_t io;
    const br_hal_t hal = {&io, br_bench_plant_enc_read, br_bench_plant_pwm_write, br_bench_plant_tick_wait, 0, 0};
    br_ukf_t ukf;
    br_app_t app;
    br_refgen_t refgen;
    br_ref_t ref = {0, 0.0f, 0.0f};
    const br_app_cfg_t cfg = {
        .ctrl = &bench_ctrl,
        .est = BR_APP_EST_UKF,
        .ukf = &bench_ukf_cfg,
        .guard = br_app_guard_cfg(BR_UKF_BENCH_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
        .motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE),
    };
    const br_app_mem_t mem = {.ukf = &ukf};
    br_bench_clock_t clk;
    uint32_t sum = 0u;
    uint32_t max = 0u;

    br_bench_clock_start(&clk);

    if (br_bench_plant_init(&io, BR_UKF_BENCH_DT_S) != BR_OK || br_refgen_init(&refgen, &bench_ref) != BR_OK ||
        br_app_init(&app, &cfg, &hal, &mem) != BR_OK ||
        br_app_arm(&app) != BR_OK) {
        br_sh_puts("ukf bench: init failed\n");
        br_sh_exit(1u);
    }
    for (uint32_t k = 0u; k < BR_UKF_BENCH_STEPS; ++k) {
        /* the axis under the last period's duty, then the period's reference */
        if (br_bench_plant_period(&io) != BR_OK || br_refgen_step(&refgen, &ref) != BR_OK) {
            br_sh_puts("ukf bench: plant or reference failed\n");
            br_sh_exit(1u);
        }
        const uint32_t t0 = br_bench_clock_stamp(&clk);
        const br_status_t st = br_app_step(&app, &ref);
        const uint32_t dt = br_bench_clock_stamp(&clk) - t0;
        if (BR_FAILED(st)) {
            br_bench_say_u32("ukf bench: step failed at k=", k);
            br_bench_say_u32(" fault=", (uint32_t)app.fault);
            br_sh_puts("\n");
            br_sh_exit(1u);
        }
        if (k > 0u) { /* step 0 primes the filter */
            sum += dt;
            max = (dt > max) ? dt : max;
        }
    }
    br_bench_say_u32("ukf steps=", BR_UKF_BENCH_STEPS - 1u);
    br_bench_say_u32(" sum_ticks=", sum);
    br_bench_say_u32(" max_ticks=", max);
    br_bench_say_u32(" sizeof_ukf=", (uint32_t)sizeof ukf);
    br_sh_puts("\n");
    br_sh_exit(0u);
}
