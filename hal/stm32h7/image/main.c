/* SPDX-License-Identifier: Apache-2.0 */
/* The bristle firmware image for the STM32H743: one axis tracking a
 * sinusoidal (circle-test) reference with the H-infinity gains of
 * firmware/gen/bristle_gen/ctrl/br_hinf_gains.h and the friction compensation
 * of the machine file's estimator (control.estimator): the particle filter
 * (1500 particles for the reference machine) in a loop at its period (1.5 ms),
 * as the simulator's H-inf + PF circle runs it, or the UKF or H-infinity only
 * at the control period (bristle/br_machine_cfg.h: the same generated
 * headers, one home).
 *
 * main: board bring-up (hal/stm32h7/board: 480 MHz, outputs off) -> after a
 * watchdog reset, park with the outputs off -> IWDG1 started -> br_app_init
 * (outputs off) -> br_app_arm (the explicit arm, after bring-up) -> per tick:
 * the deadline (missed ticks), the reference, br_app_step (the same as the
 * replay's and the simulator's), and the watchdog refresh, only after a
 * healthy period. Any fault: the application latches (duty 0, TIM1 outputs
 * off), the board parks without refreshing, IWDG1 resets the part, which
 * then stays off (br_stm32h7_board_reset_by_watchdog) until a pin or
 * power-on reset re-arms it.
 *
 * State: the configurations are const (flash); the port, the application and
 * the reference are on main's stack. The one static is the particle filter's
 * state (br_pf_t, ~94 KB at BR_PF_MAX_PARTICLES): the documented exception to
 * "no mutable globals", placed in AXI SRAM by the linker script's NOLOAD
 * section .axisram (zeroed by Reset_Handler; br_pf_init initialises it), as
 * it does not belong on the 16 KiB stack. docs/modules/hal.md. */
#include <stddef.h>
#include <stdint.h>

#include "br_stm32h7_board.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_refgen.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

/* The estimator is the first of the machine file's control.estimator (the H743
 * runs each): the PF in a loop at its own period (estimator.pf.period_s), the
 * UKF and H-infinity only at control.period_s (bristle_gen/machine/br_machine.h). */
#if BR_MACHINE_EST_RANK_PF == 1
#define BR_IMAGE_USES_PF 1
#define BR_IMAGE_USES_UKF 0
#define BR_IMAGE_EST BR_APP_EST_PF
#define BR_IMAGE_DT_S BR_EST_PF_PERIOD_S_F
#define BR_IMAGE_PERIOD_NS BR_EST_PF_PERIOD_NS
#else
#define BR_IMAGE_USES_PF 0
#if BR_MACHINE_EST_RANK_UKF == 1
#define BR_IMAGE_USES_UKF 1
#define BR_IMAGE_EST BR_APP_EST_UKF
#else
#define BR_IMAGE_USES_UKF 0
#define BR_IMAGE_EST BR_APP_EST_NONE
#endif
#define BR_IMAGE_DT_S BR_MACHINE_CTRL_PERIOD_S_F
#define BR_IMAGE_PERIOD_NS BR_MACHINE_CTRL_PERIOD_NS
#endif

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

#if BR_IMAGE_USES_PF
static const br_pf_cfg_t br_image_pf_cfg = BR_MACHINE_PF_CFG_TUNED(BR_IMAGE_DT_S);
#elif BR_IMAGE_USES_UKF
static const br_ukf_cfg_t br_image_ukf_cfg = BR_MACHINE_UKF_CFG_TUNED(BR_IMAGE_DT_S);
#endif

static const br_refgen_cfg_t br_image_ref = {
    .amplitude_m = BR_IMAGE_REF_AMPLITUDE_M,
    .period_s = BR_IMAGE_REF_PERIOD_S,
    .phase_rad = BR_IMAGE_REF_PHASE_RAD,
    .dt_s = BR_IMAGE_DT_S,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
};

#if BR_IMAGE_USES_PF
/* The documented exception: the PF's state, in AXI SRAM (see above). */
static br_pf_t br_image_pf __attribute__((section(".axisram")));
#endif

int main(void)
{
    br_stm32_t port = {0};
    br_hal_t hal = {0};
    br_app_t app = {0};
    br_refgen_t refgen = {0};
    br_ref_t ref = {0};
    uint32_t tick = 0u;
#if BR_IMAGE_USES_UKF
    br_ukf_t ukf = {0};
#endif
    const br_app_cfg_t app_cfg = {
        .ctrl = &br_image_ctrl,
        .est = BR_IMAGE_EST,
#if BR_IMAGE_USES_PF
        .pf = &br_image_pf_cfg,
#elif BR_IMAGE_USES_UKF
        .ukf = &br_image_ukf_cfg,
#endif
        .guard = br_app_guard_cfg(BR_IMAGE_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
        .motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE),
    };
#if BR_IMAGE_USES_PF
    const br_app_mem_t mem = {.pf = &br_image_pf};
#elif BR_IMAGE_USES_UKF
    const br_app_mem_t mem = {.ukf = &ukf};
#else
    const br_app_mem_t mem = {0};
#endif

    if (br_stm32h7_board_init(&port, BR_IMAGE_PERIOD_NS, &hal) != BR_OK || br_stm32h7_board_reset_by_watchdog() ||
        br_stm32h7_board_watchdog_start() != BR_OK || br_app_init(&app, &app_cfg, &hal, &mem) != BR_OK ||
        br_refgen_init(&refgen, &br_image_ref) != BR_OK || br_app_arm(&app) != BR_OK) {
        br_stm32h7_board_halt(&port);
    }
    for (;;) {
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_HAL);
            br_stm32h7_board_halt(&port);
        }
        if (br_stm32_deadline_check(&port, BR_IMAGE_MAX_MISSED) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_DEADLINE);
            br_stm32h7_board_halt(&port);
        }
        if (br_refgen_step(&refgen, &ref) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_CTRL_INPUT);
            br_stm32h7_board_halt(&port);
        }
        /* BR_OK or BR_W_OUTLIER (a skipped measurement, control went on) */
        if (BR_FAILED(br_app_step(&app, &ref))) {
            br_stm32h7_board_halt(&port); /* latched: outputs already off */
        }
        br_stm32h7_board_watchdog_refresh();
    }
}
