/* SPDX-License-Identifier: Apache-2.0 */
/* HAL port for the STM32G474 (Cortex-M4F, 170 MHz), the second port of
 * bristle (docs/porting.md): what is the G4's own on top of the shared STM32
 * driver (bristle/br_stm32.h: encoder, PWM, SysTick tick, deadline,
 * br_hal_t, GPIO, IWDG, over the core's conversions of bristle/br_port.h):
 * the clock tree from HSI16 to 170 MHz and the clock enables, on RM0440's
 * RCC, PWR and FLASH (br_stm32g4_regs.h). The board (board/) wires the
 * driver to TIM1 (PWM), TIM2 (encoder) and SysTick. docs/modules/hal.md. */
#ifndef BR_STM32G4_H
#define BR_STM32G4_H

#include <stdint.h>

#include "bristle/br_status.h"
#include "bristle/br_stm32.h"
#include "bristle/br_stm32_usart.h"
#include "bristle/br_stm32g4_regs.h"

/* Board helper: clock enables for GPIOA, GPIOB, TIM1, TIM2. */
br_status_t br_stm32g4_rcc_enable(br_stm32g4_rcc_t *rcc);

/* Board helper (the link): clock enables for DMA1, DMAMUX1 and USART2 (its
 * pins PA2 TX, PA3 RX are on GPIOA, enabled above). USART2's kernel clock
 * stays the reset's (PCLK1, 170 MHz). BR_E_NULL. */
br_status_t br_stm32g4_rcc_enable_usart2(br_stm32g4_rcc_t *rcc);

/* The G4's side of a USART channel (bristle/br_stm32_usart.h) on DMA1 or DMA2:
 * channels rx_ch and tx_ch as indices 0..7 (channel 1..8), rx_req and tx_req
 * routed to their DMAMUX channels (mux_base 0 for DMA1, 8 for DMA2), and
 * cfg's DMA fields filled: the channels, IFCR and the TX channel's clear
 * bits, the CR words (RX peripheral to memory, circular; TX memory to
 * peripheral; memory increment, bytes). Checks first (BR_E_NULL; BR_E_PARAM:
 * a channel above 7, the same twice, mux_base not 0 or 8, a request of 0 or
 * above 127), then writes. */
br_status_t br_stm32g4_usart_dma(br_stm32g4_dma_t *dma, br_stm32g4_dmamux_t *mux, uint32_t mux_base,
                                 uint32_t rx_ch, uint32_t tx_ch, uint32_t rx_req, uint32_t tx_req,
                                 br_stm32_usart_cfg_t *cfg);

/* Clock tree from the reset clock (HSI16) to 170 MHz (docs/modules/hal.md,
 * "STM32G474"): PWR clock on, range 1 boost (PWR_CR5.R1MODE = 0), flash 4
 * wait states with prefetch and caches, PLL = HSI16 / 4 * 85 / 2, AHB /2
 * across the switch (RM0440: a jump above 80 MHz goes through HCLK / 2 for
 * at least 1 us), SYSCLK = PLL, then AHB, APB1, APB2 /1 (timers 170 MHz).
 * Each wait is bounded (BR_STM32_WAIT_POLLS): BR_E_STATE if a ready flag
 * never comes. */
typedef struct {
    br_stm32g4_rcc_t *rcc;
    br_stm32g4_pwr_t *pwr;
    br_stm32g4_flash_t *flash;
} br_stm32g4_clock_regs_t;

#define BR_STM32G4_SYSCLK_HZ  170000000u
#define BR_STM32G4_TIMCLK_HZ  170000000u
#define BR_STM32G4_APB_HZ     170000000u  /* PCLK1 = PCLK2 = SYSCLK: USART2's kernel clock */
#define BR_STM32G4_PLL_M      4u
#define BR_STM32G4_PLL_N      85u
#define BR_STM32G4_FLASH_WS   4u
/* polls of SWS after the switch before HCLK goes back to /1: far more than
 * 1 us at 85 MHz (each poll is a bus read) */
#define BR_STM32G4_HPRE_HOLD_POLLS 200u

br_status_t br_stm32g4_clock_170(const br_stm32g4_clock_regs_t *r);

#endif
