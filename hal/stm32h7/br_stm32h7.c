/* SPDX-License-Identifier: Apache-2.0 */
/* STM32H743 port: the clock tree and the clock enables (br_stm32h7.h); the
 * encoder, PWM, tick and watchdog are the shared STM32 driver's
 * (hal/stm32, bristle/br_stm32.h). Pure C99 on register-block pointers: it
 * builds for the target and for host tests against fake register blocks. */
#include "bristle/br_stm32h7.h"

#include <stddef.h>

/* Layout checks against the RM0433 register maps. */
BR_STM32_LAYOUT_CHECK(rcc_ahb4enr, offsetof(br_stm32h7_rcc_t, AHB4ENR) == 0x0E0u);
BR_STM32_LAYOUT_CHECK(rcc_apb1lenr, offsetof(br_stm32h7_rcc_t, APB1LENR) == 0x0E8u);
BR_STM32_LAYOUT_CHECK(rcc_apb2enr, offsetof(br_stm32h7_rcc_t, APB2ENR) == 0x0F0u);
BR_STM32_LAYOUT_CHECK(rcc_cfgr, offsetof(br_stm32h7_rcc_t, CFGR) == 0x010u);
BR_STM32_LAYOUT_CHECK(rcc_d1cfgr, offsetof(br_stm32h7_rcc_t, D1CFGR) == 0x018u);
BR_STM32_LAYOUT_CHECK(rcc_d3cfgr, offsetof(br_stm32h7_rcc_t, D3CFGR) == 0x020u);
BR_STM32_LAYOUT_CHECK(rcc_pllckselr, offsetof(br_stm32h7_rcc_t, PLLCKSELR) == 0x028u);
BR_STM32_LAYOUT_CHECK(rcc_pll1divr, offsetof(br_stm32h7_rcc_t, PLL1DIVR) == 0x030u);
BR_STM32_LAYOUT_CHECK(rcc_rsr, offsetof(br_stm32h7_rcc_t, RSR) == 0x0D0u);
BR_STM32_LAYOUT_CHECK(rcc_apb4enr, offsetof(br_stm32h7_rcc_t, APB4ENR) == 0x0F4u);
BR_STM32_LAYOUT_CHECK(pwr_cr3, offsetof(br_stm32h7_pwr_t, CR3) == 0x0Cu);
BR_STM32_LAYOUT_CHECK(pwr_d3cr, offsetof(br_stm32h7_pwr_t, D3CR) == 0x18u);
BR_STM32_LAYOUT_CHECK(rcc_ahb1enr, offsetof(br_stm32h7_rcc_t, AHB1ENR) == 0x0D8u);
BR_STM32_LAYOUT_CHECK(dma_s0cr, offsetof(br_stm32h7_dma_t, S) == 0x10u);
BR_STM32_LAYOUT_CHECK(dma_stream, sizeof(br_stm32h7_dma_stream_t) == 0x18u);
BR_STM32_LAYOUT_CHECK(dma_s7fcr, offsetof(br_stm32h7_dma_t, S[7].FCR) == 0xCCu);
BR_STM32_LAYOUT_CHECK(syscfg_pwrcr, offsetof(br_stm32h7_syscfg_t, PWRCR) == 0x2Cu);

/* ---- board helpers -------------------------------------------------------- */

br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc)
{
    if (rcc == NULL) {
        return BR_E_NULL;
    }
    rcc->AHB4ENR |= BR_RCC_AHB4ENR_GPIOAEN | BR_RCC_AHB4ENR_GPIOBEN;
    rcc->APB1LENR |= BR_RCC_APB1LENR_TIM2EN;
    rcc->APB2ENR |= BR_RCC_APB2ENR_TIM1EN;
    /* Read back: the enable takes effect before the first peripheral access. */
    const uint32_t readback = rcc->APB2ENR;
    (void)readback;
    return BR_OK;
}

br_status_t br_stm32h7_rcc_enable_usart3(br_stm32h7_rcc_t *rcc)
{
    if (rcc == NULL) {
        return BR_E_NULL;
    }
    rcc->AHB4ENR |= BR_RCC_AHB4ENR_GPIODEN;
    rcc->AHB1ENR |= BR_RCC_AHB1ENR_DMA1EN;
    rcc->APB1LENR |= BR_RCC_APB1LENR_USART3EN;
    const uint32_t readback = rcc->APB1LENR;
    (void)readback;
    return BR_OK;
}

