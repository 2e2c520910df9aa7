/* SPDX-License-Identifier: Apache-2.0 */
/* STM32G474 port: the clock tree and the clock enables (br_stm32g4.h) on
 * RM0440's map; the encoder, PWM, tick and watchdog are the shared STM32
 * driver's (hal/stm32, bristle/br_stm32.h). Pure C99 on register-block
 * pointers: it builds for the part and for host tests on fake registers. */
#include "bristle/br_stm32g4.h"

#include <stddef.h>

/* Layout checks against the RM0440 register maps. */
BR_STM32_LAYOUT_CHECK(rcc_cfgr, offsetof(br_stm32g4_rcc_t, CFGR) == 0x08u);
BR_STM32_LAYOUT_CHECK(rcc_pllcfgr, offsetof(br_stm32g4_rcc_t, PLLCFGR) == 0x0Cu);
BR_STM32_LAYOUT_CHECK(rcc_ahb2enr, offsetof(br_stm32g4_rcc_t, AHB2ENR) == 0x4Cu);
BR_STM32_LAYOUT_CHECK(rcc_apb1enr1, offsetof(br_stm32g4_rcc_t, APB1ENR1) == 0x58u);
BR_STM32_LAYOUT_CHECK(rcc_apb2enr, offsetof(br_stm32g4_rcc_t, APB2ENR) == 0x60u);
BR_STM32_LAYOUT_CHECK(rcc_csr, offsetof(br_stm32g4_rcc_t, CSR) == 0x94u);
BR_STM32_LAYOUT_CHECK(rcc_ahb1enr, offsetof(br_stm32g4_rcc_t, AHB1ENR) == 0x48u);
BR_STM32_LAYOUT_CHECK(dma_ccr1, offsetof(br_stm32g4_dma_t, C) == 0x08u);
BR_STM32_LAYOUT_CHECK(dma_ccr8, offsetof(br_stm32g4_dma_t, C[7]) == 0x94u);
BR_STM32_LAYOUT_CHECK(pwr_cr5, offsetof(br_stm32g4_pwr_t, CR5) == 0x80u);

/* ---- board helpers -------------------------------------------------------- */

br_status_t br_stm32g4_rcc_enable(br_stm32g4_rcc_t *rcc)
{
    if (rcc == NULL) {
        return BR_E_NULL;
    }
    rcc->AHB2ENR |= BR_G4_RCC_AHB2ENR_GPIOAEN | BR_G4_RCC_AHB2ENR_GPIOBEN;
    rcc->APB1ENR1 |= BR_G4_RCC_APB1ENR1_TIM2EN;
    rcc->APB2ENR |= BR_G4_RCC_APB2ENR_TIM1EN;
    const uint32_t readback = rcc->APB2ENR; /* the enable takes effect before the first access */
    (void)readback;
    return BR_OK;
}

br_status_t br_stm32g4_rcc_enable_usart2(br_stm32g4_rcc_t *rcc)
{
    if (rcc == NULL) {
        return BR_E_NULL;
    }
    rcc->AHB1ENR |= BR_G4_RCC_AHB1ENR_DMA1EN | BR_G4_RCC_AHB1ENR_DMAMUX1EN;
    rcc->APB1ENR1 |= BR_G4_RCC_APB1ENR1_USART2EN;
    const uint32_t readback = rcc->APB1ENR1;
    (void)readback;
    return BR_OK;
}

/* ---- the USART channel's DMA ---------------------------------------------- */

