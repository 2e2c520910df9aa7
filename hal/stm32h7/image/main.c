/* The bristle firmware image for the STM32H743: one axis tracking a
 * sinusoidal (circle-test) reference with the H-infinity gains of
 * firmware/gen/bristle_gen/ctrl/br_hinf_gains.h, without friction compensation (comp 0 N).
 *
 * Peripherals (RM0433): TIM2 encoder on PA0 (CH1) / PA1 (CH2), TIM1 PWM on
 * PA8 (CH1), PA9 (CH2), PB13 (CH1N), PB14 (CH2N), all AF1; SysTick tick.
 * Clocks: the image runs on the reset clock (HSI, 64 MHz, all bus
 * prescalers 1), so the core and the timer kernel clocks are both 64 MHz. A
 * board bring-up that starts PLL1 (480 MHz core, 240 MHz timers) only has to
 * change BR_IMAGE_CPU_HZ and BR_IMAGE_TIM_HZ.
 *
 * All state lives in main's stack frame: the image has no mutable globals. */
#include <stddef.h>

#include "bristle/br_axis.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle/br_refgen.h"
#include "bristle/br_stm32h7.h"
#include "bristle_gen/machine/br_machine.h"

#define BR_IMAGE_CPU_HZ       64000000u  /* HSI after reset */
#define BR_IMAGE_TIM_HZ       64000000u  /* APB timer kernel clock */
#define BR_IMAGE_PWM_HZ       20000u
#define BR_IMAGE_CONTROL_HZ   1000u      /* must match the gains' sampling period */
#define BR_IMAGE_DEADTIME     32u        /* timer ticks: 500 ns at 64 MHz */
#define BR_IMAGE_ENC_FILTER   3u         /* f_CK_INT, N = 8 */

/* The H-inf gains are designed in continuous time and checked sampled at 1 ms
 * (docs/modules/hinf.md); the loop runs at BR_IMAGE_CONTROL_HZ. */
#define BR_IMAGE_K BR_HINF_K
#define BR_IMAGE_DT_S (1.0f / (float)BR_IMAGE_CONTROL_HZ)

/* Reference: circle of radius 5 mm in 2 s, this axis is the sine. */
#define BR_IMAGE_REF_AMPLITUDE_M 5.0e-3f
#define BR_IMAGE_REF_PERIOD_S    2.0f
#define BR_IMAGE_REF_PHASE_RAD   0.0f

#define BR_IMAGE_TAU_MAX_NM      (0.9f * BR_MACHINE_TAU_PER_DUTY_NM_F)

/* Motor stopped and outputs off; waits for a reset or a debugger. */
static void br_image_halt(br_stm32h7_t *port)
{
    (void)br_stm32h7_pwm_disable(port);
    for (;;) {
        __asm__ volatile("nop");
    }
}

int main(void)
{
    br_stm32h7_t port = {0};
    br_hal_t hal = {0};
    br_axis_t axis = {0};
    br_refgen_t refgen = {0};
    br_ref_t ref = {0};
    uint32_t tick = 0u;

    const br_stm32h7_cfg_t port_cfg = {
        .pwm_tim = (br_stm32h7_tim_t *)BR_STM32H7_TIM1_BASE,
        .enc_tim = (br_stm32h7_tim_t *)BR_STM32H7_TIM2_BASE,
        .systick = (br_stm32h7_systick_t *)BR_STM32H7_SYSTICK_BASE,
        .cpu_clock_hz = BR_IMAGE_CPU_HZ,
        .tim_clock_hz = BR_IMAGE_TIM_HZ,
        .pwm_hz = BR_IMAGE_PWM_HZ,
        .control_hz = BR_IMAGE_CONTROL_HZ,
        .enc_counter_bits = 32u,
        .enc_filter = BR_IMAGE_ENC_FILTER,
        .deadtime_ticks = BR_IMAGE_DEADTIME,
    };
    const br_ctrl_cfg_t ctrl_cfg = {
        .K = BR_IMAGE_K,
        .dt_s = BR_IMAGE_DT_S,
        .tau_max_Nm = BR_IMAGE_TAU_MAX_NM,
        .tau_per_duty_Nm = BR_MACHINE_TAU_PER_DUTY_NM_F,
        .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
        .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
    };
    const br_refgen_cfg_t ref_cfg = {
        .amplitude_m = BR_IMAGE_REF_AMPLITUDE_M,
        .period_s = BR_IMAGE_REF_PERIOD_S,
        .phase_rad = BR_IMAGE_REF_PHASE_RAD,
        .dt_s = BR_IMAGE_DT_S,
        .lead_mprad = BR_MACHINE_LEAD_MPRAD_F,
        .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,
    };
    br_stm32h7_gpio_t *gpioa = (br_stm32h7_gpio_t *)BR_STM32H7_GPIOA_BASE;
    br_stm32h7_gpio_t *gpiob = (br_stm32h7_gpio_t *)BR_STM32H7_GPIOB_BASE;

    (void)br_stm32h7_rcc_enable((br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE);
    (void)br_stm32h7_gpio_af(gpioa, 0u, 1u);  /* TIM2_CH1 */
    (void)br_stm32h7_gpio_af(gpioa, 1u, 1u);  /* TIM2_CH2 */
    (void)br_stm32h7_gpio_af(gpioa, 8u, 1u);  /* TIM1_CH1 */
    (void)br_stm32h7_gpio_af(gpioa, 9u, 1u);  /* TIM1_CH2 */
    (void)br_stm32h7_gpio_af(gpiob, 13u, 1u); /* TIM1_CH1N */
    (void)br_stm32h7_gpio_af(gpiob, 14u, 1u); /* TIM1_CH2N */

    if (br_stm32h7_init(&port, &port_cfg) != BR_OK || br_stm32h7_hal(&port, &hal) != BR_OK ||
        br_axis_init(&axis, &hal, &ctrl_cfg, NULL) != BR_OK || br_refgen_init(&refgen, &ref_cfg) != BR_OK) {
        br_image_halt(&port);
    }

    for (;;) {
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK || br_refgen_step(&refgen, &ref) != BR_OK ||
            br_axis_step(&axis, &ref) != BR_OK) {
            br_image_halt(&port);
        }
    }
}
