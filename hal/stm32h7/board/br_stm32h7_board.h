/* SPDX-License-Identifier: Apache-2.0 */
/* The board: how the STM32H743 of the bristle image is wired and clocked.
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
#ifndef BR_STM32H7_BOARD_H
#define BR_STM32H7_BOARD_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_stm32h7.h"

#define BR_BOARD_CPU_HZ     BR_STM32H7_SYSCLK_HZ  /* 480 MHz, PLL1 */
#define BR_BOARD_TIM_HZ     BR_STM32H7_TIMCLK_HZ  /* 240 MHz: APB1/APB2 timers at 2 x 120 MHz */
#define BR_BOARD_PWM_HZ     20000u
#define BR_BOARD_DEADTIME   120u      /* timer ticks: 500 ns at 240 MHz */
#define BR_BOARD_ENC_FILTER 3u        /* f_CK_INT, N = 8 */
#define BR_BOARD_USART_BAUD 921600u
#define BR_BOARD_USART_HZ   BR_STM32H7_APB_HZ /* USART3's kernel clock: rcc_pclk1 */
#define BR_BOARD_PIN_AF_USART3 7u
/* IWDG1 on the LSI (32 kHz): prescaler /4 (PR = 0), 80 ticks -> 10 ms */
#define BR_BOARD_IWDG_PR    0u
#define BR_BOARD_IWDG_RLR   79u

/* The port configuration of this board (peripheral bases, clocks, PWM,
 * encoder) for a control period of control_period_ns (a whole number of
 * 480 MHz cycles). */
br_stm32_cfg_t br_stm32h7_board_cfg(uint32_t control_period_ns);

/* Brings the board up: the clock tree (br_stm32h7_clock_480), peripheral
 * clocks, pins to their timers, then the port (outputs off until the arm;
 * br_stm32_init validates the configuration before writing a timer
 * register) and its br_hal_t. The first failing status. */
br_status_t br_stm32h7_board_init(br_stm32_t *port, uint32_t control_period_ns, br_hal_t *hal);

/* The link's byte channel: USART3's clocks and pins, DMA1 streams 0 (RX) and
 * 1 (TX) routed by DMAMUX1, then br_stm32_usart_init over rx (rx_len bytes,
 * circular) and tx (tx_len), both in RAM DMA1 reaches (AXI SRAM, not DTCM),
 * read at least every poll_period_ns. The first failing status. */
br_status_t br_stm32h7_board_usart_init(br_stm32_usart_chan_t *u, uint8_t *rx, uint32_t rx_len, uint8_t *tx,
                                        uint32_t tx_len, uint32_t poll_period_ns);

/* 1 when the last reset came from IWDG1 (a hung or faulted control loop);
 * clears the reset flags (RMVF) so that the next pin or power-on reset reads
 * as such. */
int br_stm32h7_board_reset_by_watchdog(void);

/* Starts IWDG1 (BR_BOARD_IWDG_*) and refreshes it. */
br_status_t br_stm32h7_board_watchdog_start(void);
void br_stm32h7_board_watchdog_refresh(void);

/* Motor stopped and outputs off (br_stm32_pwm_disable); then parks without
 * refreshing the watchdog: a running IWDG1 resets the part, which then comes
 * up with its outputs off (br_stm32h7_board_reset_by_watchdog). */
void br_stm32h7_board_halt(br_stm32_t *port) __attribute__((noreturn));

#endif
