/* SPDX-License-Identifier: Apache-2.0 */
/* The board: how the STM32G474 of the bristle G4 image is wired and clocked,
 * as the table the shared image reads (bristle/br_stm32_board.h,
 * hal/stm32/image/br_image_main.c; docs/porting.md, "Adding a board").
 *
 * Pins (RM0440 / the G474 datasheet's alternate-function table): TIM2
 * encoder on PA0 (CH1) / PA1 (CH2), AF1; TIM1 PWM on PA8 (CH1), PA9 (CH2),
 * PB13 (CH1N), PB14 (CH2N), AF6; the control tick is SysTick.
 * Clocks: br_stm32g4_clock_170 takes the part from HSI16 to 170 MHz (range 1
 * boost, flash 4 WS, PLL = HSI16 / 4 * 85 / 2), AHB = APB1 = APB2 = 170 MHz,
 * timer kernel clocks 170 MHz. PWM 20 kHz centre-aligned with 500 ns dead
 * time, encoder input filter f_CK_INT with N = 8. IWDG: 10 ms. The link:
 * USART2 on PA2 (TX) / PA3 (RX), AF7 (the ST-LINK's virtual COM port on a
 * Nucleo-64 board), 921 600 baud 8N1 from its reset kernel clock (PCLK1,
 * 170 MHz: BRR 184, 0.25 % slow), by DMA1 channel 1 (RX, circular) and
 * channel 2 (TX). No enable input. The pins, the AF numbers and the DMAMUX
 * requests are written from the manual's tables, not yet checked on a part
 * (docs/porting.md).
 * docs/modules/hal.md, "STM32G474". */
#ifndef BR_BOARD_H
#define BR_BOARD_H

#include <stdint.h>

#include "bristle/br_stm32_board.h"
#include "bristle/br_stm32g4.h"

#define BR_BOARD_CPU_HZ     BR_STM32G4_SYSCLK_HZ  /* 170 MHz, PLL */
#define BR_BOARD_TIM_HZ     BR_STM32G4_TIMCLK_HZ  /* 170 MHz: APB prescalers 1 */
#define BR_BOARD_PWM_HZ     20000u
#define BR_BOARD_DEADTIME   85u       /* timer ticks: 500 ns at 170 MHz */
#define BR_BOARD_ENC_FILTER 3u        /* f_CK_INT, N = 8 */
#define BR_BOARD_USART_BAUD 921600u
#define BR_BOARD_USART_HZ   BR_STM32G4_APB_HZ /* USART2's kernel clock: PCLK1 */
#define BR_BOARD_PIN_AF_TIM2 1u
#define BR_BOARD_PIN_AF_TIM1 6u
#define BR_BOARD_PIN_AF_USART2 7u
/* IWDG on the LSI (32 kHz): prescaler /4 (PR = 0), 80 ticks -> 10 ms */
#define BR_BOARD_IWDG_PR    0u
#define BR_BOARD_IWDG_RLR   79u

/* What the shared image needs at compile time (hal/stm32/image): */
/* the PF does not run in its period on this core: at 1500 particles its
 * period takes more instructions than 1.5 ms has cycles at 170 MHz, while
 * H-inf + UKF takes a few percent of 1 ms (the Cortex-M4 figures of `make
 * target-bench`: docs/target.md, "Current figures") */
#define BR_BOARD_RUNS_PF 0
/* the recorder's ring and the USART's DMA buffers in SRAM1 + SRAM2: the DMA
 * does not reach the CCM SRAM that holds the stack; NOLOAD, zeroed by the
 * startup (stm32g474.ld's .xram) */
#define BR_BOARD_XRAM __attribute__((section(".xram")))
/* the recorder: 2000 samples (58 000 bytes of the 96 KiB; 2 s at 1 ms), 1500
 * of them before the trigger */
#define BR_BOARD_REC_SAMPLES 2000u
#define BR_BOARD_REC_PRE     1500u
/* the startup (hal/stm32/image/br_startup.c): the 102 interrupt lines of
 * RM0440's vector table; no cache on the M4 (the flash's ART accelerator is
 * enabled with the wait states, br_stm32g4_clock_170) */
#define BR_BOARD_IRQ_VECTORS 102
/* ... each parked: BR_DEF (one), BR_DEF_X50 (fifty) of the startup */
#define BR_BOARD_IRQ_PARKED  BR_DEF_X50, BR_DEF_X50, BR_DEF, BR_DEF
#define BR_BOARD_ICACHE      0

/* The table's values (hal/stm32/image/br_board_table.c): the blocks, the
 * timers' pins (TIM2_CH1, TIM2_CH2, TIM1_CH1, TIM1_CH2, TIM1_CH1N, TIM1_CH2N)
 * and the link's (TX, RX) */
#define BR_BOARD_GPIO(port) ((br_stm32_gpio_t *)BR_STM32G4_GPIO##port##_BASE)
#define BR_BOARD_PWM_TIM_BASE BR_STM32G4_TIM1_BASE
#define BR_BOARD_ENC_TIM_BASE BR_STM32G4_TIM2_BASE
#define BR_BOARD_TIM_PINS                                                                                 \
    {BR_BOARD_GPIO(A), 0u, BR_BOARD_PIN_AF_TIM2}, {BR_BOARD_GPIO(A), 1u, BR_BOARD_PIN_AF_TIM2},                     \
    {BR_BOARD_GPIO(A), 8u, BR_BOARD_PIN_AF_TIM1}, {BR_BOARD_GPIO(A), 9u, BR_BOARD_PIN_AF_TIM1},                     \
    {BR_BOARD_GPIO(B), 13u, BR_BOARD_PIN_AF_TIM1}, {BR_BOARD_GPIO(B), 14u, BR_BOARD_PIN_AF_TIM1}
#define BR_BOARD_N_TIM_PINS 6u
#define BR_BOARD_USART_BASE BR_STM32G4_USART2_BASE
#define BR_BOARD_USART_PINS {BR_BOARD_GPIO(A), 2u, BR_BOARD_PIN_AF_USART2}, {BR_BOARD_GPIO(A), 3u, BR_BOARD_PIN_AF_USART2}
#define BR_BOARD_IWDG_BASE BR_STM32G4_IWDG_BASE

/* the board's part functions (its board/br_<part>_board.c), named in the
 * table (hal/stm32/image/br_board_table.c): the clock tree and the timers'
 * and pins' clock enables; the USART's clock enables and DMA routing; 1 when
 * the last reset came from the watchdog (the reset flags then cleared) */
br_status_t br_board_clocks(void);
br_status_t br_board_usart_dma(br_stm32_usart_cfg_t *cfg);
int br_board_reset_by_watchdog(void);

/* the board's table */
extern const br_stm32_board_t br_board;

#endif
