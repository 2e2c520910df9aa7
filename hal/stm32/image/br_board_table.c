/* SPDX-License-Identifier: Apache-2.0 */
/* The board's table (bristle/br_stm32_board.h), written once for every STM32
 * board from the values of its br_board.h (hal/<part>/board: addresses,
 * clocks, pins, the watchdog) and its three part functions (br_board.h's
 * br_board_clocks, br_board_usart_dma, br_board_reset_by_watchdog). */
#include "br_board.h"

const br_stm32_board_t br_board = {
    .clocks = br_board_clocks,
    .port = {
        .pwm_tim = (br_stm32_tim_t *)BR_BOARD_PWM_TIM_BASE,
        .enc_tim = (br_stm32_tim_t *)BR_BOARD_ENC_TIM_BASE,
        .systick = (br_stm32_systick_t *)BR_STM32_SYSTICK_BASE,
        .cpu_clock_hz = BR_BOARD_CPU_HZ,
        .tim_clock_hz = BR_BOARD_TIM_HZ,
        .pwm_hz = BR_BOARD_PWM_HZ,
        .enc_counter_bits = 32u,
        .enc_filter = BR_BOARD_ENC_FILTER,
        .deadtime_ticks = BR_BOARD_DEADTIME,
    },
    .pins = {BR_BOARD_TIM_PINS},
    .n_pins = BR_BOARD_N_TIM_PINS,
    .usart_dma = br_board_usart_dma,
    .usart = (br_stm32_usart_t *)BR_BOARD_USART_BASE,
    .usart_clock_hz = BR_BOARD_USART_HZ,
    .baud = BR_BOARD_USART_BAUD,
    .usart_pins = {BR_BOARD_USART_PINS},
    .iwdg = (br_stm32_iwdg_t *)BR_BOARD_IWDG_BASE,
    .iwdg_pr = BR_BOARD_IWDG_PR,
    .iwdg_rlr = BR_BOARD_IWDG_RLR,
    .reset_by_watchdog = br_board_reset_by_watchdog,
};
