/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32H743 board's row of the port suite (port_board.h,
 * test_stm32_port.c): its clocks (hal/stm32h7/board/br_board.h: 480 MHz core,
 * 240 MHz timers, USART3 on the 120 MHz APB clock), the register values they
 * give, and the part's own cases on fake blocks of RM0433's map: the clock
 * enables, the clock tree to 480 MHz, the USART's DMA side (DMA1 streams,
 * DMAMUX1). */
#include "br_test.h"

#include <string.h>

#include "bristle/br_stm32h7.h"
#include "port_board.h"

/* ---- clock enables ------------------------------------------------------------ */

static void h7_test_rcc_enable(void **st)
{
    (void)st;
    br_stm32h7_rcc_t rcc;
    memset(&rcc, 0, sizeof rcc);
    rcc.APB2ENR = 0x100u; /* other enables are kept */
    assert_int_equal(br_stm32h7_rcc_enable(&rcc), BR_OK);
    assert_int_equal(rcc.AHB4ENR, BR_RCC_AHB4ENR_GPIOAEN | BR_RCC_AHB4ENR_GPIOBEN);
    assert_int_equal(rcc.APB1LENR, BR_RCC_APB1LENR_TIM2EN);
    assert_int_equal(rcc.APB2ENR, 0x100u | BR_RCC_APB2ENR_TIM1EN);
    assert_int_equal(br_stm32h7_rcc_enable(NULL), BR_E_NULL);
}

/* ---- clocks: HSI 64 MHz -> PLL1 480 MHz ------------------------------------ */

typedef struct {
    br_stm32h7_rcc_t rcc;
    br_stm32h7_pwr_t pwr;
    br_stm32h7_syscfg_t syscfg;
    br_stm32h7_flash_t flash;
} fake_clock_t;

/* reset values where they matter (RM0433), with the ready flags a running
 * part would raise already set (a fake register does not change by itself) */
static br_stm32h7_clock_regs_t clock_up(fake_clock_t *k, int pll_locks)
{
    memset(k, 0, sizeof *k);
    k->rcc.CR = BR_RCC_CR_HSION | BR_RCC_CR_HSIRDY | (pll_locks ? BR_RCC_CR_PLL1RDY : 0u);
    k->rcc.CFGR = BR_RCC_CFGR_SWS_PLL1; /* the switch "completes" */
    k->rcc.PLLCKSELR = 0x02020200u;     /* DIVM1..3 = 32, HSI */
    k->rcc.PLLCFGR = 0x01FF0000u;       /* every DIVxyEN set */
    k->pwr.CR3 = BR_PWR_CR3_SCUEN | BR_PWR_CR3_LDOEN;
    k->pwr.CSR1 = BR_PWR_CSR1_ACTVOSRDY;
    k->pwr.D3CR = (1u << 14) | BR_PWR_D3CR_VOSRDY; /* VOS3 after reset */
    k->flash.ACR = 0x37u;                          /* 7 WS, WRHIGHFREQ 3 */
    const br_stm32h7_clock_regs_t r = {&k->rcc, &k->pwr, &k->syscfg, &k->flash};
    return r;
}

