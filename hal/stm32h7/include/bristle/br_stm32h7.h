/* SPDX-License-Identifier: Apache-2.0 */
/* HAL port for the STM32H743 (Cortex-M7, 480 MHz): what is the H7's own on
 * top of the shared STM32 driver (bristle/br_stm32.h: encoder, PWM, SysTick
 * tick, deadline, br_hal_t, GPIO, IWDG): the clock tree from HSI 64 MHz to
 * 480 MHz and the clock enables of the timers and pins, on RM0433's RCC,
 * PWR, SYSCFG and FLASH (br_stm32h7_regs.h). The board (board/) wires the
 * driver to TIM1 (PWM), TIM2 (encoder) and SysTick. See docs/modules/hal.md. */
#ifndef BR_STM32H7_H
#define BR_STM32H7_H

#include <stdint.h>
#include "bristle/br_status.h"
#include "bristle/br_stm32.h"
#include "bristle/br_stm32h7_regs.h"

/* Board helper (used by the image): clock enables for GPIOA, GPIOB, TIM1, TIM2. */
br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc);

/* Clock tree from the reset clock (HSI 64 MHz) to 480 MHz (docs/modules/hal.md,
 * "Clocks"): LDO supply, VOS1 then VOS0 (SYSCFG ODEN), flash 4 wait states
 * (WRHIGHFREQ 2), PLL1 = HSI / 4 * 60 / 2 (ref 16 MHz, VCO 960 MHz), D1CPRE /1,
 * HPRE /2 (AXI/AHB 240 MHz), APB1..4 /2 (120 MHz; timers 240 MHz), then
 * SYSCLK = PLL1. Each wait is bounded (BR_STM32_WAIT_POLLS): BR_E_STATE if a
 * ready flag never comes (the system clock is then not switched), BR_E_NULL
 * for a NULL block. */
typedef struct {
    br_stm32h7_rcc_t *rcc;
    br_stm32h7_pwr_t *pwr;
    br_stm32h7_syscfg_t *syscfg;
    br_stm32h7_flash_t *flash;
} br_stm32h7_clock_regs_t;

#define BR_STM32H7_SYSCLK_HZ 480000000u
#define BR_STM32H7_HCLK_HZ   240000000u
#define BR_STM32H7_APB_HZ    120000000u
#define BR_STM32H7_TIMCLK_HZ 240000000u
#define BR_STM32H7_PLL1_DIVM 4u
#define BR_STM32H7_PLL1_DIVN 60u
#define BR_STM32H7_PLL1_DIVP 2u
#define BR_STM32H7_FLASH_WS  4u
#define BR_STM32H7_FLASH_WRHIGHFREQ 2u

br_status_t br_stm32h7_clock_480(const br_stm32h7_clock_regs_t *r);

#endif
