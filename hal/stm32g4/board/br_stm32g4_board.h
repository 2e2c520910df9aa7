/* SPDX-License-Identifier: Apache-2.0 */
/* The board: how the STM32G474 of the bristle G4 image is wired and clocked.
 *
 * Pins (RM0440 / the G474 datasheet's alternate-function table): TIM2
 * encoder on PA0 (CH1) / PA1 (CH2), AF1; TIM1 PWM on PA8 (CH1), PA9 (CH2),
 * PB13 (CH1N), PB14 (CH2N), AF6; the control tick is SysTick.
 * Clocks: br_stm32g4_clock_170 takes the part from HSI16 to 170 MHz (range 1
 * boost, flash 4 WS, PLL = HSI16 / 4 * 85 / 2), AHB = APB1 = APB2 = 170 MHz,
 * timer kernel clocks 170 MHz. PWM 20 kHz centre-aligned with 500 ns dead
 * time, encoder input filter f_CK_INT with N = 8. IWDG: 10 ms.
 * docs/modules/hal.md, "STM32G474". */
#ifndef BR_STM32G4_BOARD_H
#define BR_STM32G4_BOARD_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_stm32g4.h"

#define BR_G4_BOARD_CPU_HZ     BR_STM32G4_SYSCLK_HZ  /* 170 MHz, PLL */
#define BR_G4_BOARD_TIM_HZ     BR_STM32G4_TIMCLK_HZ  /* 170 MHz: APB prescalers 1 */
#define BR_G4_BOARD_PWM_HZ     20000u
#define BR_G4_BOARD_DEADTIME   85u       /* timer ticks: 500 ns at 170 MHz */
#define BR_G4_BOARD_ENC_FILTER 3u        /* f_CK_INT, N = 8 */
#define BR_G4_BOARD_PIN_AF_TIM2 1u
#define BR_G4_BOARD_PIN_AF_TIM1 6u
/* IWDG on the LSI (32 kHz): prescaler /4 (PR = 0), 80 ticks -> 10 ms */
#define BR_G4_BOARD_IWDG_PR    0u
#define BR_G4_BOARD_IWDG_RLR   79u

/* The port configuration of this board for a control period of
 * control_period_ns (a whole number of 170 MHz cycles). */
br_stm32_cfg_t br_stm32g4_board_cfg(uint32_t control_period_ns);

/* Clock tree, peripheral clocks, pins, then the port (outputs off until the
 * arm) and its br_hal_t. The first failing status. */
br_status_t br_stm32g4_board_init(br_stm32_t *port, uint32_t control_period_ns, br_hal_t *hal);

/* 1 when the last reset came from the IWDG; clears the reset flags (RMVF). */
int br_stm32g4_board_reset_by_watchdog(void);

br_status_t br_stm32g4_board_watchdog_start(void);
void br_stm32g4_board_watchdog_refresh(void);

/* Outputs off (br_stm32_pwm_disable), then park without refreshing the
 * watchdog: a running IWDG resets the part, which comes up with its outputs
 * off and stays off after a watchdog reset. */
void br_stm32g4_board_halt(br_stm32_t *port) __attribute__((noreturn));

#endif
