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
#include "bristle/br_stm32_usart.h"
#include "bristle/br_stm32h7_regs.h"

/* Board helper (used by the image): clock enables for GPIOA, GPIOB, TIM1, TIM2. */
br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc);

/* Board helper (the link): clock enables for DMA1, USART3 and GPIOD (its
 * pins PD8 TX, PD9 RX). The USART3 kernel clock stays the reset's
 * (rcc_pclk1, BR_STM32H7_APB_HZ). BR_E_NULL. */
br_status_t br_stm32h7_rcc_enable_usart3(br_stm32h7_rcc_t *rcc);

/* The H7's side of a USART channel (bristle/br_stm32_usart.h) on DMA1 or DMA2:
 * routes rx_req to the DMAMUX1 channel of stream rx_stream and tx_req to
 * tx_stream's (mux_base 0 for DMA1, 8 for DMA2), puts both streams in direct
 * mode (FCR 0), and fills cfg's DMA fields: the streams, the TX stream's
 * flag-clear register and bits, the CR words (RX peripheral to memory,
 * circular; TX memory to peripheral; memory increment, bytes). Checks first
 * (BR_E_NULL; BR_E_PARAM: a stream above 7, the same stream twice, mux_base
 * not 0 or 8, a request of 0 or above 255), then writes. */
br_status_t br_stm32h7_usart_dma(br_stm32h7_dma_t *dma, br_stm32h7_dmamux_t *mux, uint32_t mux_base,
                                 uint32_t rx_stream, uint32_t tx_stream, uint32_t rx_req, uint32_t tx_req,
                                 br_stm32_usart_cfg_t *cfg);

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
