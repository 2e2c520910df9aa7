/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32H743 board's table (br_board.h): its addresses, pins and clocks,
 * and the part functions it names. */
#include "br_board.h"

#define H7_RCC   ((br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE)
#define H7_GPIOA ((br_stm32_gpio_t *)BR_STM32H7_GPIOA_BASE)
#define H7_GPIOB ((br_stm32_gpio_t *)BR_STM32H7_GPIOB_BASE)
#define H7_GPIOD ((br_stm32_gpio_t *)BR_STM32H7_GPIOD_BASE)

/* the clock tree to 480 MHz, then the timers' and pins' clock enables */
static br_status_t h7_clocks(void)
{
    const br_stm32h7_clock_regs_t clk = {
        H7_RCC,
        (br_stm32h7_pwr_t *)BR_STM32H7_PWR_BASE,
        (br_stm32h7_syscfg_t *)BR_STM32H7_SYSCFG_BASE,
        (br_stm32h7_flash_t *)BR_STM32H7_FLASH_BASE,
    };
    const br_status_t st = br_stm32h7_clock_480(&clk);
    return (st != BR_OK) ? st : br_stm32h7_rcc_enable(H7_RCC);
}

/* USART3's clocks, DMA1 streams 0 (RX) and 1 (TX) routed by DMAMUX1 */
static br_status_t h7_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    const br_status_t st = br_stm32h7_rcc_enable_usart3(H7_RCC);
    return (st != BR_OK) ? st
                         : br_stm32h7_usart_dma((br_stm32h7_dma_t *)BR_STM32H7_DMA1_BASE,
                                                (br_stm32h7_dmamux_t *)BR_STM32H7_DMAMUX1_BASE, 0u, 0u, 1u,
                                                BR_H7_DMAREQ_USART3_RX, BR_H7_DMAREQ_USART3_TX, cfg);
}

/* RCC_RSR: IWDG1RSTF, then RMVF so that the next pin or power-on reset reads as such */
static int h7_reset_by_watchdog(void)
{
    br_stm32h7_rcc_t *const rcc = H7_RCC;
    const int wd = (rcc->RSR & BR_RCC_RSR_IWDG1RSTF) != 0u;
    rcc->RSR |= BR_RCC_RSR_RMVF;
    return wd;
}

const br_stm32_board_t br_board = {
    .clocks = h7_clocks,
    .port = {
        .pwm_tim = (br_stm32_tim_t *)BR_STM32H7_TIM1_BASE,
        .enc_tim = (br_stm32_tim_t *)BR_STM32H7_TIM2_BASE,
        .systick = (br_stm32_systick_t *)BR_STM32H7_SYSTICK_BASE,
        .cpu_clock_hz = BR_BOARD_CPU_HZ,
        .tim_clock_hz = BR_BOARD_TIM_HZ,
        .pwm_hz = BR_BOARD_PWM_HZ,
        .enc_counter_bits = 32u,
        .enc_filter = BR_BOARD_ENC_FILTER,
        .deadtime_ticks = BR_BOARD_DEADTIME,
    },
    .pins = {
        {H7_GPIOA, 0u, BR_BOARD_PIN_AF_TIM},  /* TIM2_CH1 */
        {H7_GPIOA, 1u, BR_BOARD_PIN_AF_TIM},  /* TIM2_CH2 */
        {H7_GPIOA, 8u, BR_BOARD_PIN_AF_TIM},  /* TIM1_CH1 */
        {H7_GPIOA, 9u, BR_BOARD_PIN_AF_TIM},  /* TIM1_CH2 */
        {H7_GPIOB, 13u, BR_BOARD_PIN_AF_TIM}, /* TIM1_CH1N */
        {H7_GPIOB, 14u, BR_BOARD_PIN_AF_TIM}, /* TIM1_CH2N */
    },
    .n_pins = 6u,
    .usart_dma = h7_usart_dma,
    .usart = (br_stm32_usart_t *)BR_STM32H7_USART3_BASE,
    .usart_clock_hz = BR_BOARD_USART_HZ,
    .baud = BR_BOARD_USART_BAUD,
    .usart_pins = {
        {H7_GPIOD, 8u, BR_BOARD_PIN_AF_USART3}, /* USART3_TX */
        {H7_GPIOD, 9u, BR_BOARD_PIN_AF_USART3}, /* USART3_RX */
    },
    .iwdg = (br_stm32_iwdg_t *)BR_STM32H7_IWDG1_BASE,
    .iwdg_pr = BR_BOARD_IWDG_PR,
    .iwdg_rlr = BR_BOARD_IWDG_RLR,
    .reset_by_watchdog = h7_reset_by_watchdog,
};
