/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32G474 board's table (br_board.h): its addresses, pins and clocks,
 * and the part functions it names. */
#include "br_board.h"

#define G4_RCC   ((br_stm32g4_rcc_t *)BR_STM32G4_RCC_BASE)
#define G4_GPIOA ((br_stm32_gpio_t *)BR_STM32G4_GPIOA_BASE)
#define G4_GPIOB ((br_stm32_gpio_t *)BR_STM32G4_GPIOB_BASE)

/* the clock tree to 170 MHz, then the timers' and pins' clock enables */
static br_status_t g4_clocks(void)
{
    const br_stm32g4_clock_regs_t clk = {
        G4_RCC,
        (br_stm32g4_pwr_t *)BR_STM32G4_PWR_BASE,
        (br_stm32g4_flash_t *)BR_STM32G4_FLASH_BASE,
    };
    const br_status_t st = br_stm32g4_clock_170(&clk);
    return (st != BR_OK) ? st : br_stm32g4_rcc_enable(G4_RCC);
}

/* USART2's clocks, DMA1 channels 1 (RX) and 2 (TX) routed by DMAMUX */
static br_status_t g4_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    const br_status_t st = br_stm32g4_rcc_enable_usart2(G4_RCC);
    return (st != BR_OK) ? st
                         : br_stm32g4_usart_dma((br_stm32g4_dma_t *)BR_STM32G4_DMA1_BASE,
                                                (br_stm32g4_dmamux_t *)BR_STM32G4_DMAMUX1_BASE, 0u, 0u, 1u,
                                                BR_G4_DMAREQ_USART2_RX, BR_G4_DMAREQ_USART2_TX, cfg);
}

/* RCC_CSR: IWDGRSTF, then RMVF so that the next pin or power-on reset reads as such */
static int g4_reset_by_watchdog(void)
{
    br_stm32g4_rcc_t *const rcc = G4_RCC;
    const int wd = (rcc->CSR & BR_G4_RCC_CSR_IWDGRSTF) != 0u;
    rcc->CSR |= BR_G4_RCC_CSR_RMVF;
    return wd;
}

const br_stm32_board_t br_board = {
    .clocks = g4_clocks,
    .port = {
        .pwm_tim = (br_stm32_tim_t *)BR_STM32G4_TIM1_BASE,
        .enc_tim = (br_stm32_tim_t *)BR_STM32G4_TIM2_BASE,
        .systick = (br_stm32_systick_t *)BR_STM32G4_SYSTICK_BASE,
        .cpu_clock_hz = BR_BOARD_CPU_HZ,
        .tim_clock_hz = BR_BOARD_TIM_HZ,
        .pwm_hz = BR_BOARD_PWM_HZ,
        .enc_counter_bits = 32u,
        .enc_filter = BR_BOARD_ENC_FILTER,
        .deadtime_ticks = BR_BOARD_DEADTIME,
    },
    .pins = {
        {G4_GPIOA, 0u, BR_BOARD_PIN_AF_TIM2},  /* TIM2_CH1 */
        {G4_GPIOA, 1u, BR_BOARD_PIN_AF_TIM2},  /* TIM2_CH2 */
        {G4_GPIOA, 8u, BR_BOARD_PIN_AF_TIM1},  /* TIM1_CH1 */
        {G4_GPIOA, 9u, BR_BOARD_PIN_AF_TIM1},  /* TIM1_CH2 */
        {G4_GPIOB, 13u, BR_BOARD_PIN_AF_TIM1}, /* TIM1_CH1N */
        {G4_GPIOB, 14u, BR_BOARD_PIN_AF_TIM1}, /* TIM1_CH2N */
    },
    .n_pins = 6u,
    .usart_dma = g4_usart_dma,
    .usart = (br_stm32_usart_t *)BR_STM32G4_USART2_BASE,
    .usart_clock_hz = BR_BOARD_USART_HZ,
    .baud = BR_BOARD_USART_BAUD,
    .usart_pins = {
        {G4_GPIOA, 2u, BR_BOARD_PIN_AF_USART2}, /* USART2_TX */
        {G4_GPIOA, 3u, BR_BOARD_PIN_AF_USART2}, /* USART2_RX */
    },
    .iwdg = (br_stm32_iwdg_t *)BR_STM32G4_IWDG_BASE,
    .iwdg_pr = BR_BOARD_IWDG_PR,
    .iwdg_rlr = BR_BOARD_IWDG_RLR,
    .reset_by_watchdog = g4_reset_by_watchdog,
};
