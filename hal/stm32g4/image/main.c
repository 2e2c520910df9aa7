/* SPDX-License-Identifier: Apache-2.0 */
/* The bristle firmware image for the STM32G474 (Cortex-M4F, 170 MHz): one
 * axis tracking the circle test's sinusoidal reference with the H-infinity
 * gains of bristle_gen/ctrl/br_hinf_gains.h and the friction compensation of
 * the UKF (the machine file's tuned settings) at the control period (1 ms),
 * as the simulator's H-inf + UKF circle runs it.
 *
 * Why the UKF and not the PF (the STM32H743 image's estimator): the PF's
 * state (br_pf_t, 94816 bytes at BR_PF_MAX_PARTICLES) would fit the G474's
 * 96 KiB of SRAM1 + SRAM2, but not its time: a PF period at the machine's
 * 1500 particles takes 570 352 instructions on the Cortex-M4 (QEMU
 * mps2-an386, `make target-bench`, docs/target.md), more than twice the
 * 255 000 cycles of 1.5 ms at 170 MHz. This application (H-inf + UKF) is
 * 10 777 instructions per 1 ms period there (br_ukf_bench_mps2), 6.3 % of
 * 170 000 cycles; the UKF's state is 1060 bytes.
 *
 * main: board bring-up (170 MHz, outputs off) -> after a watchdog reset,
 * park with the outputs off -> IWDG started -> br_app_init -> br_app_arm ->
 * per tick: the deadline, the reference, br_app_step, the watchdog refresh
 * only after a healthy period. Any fault: the application latches (duty 0,
 * TIM1 outputs off), the board parks without refreshing, the IWDG resets the
 * part, which then stays off. State: configurations const (flash); the port,
 * the application, the UKF and the reference on main's stack (no static).
 * docs/modules/hal.md, "STM32G474". */
#include <stddef.h>
#include <stdint.h>

#include "br_stm32g4_board.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_refgen.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

/* The estimator is the first of the machine file's control.estimator that the
 * G474 can run in its period: the UKF or H-infinity only, at control.period_s. */
#if BR_MACHINE_EST_RANK_UKF && (!BR_MACHINE_EST_RANK_NONE || BR_MACHINE_EST_RANK_UKF < BR_MACHINE_EST_RANK_NONE)
#define BR_IMAGE_EST BR_APP_EST_UKF
#elif BR_MACHINE_EST_RANK_NONE
#define BR_IMAGE_EST BR_APP_EST_NONE
#else
#error "control.estimator lists only pf: the STM32G474 cannot run the PF in its period (570 352 instructions per 1.5 ms period at 1500 particles on the Cortex-M4, docs/target.md); add ukf or none to the list, or build BOARD=stm32h7"
#endif
#define BR_IMAGE_DT_S BR_MACHINE_CTRL_PERIOD_S_F
#define BR_IMAGE_PERIOD_NS BR_MACHINE_CTRL_PERIOD_NS

/* Reference: circle of radius 5 mm in 2 s, this axis is the sine. */
#define BR_IMAGE_REF_AMPLITUDE_M 5.0e-3f
#define BR_IMAGE_REF_PERIOD_S    2.0f
#define BR_IMAGE_REF_PHASE_RAD   0.0f

/* Deadline: more missed ticks than this since the arm turn the outputs off. */
#define BR_IMAGE_MAX_MISSED 2u

static const br_ctrl_cfg_t br_image_ctrl = {
    .K = BR_HINF_K,
    .dt_s = BR_IMAGE_DT_S,
    .tau_max_Nm = BR_MACHINE_TORQUE_LIMIT_NM_F,
    .tau_per_duty_Nm = BR_MACHINE_TAU_PER_DUTY_NM_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
};

static const br_ukf_cfg_t br_image_ukf_cfg = BR_MACHINE_UKF_CFG_TUNED(BR_IMAGE_DT_S);

static const br_refgen_cfg_t br_image_ref = {
    .amplitude_m = BR_IMAGE_REF_AMPLITUDE_M,
    .period_s = BR_IMAGE_REF_PERIOD_S,
    .phase_rad = BR_IMAGE_REF_PHASE_RAD,
    .dt_s = BR_IMAGE_DT_S,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
};

int main(void)
{
    br_stm32_t port = {0};
    br_hal_t hal = {0};
    br_app_t app = {0};
    br_ukf_t ukf = {0};
    br_refgen_t refgen = {0};
    br_ref_t ref = {0};
    uint32_t tick = 0u;
    const br_app_cfg_t app_cfg = {
        .ctrl = &br_image_ctrl,
        .est = BR_IMAGE_EST,
        .ukf = &br_image_ukf_cfg,
        .guard = br_app_guard_cfg(BR_IMAGE_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
        .motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE),
    };
    const br_app_mem_t mem = {.ukf = &ukf};

    if (br_stm32g4_board_init(&port, BR_IMAGE_PERIOD_NS, &hal) != BR_OK || br_stm32g4_board_reset_by_watchdog() ||
        br_stm32g4_board_watchdog_start() != BR_OK || br_app_init(&app, &app_cfg, &hal, &mem) != BR_OK ||
        br_refgen_init(&refgen, &br_image_ref) != BR_OK || br_app_arm(&app) != BR_OK) {
        br_stm32g4_board_halt(&port);
    }
    for (;;) {
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_HAL);
            br_stm32g4_board_halt(&port);
        }
        if (br_stm32_deadline_check(&port, BR_IMAGE_MAX_MISSED) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_DEADLINE);
            br_stm32g4_board_halt(&port);
        }
        if (br_refgen_step(&refgen, &ref) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_CTRL_INPUT);
            br_stm32g4_board_halt(&port);
        }
        /* BR_OK or BR_W_OUTLIER (a skipped measurement, control went on) */
        if (BR_FAILED(br_app_step(&app, &ref))) {
            br_stm32g4_board_halt(&port); /* latched: outputs already off */
        }
        br_stm32g4_board_watchdog_refresh();
    }
}