static void h7_test_clock_tree(void **st)
{
    (void)st;
    fake_clock_t k;
    br_stm32h7_clock_regs_t r = clock_up(&k, 1);
    assert_int_equal(br_stm32h7_clock_480(&r), BR_OK);
    /* supply LDO, VOS1 + ODEN = VOS0 */
    assert_int_equal(k.pwr.CR3 & 7u, BR_PWR_CR3_LDOEN);
    assert_int_equal(k.pwr.D3CR & BR_PWR_D3CR_VOS_Msk, 3u << 14);
    assert_int_equal(k.rcc.APB4ENR & BR_RCC_APB4ENR_SYSCFGEN, BR_RCC_APB4ENR_SYSCFGEN);
    assert_int_equal(k.syscfg.PWRCR & 1u, 1u);
    /* flash: 4 WS, WRHIGHFREQ = 2 */
    assert_int_equal(k.flash.ACR & 0x3Fu, 0x24u);
    /* PLL1: HSI, M = 4; range 8..16 MHz, wide VCO, integer; P on, Q/R off */
    assert_int_equal(k.rcc.PLLCKSELR, 0x02020040u);
    /* reset 0x01FF0000 with PLL1's Q and R enables cleared, RGE = 11 */
    assert_int_equal(k.rcc.PLLCFGR, 0x01F9000Cu);
    /* N - 1 = 59, P - 1 = 1, Q - 1 = R - 1 = 3 */
    assert_int_equal(k.rcc.PLL1DIVR, 59u | (1u << 9) | (3u << 16) | (3u << 24));
    assert_true((k.rcc.CR & BR_RCC_CR_PLL1ON) != 0u);
    /* D1CPRE /1, HPRE /2, D1PPRE /2; APB1, APB2, APB4 /2 */
    assert_int_equal(k.rcc.D1CFGR, 0x0048u);
    assert_int_equal(k.rcc.D2CFGR, 0x0440u);
    assert_int_equal(k.rcc.D3CFGR, 0x0040u);
    /* SYSCLK = PLL1, TIMPRE 0 */
    assert_int_equal(k.rcc.CFGR & 7u, 3u);
    assert_int_equal(k.rcc.CFGR & BR_RCC_CFGR_TIMPRE, 0u);
    /* the frequencies the board's constants state */
    assert_int_equal(64000000u / BR_STM32H7_PLL1_DIVM * BR_STM32H7_PLL1_DIVN / BR_STM32H7_PLL1_DIVP,
                     BR_STM32H7_SYSCLK_HZ);

    /* PLL1 never locks: bounded wait, the system clock stays on HSI */
    r = clock_up(&k, 0);
    k.rcc.CFGR = 0u;
    assert_int_equal(br_stm32h7_clock_480(&r), BR_E_STATE);
    assert_int_equal(k.rcc.CFGR & 7u, 0u);
    assert_int_equal(k.rcc.D1CFGR, 0u);
    /* the voltage never ready: nothing past it written */
    r = clock_up(&k, 1);
    k.pwr.D3CR = 1u << 14;
    assert_int_equal(br_stm32h7_clock_480(&r), BR_E_STATE);
    assert_int_equal(k.flash.ACR, 0x37u);
    assert_int_equal(k.rcc.CR & BR_RCC_CR_PLL1ON, 0u);
    r.flash = NULL;
    assert_int_equal(br_stm32h7_clock_480(&r), BR_E_NULL);
}

/* the H7's DMA side: DMAMUX routing, direct mode, the streams' CR words and
 * the flag-clear register of the TX stream (LIFCR for 0..3, HIFCR for 4..7) */
