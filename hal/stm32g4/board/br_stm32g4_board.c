/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32G474 board's part functions (br_board.h), named in its table
 * (hal/stm32/image/br_board_table.c). */
#include "br_board.h"

#define G4_RCC   ((br_stm32g4_rcc_t *)BR_STM32G4_RCC_BASE)

/* the clock tree to 170 MHz, then the timers' and pins' clock enables */
br_status_t br_board_clocks(void)
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
br_status_t br_board_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    const br_status_t st = br_stm32g4_rcc_enable_usart2(G4_RCC);
    return (st != BR_OK) ? st
                         : br_stm32g4_usart_dma((br_stm32g4_dma_t *)BR_STM32G4_DMA1_BASE,
                                                (br_stm32g4_dmamux_t *)BR_STM32G4_DMAMUX1_BASE, 0u, 0u, 1u,
                                                BR_G4_DMAREQ_USART2_RX, BR_G4_DMAREQ_USART2_TX, cfg);
}

/* RCC_CSR: IWDGRSTF, then RMVF so that the next pin or power-on reset reads as such */
int br_board_reset_by_watchdog(void)
{
    br_stm32g4_rcc_t *const rcc = G4_RCC;
    const int wd = (rcc->CSR & BR_G4_RCC_CSR_IWDGRSTF) != 0u;
    rcc->CSR |= BR_G4_RCC_CSR_RMVF;
    return wd;
}
