/* The bristle firmware image for the STM32H743: one axis tracking a
 * sinusoidal (circle-test) reference with the H-infinity gains of
 * firmware/gen/bristle_gen/ctrl/br_hinf_gains.h, without friction
 * compensation (BR_APP_EST_NONE).
 *
 * main: board bring-up (hal/stm32h7/board) -> br_app_init -> per tick: the
 * reference, br_app_step. Any error stops the motor and parks.
 *
 * The configuration is const (flash); the state is on main's stack, so the
 * image has no mutable globals. An estimator's state does not belong on this
 * 16 KiB stack: a PF image keeps its br_pf_t (~94 KB) in a static in .bss
 * (DTCM) and passes it in br_app_mem_t (firmware/include/bristle/br_app.h). */
#include <stddef.h>
#include <stdint.h>

#include "br_stm32h7_board.h"
#include "bristle/br_app.h"
#include "bristle/br_refgen.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/machine/br_machine.h"

/* The H-inf gains are designed in continuous time and checked sampled at 1 ms
 * (docs/modules/hinf.md): the loop runs at BR_IMAGE_CONTROL_HZ. */
#define BR_IMAGE_CONTROL_HZ 1000u
#define BR_IMAGE_DT_S (1.0f / (float)BR_IMAGE_CONTROL_HZ)

/* Reference: circle of radius 5 mm in 2 s, this axis is the sine. */
#define BR_IMAGE_REF_AMPLITUDE_M 5.0e-3f
#define BR_IMAGE_REF_PERIOD_S    2.0f
#define BR_IMAGE_REF_PHASE_RAD   0.0f

#define BR_IMAGE_TAU_MAX_NM (0.9f * BR_MACHINE_TAU_PER_DUTY_NM_F)

static const br_ctrl_cfg_t br_image_ctrl = {
    .K = BR_HINF_K,
    .dt_s = BR_IMAGE_DT_S,
    .tau_max_Nm = BR_IMAGE_TAU_MAX_NM,
    .tau_per_duty_Nm = BR_MACHINE_TAU_PER_DUTY_NM_F,
    .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
    .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
};

static const br_app_cfg_t br_image_app = {
    .ctrl = &br_image_ctrl,
    .est = BR_APP_EST_NONE,
};

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
    br_stm32h7_t port = {0};
    br_hal_t hal = {0};
    br_app_t app = {0};
    br_refgen_t refgen = {0};
    br_ref_t ref = {0};
    uint32_t tick = 0u;

    if (br_stm32h7_board_init(&port, BR_IMAGE_CONTROL_HZ, &hal) != BR_OK ||
        br_app_init(&app, &br_image_app, &hal, NULL) != BR_OK || br_refgen_init(&refgen, &br_image_ref) != BR_OK) {
        br_stm32h7_board_halt(&port);
    }
    for (;;) {
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK || br_refgen_step(&refgen, &ref) != BR_OK ||
            br_app_step(&app, &ref) != BR_OK) {
            br_stm32h7_board_halt(&port);
        }
    }
}
