/* SPDX-License-Identifier: Apache-2.0 */
/* The board: how the STM32H743 of the bristle image is wired and clocked,
 * as the table the shared image reads (bristle/br_stm32_board.h,
 * hal/stm32/image/br_image_main.c; docs/porting.md, "Adding a board").
 *
 * Pins (RM0433, all AF1): TIM2 encoder on PA0 (CH1) / PA1 (CH2); TIM1 PWM on
 * PA8 (CH1), PA9 (CH2), PB13 (CH1N), PB14 (CH2N); the control tick is SysTick.
 * Clocks: br_stm32h7_clock_480 brings the part from the reset clock (HSI
 * 64 MHz) to 480 MHz (VOS0, flash 4 WS, PLL1 = HSI / 4 * 60 / 2), AXI/AHB
 * 240 MHz, APB 120 MHz, timer kernel clocks 240 MHz. PWM 20 kHz
 * centre-aligned with 500 ns dead time, encoder input filter f_CK_INT with
 * N = 8. Watchdog IWDG1: 10 ms. The link: USART3 on PD8 (TX) / PD9 (RX), AF7
 * (the ST-LINK's virtual COM port on a Nucleo-144 board), 921 600 baud 8N1
 * from its reset kernel clock (rcc_pclk1, 120 MHz: BRR 130, 0.16 % fast), by
 * DMA1 stream 0 (RX, circular) and stream 1 (TX). No enable input.
 * docs/modules/hal.md, docs/porting.md. */
#ifndef BR_BOARD_H
#define BR_BOARD_H

#include <stdint.h>

#include "bristle/br_stm32_board.h"
#include "bristle/br_stm32h7.h"

#define BR_BOARD_CPU_HZ     BR_STM32H7_SYSCLK_HZ  /* 480 MHz, PLL1 */
#define BR_BOARD_TIM_HZ     BR_STM32H7_TIMCLK_HZ  /* 240 MHz: APB1/APB2 timers at 2 x 120 MHz */
#define BR_BOARD_PWM_HZ     20000u
#define BR_BOARD_DEADTIME   120u      /* timer ticks: 500 ns at 240 MHz */
#define BR_BOARD_ENC_FILTER 3u        /* f_CK_INT, N = 8 */
#define BR_BOARD_USART_BAUD 921600u
#define BR_BOARD_USART_HZ   BR_STM32H7_APB_HZ /* USART3's kernel clock: rcc_pclk1 */
#define BR_BOARD_PIN_AF_TIM 1u
#define BR_BOARD_PIN_AF_USART3 7u
/* IWDG1 on the LSI (32 kHz): prescaler /4 (PR = 0), 80 ticks -> 10 ms */
#define BR_BOARD_IWDG_PR    0u
#define BR_BOARD_IWDG_RLR   79u

/* What the shared image needs at compile time (hal/stm32/image): */
/* the PF runs in its period on this core: at 1500 particles under half of
 * the 720 000 cycles of 1.5 ms (`make target-bench`: docs/target.md,
 * "Current figures") */
#define BR_BOARD_RUNS_PF 1
/* the big statics (the PF's state, the recorder's ring, the USART's DMA
 * buffers) in AXI SRAM: DMA1 does not reach the DTCM that holds the stack;
 * NOLOAD, zeroed by the startup (stm32h743.ld's .xram) */
#define BR_BOARD_XRAM __attribute__((section(".xram")))
/* the recorder: 8000 samples (232 000 bytes of the 512 KiB AXI SRAM; 8 s at
 * 1 ms), 6000 of them before the trigger */
#define BR_BOARD_REC_SAMPLES 8000u
#define BR_BOARD_REC_PRE     6000u
/* the startup (hal/stm32/image/br_startup.c): the 150 interrupt lines of
 * RM0433's vector table; the M7's instruction cache enabled */
#define BR_BOARD_IRQ_VECTORS 150
/* ... each parked: BR_DEF (one), BR_DEF_X50 (fifty) of the startup */
#define BR_BOARD_IRQ_PARKED  BR_DEF_X50, BR_DEF_X50, BR_DEF_X50
#define BR_BOARD_ICACHE      1

/* The table's values (hal/stm32/image/br_board_table.c): the blocks, the
 * timers' pins (TIM2_CH1, TIM2_CH2, TIM1_CH1, TIM1_CH2, TIM1_CH1N, TIM1_CH2N)
 * and the link's (TX, RX) */
#define BR_BOARD_GPIO(port) ((br_stm32_gpio_t *)BR_STM32H7_GPIO##port##_BASE)
#define BR_BOARD_PWM_TIM_BASE BR_STM32H7_TIM1_BASE
#define BR_BOARD_ENC_TIM_BASE BR_STM32H7_TIM2_BASE
#define BR_BOARD_TIM_PINS                                                                                 \
    {BR_BOARD_GPIO(A), 0u, BR_BOARD_PIN_AF_TIM}, {BR_BOARD_GPIO(A), 1u, BR_BOARD_PIN_AF_TIM},                     \
    {BR_BOARD_GPIO(A), 8u, BR_BOARD_PIN_AF_TIM}, {BR_BOARD_GPIO(A), 9u, BR_BOARD_PIN_AF_TIM},                     \
    {BR_BOARD_GPIO(B), 13u, BR_BOARD_PIN_AF_TIM}, {BR_BOARD_GPIO(B), 14u, BR_BOARD_PIN_AF_TIM}
#define BR_BOARD_N_TIM_PINS 6u
#define BR_BOARD_USART_BASE BR_STM32H7_USART3_BASE
#define BR_BOARD_USART_PINS {BR_BOARD_GPIO(D), 8u, BR_BOARD_PIN_AF_USART3}, {BR_BOARD_GPIO(D), 9u, BR_BOARD_PIN_AF_USART3}
#define BR_BOARD_IWDG_BASE BR_STM32H7_IWDG1_BASE

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