/* ---- the USART channel's DMA ----------------------------------------------- */

/* A stream's clear bits: streams 0..3 in LIFCR, 4..7 in HIFCR, each at 0, 6,
 * 16 or 22 of its register. */
static uint32_t dma_ifcr_shift(uint32_t stream)
{
    static const uint8_t shift[4] = {0u, 6u, 16u, 22u};
    return shift[stream % 4u];
}

br_status_t br_stm32h7_usart_dma(br_stm32h7_dma_t *dma, br_stm32h7_dmamux_t *mux, uint32_t mux_base,
                                 uint32_t rx_stream, uint32_t tx_stream, uint32_t rx_req, uint32_t tx_req,
                                 br_stm32_usart_cfg_t *cfg)
{
    if (dma == NULL || mux == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    if (rx_stream >= BR_H7_DMA_STREAMS || tx_stream >= BR_H7_DMA_STREAMS || rx_stream == tx_stream ||
        (mux_base != 0u && mux_base != BR_H7_DMA_STREAMS) || rx_req == 0u || tx_req == 0u ||
        rx_req > BR_H7_DMAMUX_REQ_MAX || tx_req > BR_H7_DMAMUX_REQ_MAX) {
        return BR_E_PARAM;
    }
    mux->CCR[mux_base + rx_stream] = rx_req;
    mux->CCR[mux_base + tx_stream] = tx_req;
    dma->S[rx_stream].FCR = 0u;
    dma->S[tx_stream].FCR = 0u;
    cfg->rx_dma = &dma->S[rx_stream].ch;
    cfg->tx_dma = &dma->S[tx_stream].ch;
    cfg->tx_dma_ifcr = (tx_stream < 4u) ? &dma->LIFCR : &dma->HIFCR;
    cfg->tx_dma_ifcr_mask = BR_H7_DMA_IFCR_STREAM << dma_ifcr_shift(tx_stream);
    cfg->rx_dma_cr = BR_H7_DMA_SxCR_DIR_P2M | BR_H7_DMA_SxCR_CIRC | BR_H7_DMA_SxCR_MINC;
    cfg->tx_dma_cr = BR_H7_DMA_SxCR_DIR_M2P | BR_H7_DMA_SxCR_MINC;
    return BR_OK;
}

/* ---- clocks (docs/modules/hal.md, "Clocks") ------------------------------------ */

br_status_t br_stm32h7_clock_480(const br_stm32h7_clock_regs_t *r)
{
    if (r == NULL || r->rcc == NULL || r->pwr == NULL || r->syscfg == NULL || r->flash == NULL) {
        return BR_E_NULL;
    }
    br_stm32h7_rcc_t *const rcc = r->rcc;
    br_stm32h7_pwr_t *const pwr = r->pwr;
    /* 1. supply: LDO (the part has no SMPS); the configuration is taken once
     *    after reset, then wait until the voltage levels are ready */
    pwr->CR3 = (pwr->CR3 & ~(BR_PWR_CR3_SCUEN | BR_PWR_CR3_LDOEN | BR_PWR_CR3_BYPASS)) | BR_PWR_CR3_LDOEN;
    if (!br_stm32_wait(&pwr->CSR1, BR_PWR_CSR1_ACTVOSRDY, BR_PWR_CSR1_ACTVOSRDY)) {
        return BR_E_STATE;
    }
    /* 2. VOS1, then the overdrive (SYSCFG ODEN) for VOS0 */
    pwr->D3CR = (pwr->D3CR & ~BR_PWR_D3CR_VOS_Msk) | BR_PWR_D3CR_VOS_SCALE1;
    if (!br_stm32_wait(&pwr->D3CR, BR_PWR_D3CR_VOSRDY, BR_PWR_D3CR_VOSRDY)) {
        return BR_E_STATE;
    }
    rcc->APB4ENR |= BR_RCC_APB4ENR_SYSCFGEN;
    const uint32_t readback = rcc->APB4ENR;
    (void)readback;
    r->syscfg->PWRCR |= BR_SYSCFG_PWRCR_ODEN;
    if (!br_stm32_wait(&pwr->D3CR, BR_PWR_D3CR_VOSRDY, BR_PWR_D3CR_VOSRDY)) {
        return BR_E_STATE;
    }
    /* 3. flash: 4 wait states, programming delay 2, before the clock rises;
     *    read back (the new latency must be in effect) */
    r->flash->ACR = (r->flash->ACR & ~(BR_FLASH_ACR_LATENCY_Msk | BR_FLASH_ACR_WRHIGHFREQ_Msk)) |
                    BR_STM32H7_FLASH_WS | (BR_STM32H7_FLASH_WRHIGHFREQ << BR_FLASH_ACR_WRHIGHFREQ_Pos);
    if (!br_stm32_wait(&r->flash->ACR, BR_FLASH_ACR_LATENCY_Msk, BR_STM32H7_FLASH_WS)) {
        return BR_E_STATE;
    }
    /* 4. PLL1 from HSI: DIVM1 = 4 (16 MHz), range 8..16 MHz, wide VCO,
     *    N = 60 (960 MHz), P = 2 (480 MHz), Q = R = 4 and off */
    if (!br_stm32_wait(&rcc->CR, BR_RCC_CR_HSIRDY, BR_RCC_CR_HSIRDY)) {
        return BR_E_STATE;
    }
    rcc->PLLCKSELR = (rcc->PLLCKSELR & ~(BR_RCC_PLLCKSELR_PLLSRC_Msk | BR_RCC_PLLCKSELR_DIVM1_Msk)) |
                     (BR_STM32H7_PLL1_DIVM << BR_RCC_PLLCKSELR_DIVM1_Pos);
    rcc->PLLCFGR = (rcc->PLLCFGR & ~(BR_RCC_PLLCFGR_PLL1_Msk | BR_RCC_PLLCFGR_DIVQ1EN | BR_RCC_PLLCFGR_DIVR1EN)) |
                   BR_RCC_PLLCFGR_PLL1RGE_8_16 | BR_RCC_PLLCFGR_DIVP1EN;
    rcc->PLL1DIVR = ((BR_STM32H7_PLL1_DIVN - 1u) << BR_RCC_PLL1DIVR_DIVN1_Pos) |
                    ((BR_STM32H7_PLL1_DIVP - 1u) << BR_RCC_PLL1DIVR_DIVP1_Pos) |
                    (3u << BR_RCC_PLL1DIVR_DIVQ1_Pos) | (3u << BR_RCC_PLL1DIVR_DIVR1_Pos);
    rcc->CR |= BR_RCC_CR_PLL1ON;
    if (!br_stm32_wait(&rcc->CR, BR_RCC_CR_PLL1RDY, BR_RCC_CR_PLL1RDY)) {
        return BR_E_STATE;
    }
    /* 5. bus prescalers before the switch: D1CPRE /1, HPRE /2, APB3 /2,
     *    APB1 /2, APB2 /2, APB4 /2; TIMPRE = 0: timers at 2 x APB */
    rcc->D1CFGR = (rcc->D1CFGR & ~BR_RCC_D1CFGR_Msk) | BR_RCC_D1CFGR_D1CPRE_DIV1 | BR_RCC_D1CFGR_HPRE_DIV2 |
                  BR_RCC_D1CFGR_D1PPRE_DIV2;
    rcc->D2CFGR = (rcc->D2CFGR & ~BR_RCC_D2CFGR_Msk) | BR_RCC_D2CFGR_D2PPRE1_DIV2 | BR_RCC_D2CFGR_D2PPRE2_DIV2;
    rcc->D3CFGR = (rcc->D3CFGR & ~BR_RCC_D3CFGR_Msk) | BR_RCC_D3CFGR_D3PPRE_DIV2;
    /* 6. system clock = PLL1 */
    rcc->CFGR = (rcc->CFGR & ~(BR_RCC_CFGR_SW_Msk | BR_RCC_CFGR_TIMPRE)) | BR_RCC_CFGR_SW_PLL1;
    if (!br_stm32_wait(&rcc->CFGR, BR_RCC_CFGR_SWS_Msk, BR_RCC_CFGR_SWS_PLL1)) {
        return BR_E_STATE;
    }
    return BR_OK;
}