br_status_t br_stm32g4_usart_dma(br_stm32g4_dma_t *dma, br_stm32g4_dmamux_t *mux, uint32_t mux_base,
                                 uint32_t rx_ch, uint32_t tx_ch, uint32_t rx_req, uint32_t tx_req,
                                 br_stm32_usart_cfg_t *cfg)
{
    if (dma == NULL || mux == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    if (rx_ch >= BR_G4_DMA_CHANNELS || tx_ch >= BR_G4_DMA_CHANNELS || rx_ch == tx_ch ||
        (mux_base != 0u && mux_base != BR_G4_DMA_CHANNELS) || rx_req == 0u || tx_req == 0u ||
        rx_req > BR_G4_DMAMUX_REQ_MAX || tx_req > BR_G4_DMAMUX_REQ_MAX) {
        return BR_E_PARAM;
    }
    mux->CCR[mux_base + rx_ch] = rx_req;
    mux->CCR[mux_base + tx_ch] = tx_req;
    cfg->rx_dma = &dma->C[rx_ch].ch;
    cfg->tx_dma = &dma->C[tx_ch].ch;
    cfg->tx_dma_ifcr = &dma->IFCR;
    cfg->tx_dma_ifcr_mask = BR_G4_DMA_IFCR_CHANNEL << (4u * tx_ch);
    cfg->rx_dma_cr = BR_G4_DMA_CCR_CIRC | BR_G4_DMA_CCR_MINC;
    cfg->tx_dma_cr = BR_G4_DMA_CCR_DIR_M2P | BR_G4_DMA_CCR_MINC;
    return BR_OK;
}

/* ---- clocks ------------------------------------------------------------------- */

br_status_t br_stm32g4_clock_170(const br_stm32g4_clock_regs_t *r)
{
    if (r == NULL || r->rcc == NULL || r->pwr == NULL || r->flash == NULL) {
        return BR_E_NULL;
    }
    br_stm32g4_rcc_t *const rcc = r->rcc;
    /* 1. PWR's clock, then range 1 boost mode (needed above 150 MHz), with
     *    HCLK = SYSCLK / 2 until the new clock has run for 1 us */
    rcc->APB1ENR1 |= BR_G4_RCC_APB1ENR1_PWREN;
    uint32_t readback = rcc->APB1ENR1;
    (void)readback;
    rcc->CFGR = (rcc->CFGR & ~BR_G4_RCC_CFGR_HPRE_Msk) | BR_G4_RCC_CFGR_HPRE_DIV2;
    r->pwr->CR5 &= ~BR_G4_PWR_CR5_R1MODE;
    /* 2. flash: 4 wait states (170 MHz, boost), prefetch, caches; read back */
    r->flash->ACR = (r->flash->ACR & ~BR_G4_FLASH_ACR_LATENCY_Msk) | BR_STM32G4_FLASH_WS |
                    BR_G4_FLASH_ACR_PRFTEN | BR_G4_FLASH_ACR_ICEN | BR_G4_FLASH_ACR_DCEN;
    if (!br_stm32_wait(&r->flash->ACR, BR_G4_FLASH_ACR_LATENCY_Msk, BR_STM32G4_FLASH_WS)) {
        return BR_E_STATE;
    }
    /* 3. PLL from HSI16: M = 4 (4 MHz), N = 85 (VCO 340 MHz), R = 2 (170 MHz:
     *    PLLR = 00, the field left 0) */
    if (!br_stm32_wait(&rcc->CR, BR_G4_RCC_CR_HSIRDY, BR_G4_RCC_CR_HSIRDY)) {
        return BR_E_STATE;
    }
    rcc->PLLCFGR = BR_G4_RCC_PLLCFGR_PLLSRC_HSI | ((BR_STM32G4_PLL_M - 1u) << BR_G4_RCC_PLLCFGR_PLLM_Pos) |
                   (BR_STM32G4_PLL_N << BR_G4_RCC_PLLCFGR_PLLN_Pos) | BR_G4_RCC_PLLCFGR_PLLREN;
    rcc->CR |= BR_G4_RCC_CR_PLLON;
    if (!br_stm32_wait(&rcc->CR, BR_G4_RCC_CR_PLLRDY, BR_G4_RCC_CR_PLLRDY)) {
        return BR_E_STATE;
    }
    /* 4. SYSCLK = PLL (HCLK still /2) */
    rcc->CFGR = (rcc->CFGR & ~BR_G4_RCC_CFGR_SW_Msk) | BR_G4_RCC_CFGR_SW_PLL;
    if (!br_stm32_wait(&rcc->CFGR, BR_G4_RCC_CFGR_SWS_Msk, BR_G4_RCC_CFGR_SWS_PLL)) {
        return BR_E_STATE;
    }
    /* 5. at least 1 us at HCLK / 2, then AHB, APB1, APB2 /1 */
    for (uint32_t polls = 0u; polls < BR_STM32G4_HPRE_HOLD_POLLS; ++polls) {
        readback = rcc->CFGR;
    }
    (void)readback;
    rcc->CFGR &= ~(BR_G4_RCC_CFGR_HPRE_Msk | BR_G4_RCC_CFGR_PPRE_Msk);
    return BR_OK;
}