static void h7_test_usart_dma(void **st)
{
    (void)st;
    br_stm32h7_dma_t dma;
    br_stm32h7_dmamux_t mux;
    br_stm32_usart_cfg_t c;
    memset(&dma, 0xFF, sizeof dma);
    memset(&mux, 0, sizeof mux);
    memset(&c, 0, sizeof c);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 0u, 1u, BR_H7_DMAREQ_USART3_RX, BR_H7_DMAREQ_USART3_TX, &c),
                     BR_OK);
    assert_int_equal(mux.CCR[0], 45u);
    assert_int_equal(mux.CCR[1], 46u);
    assert_int_equal(dma.S[0].FCR, 0u);
    assert_int_equal(dma.S[1].FCR, 0u);
    assert_ptr_equal(c.rx_dma, &dma.S[0].ch);
    assert_ptr_equal(c.tx_dma, &dma.S[1].ch);
    assert_ptr_equal(c.tx_dma_ifcr, &dma.LIFCR);
    assert_int_equal(c.tx_dma_ifcr_mask, 0x3Du << 6);
    /* RX: DIR 00, CIRC, MINC; TX: DIR 01, MINC; bytes, EN clear */
    assert_int_equal(c.rx_dma_cr, (1u << 8) | (1u << 10));
    assert_int_equal(c.tx_dma_cr, (1u << 6) | (1u << 10));
    /* DMA2, streams 7 (RX) and 6 (TX): DMAMUX channels 15, 14; HIFCR bits 16.. */
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 8u, 7u, 6u, 3u, 4u, &c), BR_OK);
    assert_int_equal(mux.CCR[15], 3u);
    assert_int_equal(mux.CCR[14], 4u);
    assert_ptr_equal(c.tx_dma_ifcr, &dma.HIFCR);
    assert_int_equal(c.tx_dma_ifcr_mask, 0x3Du << 16);

    /* guards: nothing written */
    br_stm32h7_dmamux_t mux0;
    memcpy(&mux0, &mux, sizeof mux);
    assert_int_equal(br_stm32h7_usart_dma(NULL, &mux, 0u, 0u, 1u, 45u, 46u, &c), BR_E_NULL);
    assert_int_equal(br_stm32h7_usart_dma(&dma, NULL, 0u, 0u, 1u, 45u, 46u, &c), BR_E_NULL);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 0u, 1u, 45u, 46u, NULL), BR_E_NULL);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 8u, 1u, 45u, 46u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 0u, 8u, 45u, 46u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 2u, 2u, 45u, 46u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 4u, 0u, 1u, 45u, 46u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 0u, 1u, 0u, 46u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32h7_usart_dma(&dma, &mux, 0u, 0u, 1u, 45u, 256u, &c), BR_E_PARAM);
    assert_memory_equal(&mux0, &mux, sizeof mux);

    /* the clock enables */
    br_stm32h7_rcc_t rcc;
    memset(&rcc, 0, sizeof rcc);
    assert_int_equal(br_stm32h7_rcc_enable_usart3(NULL), BR_E_NULL);
    assert_int_equal(br_stm32h7_rcc_enable_usart3(&rcc), BR_OK);
    assert_int_equal(rcc.AHB1ENR, 1u << 0);
    assert_int_equal(rcc.AHB4ENR, 1u << 3);
    assert_int_equal(rcc.APB1LENR, 1u << 18);
}

/* the board table's usart_dma over fake DMA1 and DMAMUX1 blocks: USART3's
 * requests on streams 0 (RX) and 1 (TX), as hal/stm32h7/board does */
static br_stm32h7_dma_t h7_fake_dma;
static br_stm32h7_dmamux_t h7_fake_mux;
static br_status_t h7_fake_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    memset(&h7_fake_dma, 0, sizeof h7_fake_dma);
    memset(&h7_fake_mux, 0, sizeof h7_fake_mux);
    return br_stm32h7_usart_dma(&h7_fake_dma, &h7_fake_mux, 0u, 0u, 1u, BR_H7_DMAREQ_USART3_RX,
                                BR_H7_DMAREQ_USART3_TX, cfg);
}

const port_board_t port_board = {
    .name = "stm32h7",
    .cpu_hz = 480000000u,
    .tim_hz = 240000000u,
    .deadtime_ticks = 120u,
    .usart_hz = 120000000u,
    .arr_20k = 6000u,
    .ccr_quarter = 1500u,
    .arr_1k = 60000u,
    .load_1ms = 479999u,
    .load_1500us = 719999u,
    .usart_brr_921600 = 130u,      /* 120e6 / 921 600 = 130.2 */
    .pwm_hz_100_steps = 1200000u,
    .pwm_hz_too_fast = 1500000u,   /* 80 steps */
    .tick_hz_500_cycles = 960000u,
    .tick_hz_over_2p24 = 10u,      /* 48e6 cycles */
    .period_ns_over_2p24 = 40000000u, /* 19.2e6 cycles */
    .usart_dma = h7_fake_usart_dma,
    .test_rcc_enable = h7_test_rcc_enable,
    .test_clock_tree = h7_test_clock_tree,
    .test_usart_dma = h7_test_usart_dma,
};
