/* SPDX-License-Identifier: Apache-2.0 */
/* The G4 board's wiring and clocks (br_stm32g4_board.h). */
#include "br_stm32g4_board.h"

br_stm32_cfg_t br_stm32g4_board_cfg(uint32_t control_period_ns)
{
    const br_stm32_cfg_t cfg = {
        .pwm_tim = (br_stm32_tim_t *)BR_STM32G4_TIM1_BASE,
        .enc_tim = (br_stm32_tim_t *)BR_STM32G4_TIM2_BASE,
        .systick = (br_stm32_systick_t *)BR_STM32G4_SYSTICK_BASE,
        .cpu_clock_hz = BR_G4_BOARD_CPU_HZ,
        .tim_clock_hz = BR_G4_BOARD_TIM_HZ,
        .pwm_hz = BR_G4_BOARD_PWM_HZ,
        .control_hz = 0u,
        .control_period_ns = control_period_ns,
        .enc_counter_bits = 32u,
        .enc_filter = BR_G4_BOARD_ENC_FILTER,
        .deadtime_ticks = BR_G4_BOARD_DEADTIME,
    };
    return cfg;
}

br_status_t br_stm32g4_board_init(br_stm32_t *port, uint32_t control_period_ns, br_hal_t *hal)
{
    const br_stm32g4_clock_regs_t clk = {
        (br_stm32g4_rcc_t *)BR_STM32G4_RCC_BASE,
        (br_stm32g4_pwr_t *)BR_STM32G4_PWR_BASE,
        (br_stm32g4_flash_t *)BR_STM32G4_FLASH_BASE,
    };
    br_status_t st = br_stm32g4_clock_170(&clk);
    if (st != BR_OK) {
        return st;
    }
    br_stm32_gpio_t *gpioa = (br_stm32_gpio_t *)BR_STM32G4_GPIOA_BASE;
    br_stm32_gpio_t *gpiob = (br_stm32_gpio_t *)BR_STM32G4_GPIOB_BASE;
    (void)br_stm32g4_rcc_enable((br_stm32g4_rcc_t *)BR_STM32G4_RCC_BASE);
    (void)br_stm32_gpio_af(gpioa, 0u, BR_G4_BOARD_PIN_AF_TIM2);  /* TIM2_CH1 */
    (void)br_stm32_gpio_af(gpioa, 1u, BR_G4_BOARD_PIN_AF_TIM2);  /* TIM2_CH2 */
    (void)br_stm32_gpio_af(gpioa, 8u, BR_G4_BOARD_PIN_AF_TIM1);  /* TIM1_CH1 */
    (void)br_stm32_gpio_af(gpioa, 9u, BR_G4_BOARD_PIN_AF_TIM1);  /* TIM1_CH2 */
    (void)br_stm32_gpio_af(gpiob, 13u, BR_G4_BOARD_PIN_AF_TIM1); /* TIM1_CH1N */
    (void)br_stm32_gpio_af(gpiob, 14u, BR_G4_BOARD_PIN_AF_TIM1); /* TIM1_CH2N */
    const br_stm32_cfg_t cfg = br_stm32g4_board_cfg(control_period_ns);
    st = br_stm32_init(port, &cfg);
    return (st != BR_OK) ? st : br_stm32_hal(port, hal);
}

int br_stm32g4_board_reset_by_watchdog(void)
{
    br_stm32g4_rcc_t *rcc = (br_stm32g4_rcc_t *)BR_STM32G4_RCC_BASE;
    const int wd = (rcc->CSR & BR_G4_RCC_CSR_IWDGRSTF) != 0u;
    rcc->CSR |= BR_G4_RCC_CSR_RMVF;
    return wd;
}

br_status_t br_stm32g4_board_watchdog_start(void)
{
    return br_stm32_iwdg_start((br_stm32_iwdg_t *)BR_STM32G4_IWDG_BASE, BR_G4_BOARD_IWDG_PR,
                                 BR_G4_BOARD_IWDG_RLR);
}

void br_stm32g4_board_watchdog_refresh(void)
{
    br_stm32_iwdg_refresh((br_stm32_iwdg_t *)BR_STM32G4_IWDG_BASE);
}

void br_stm32g4_board_halt(br_stm32_t *port)
{
    (void)br_stm32_pwm_disable(port);
    for (;;) {
        __asm__ volatile("nop");
    }
}
