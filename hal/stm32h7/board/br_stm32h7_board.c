/* SPDX-License-Identifier: Apache-2.0 */
/* The board's wiring and clocks (br_stm32h7_board.h). */
#include "br_stm32h7_board.h"

br_stm32_cfg_t br_stm32h7_board_cfg(uint32_t control_period_ns)
{
    const br_stm32_cfg_t cfg = {
        .pwm_tim = (br_stm32_tim_t *)BR_STM32H7_TIM1_BASE,
        .enc_tim = (br_stm32_tim_t *)BR_STM32H7_TIM2_BASE,
        .systick = (br_stm32_systick_t *)BR_STM32H7_SYSTICK_BASE,
        .cpu_clock_hz = BR_BOARD_CPU_HZ,
        .tim_clock_hz = BR_BOARD_TIM_HZ,
        .pwm_hz = BR_BOARD_PWM_HZ,
        .control_hz = 0u,
        .enc_counter_bits = 32u,
        .enc_filter = BR_BOARD_ENC_FILTER,
        .deadtime_ticks = BR_BOARD_DEADTIME,
        .control_period_ns = control_period_ns,
    };
    return cfg;
}

br_status_t br_stm32h7_board_init(br_stm32_t *port, uint32_t control_period_ns, br_hal_t *hal)
{
    const br_stm32h7_clock_regs_t clk = {
        (br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE,
        (br_stm32h7_pwr_t *)BR_STM32H7_PWR_BASE,
        (br_stm32h7_syscfg_t *)BR_STM32H7_SYSCFG_BASE,
        (br_stm32h7_flash_t *)BR_STM32H7_FLASH_BASE,
    };
    br_status_t st = br_stm32h7_clock_480(&clk);
    if (st != BR_OK) {
        return st;
    }
    br_stm32_gpio_t *gpioa = (br_stm32_gpio_t *)BR_STM32H7_GPIOA_BASE;
    br_stm32_gpio_t *gpiob = (br_stm32_gpio_t *)BR_STM32H7_GPIOB_BASE;
    (void)br_stm32h7_rcc_enable((br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE);
    (void)br_stm32_gpio_af(gpioa, 0u, 1u);  /* TIM2_CH1 */
    (void)br_stm32_gpio_af(gpioa, 1u, 1u);  /* TIM2_CH2 */
    (void)br_stm32_gpio_af(gpioa, 8u, 1u);  /* TIM1_CH1 */
    (void)br_stm32_gpio_af(gpioa, 9u, 1u);  /* TIM1_CH2 */
    (void)br_stm32_gpio_af(gpiob, 13u, 1u); /* TIM1_CH1N */
    (void)br_stm32_gpio_af(gpiob, 14u, 1u); /* TIM1_CH2N */
    const br_stm32_cfg_t cfg = br_stm32h7_board_cfg(control_period_ns);
    st = br_stm32_init(port, &cfg);
    return (st != BR_OK) ? st : br_stm32_hal(port, hal);
}

br_status_t br_stm32h7_board_usart_init(br_stm32_usart_chan_t *u, uint8_t *rx, uint32_t rx_len, uint8_t *tx,
                                        uint32_t tx_len, uint32_t poll_period_ns)
{
    br_stm32_gpio_t *gpiod = (br_stm32_gpio_t *)BR_STM32H7_GPIOD_BASE;
    br_stm32_usart_cfg_t cfg = {
        .usart = (br_stm32_usart_t *)BR_STM32H7_USART3_BASE,
        .rx_buf = rx,
        .rx_len = rx_len,
        .tx_buf = tx,
        .tx_len = tx_len,
        .kernel_clock_hz = BR_BOARD_USART_HZ,
        .baud = BR_BOARD_USART_BAUD,
        .poll_period_ns = poll_period_ns,
    };
    br_status_t st = br_stm32h7_rcc_enable_usart3((br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE);
    if (st == BR_OK) {
        st = br_stm32h7_usart_dma((br_stm32h7_dma_t *)BR_STM32H7_DMA1_BASE, (br_stm32h7_dmamux_t *)BR_STM32H7_DMAMUX1_BASE,
                                  0u, 0u, 1u, BR_H7_DMAREQ_USART3_RX, BR_H7_DMAREQ_USART3_TX, &cfg);
    }
    if (st == BR_OK) {
        (void)br_stm32_gpio_af(gpiod, 8u, BR_BOARD_PIN_AF_USART3); /* USART3_TX */
        (void)br_stm32_gpio_af(gpiod, 9u, BR_BOARD_PIN_AF_USART3); /* USART3_RX */
        st = br_stm32_usart_init(u, &cfg);
    }
    return st;
}

int br_stm32h7_board_reset_by_watchdog(void)
{
    br_stm32h7_rcc_t *rcc = (br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE;
    const int wd = (rcc->RSR & BR_RCC_RSR_IWDG1RSTF) != 0u;
    rcc->RSR |= BR_RCC_RSR_RMVF;
    return wd;
}

br_status_t br_stm32h7_board_watchdog_start(void)
{
    return br_stm32_iwdg_start((br_stm32_iwdg_t *)BR_STM32H7_IWDG1_BASE, BR_BOARD_IWDG_PR, BR_BOARD_IWDG_RLR);
}

void br_stm32h7_board_watchdog_refresh(void)
{
    br_stm32_iwdg_refresh((br_stm32_iwdg_t *)BR_STM32H7_IWDG1_BASE);
}

void br_stm32h7_board_halt(br_stm32_t *port)
{
    (void)br_stm32_pwm_disable(port);
    for (;;) {
        __asm__ volatile("nop");
    }
}
