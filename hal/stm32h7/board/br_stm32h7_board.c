/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32H743 board's part functions (br_board.h), named in its table
 * (hal/stm32/image/br_board_table.c). */
#include "br_board.h"

#define H7_RCC   ((br_stm32h7_rcc_t *)BR_STM32H7_RCC_BASE)

/* the clock tree to 480 MHz, then the timers' and pins' clock enables */
br_status_t br_board_clocks(void)
{
    const br_stm32h7_clock_regs_t clk = {
        H7_RCC,
        (br_stm32h7_pwr_t *)BR_STM32H7_PWR_BASE,
        (br_stm32h7_syscfg_t *)BR_STM32H7_SYSCFG_BASE,
        (br_stm32h7_flash_t *)BR_STM32H7_FLASH_BASE,
    };
    const br_status_t st = br_stm32h7_clock_480(&clk);
    return (st != BR_OK) ? st : br_stm32h7_rcc_enable(H7_RCC);
}

/* USART3's clocks, DMA1 streams 0 (RX) and 1 (TX) routed by DMAMUX1 */
br_status_t br_board_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    const br_status_t st = br_stm32h7_rcc_enable_usart3(H7_RCC);
    return (st != BR_OK) ? st
                         : br_stm32h7_usart_dma((br_stm32h7_dma_t *)BR_STM32H7_DMA1_BASE,
                                                (br_stm32h7_dmamux_t *)BR_STM32H7_DMAMUX1_BASE, 0u, 0u, 1u,
                                                BR_H7_DMAREQ_USART3_RX, BR_H7_DMAREQ_USART3_TX, cfg);
}

/* RCC_RSR: IWDG1RSTF, then RMVF so that the next pin or power-on reset reads as such */
int br_board_reset_by_watchdog(void)
{
    br_stm32h7_rcc_t *const rcc = H7_RCC;
    const int wd = (rcc->RSR & BR_RCC_RSR_IWDG1RSTF) != 0u;
    rcc->RSR |= BR_RCC_RSR_RMVF;
    return wd;
}
