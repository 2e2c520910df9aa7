/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32G474 board's row of the port suite (port_board.h,
 * test_stm32_port.c): its clocks (hal/stm32g4/board/br_board.h: 170 MHz
 * core, timers and USART2 kernel clock), the register values they give, and
 * the part's own cases on fake blocks of RM0440's map: the clock enables, the
 * clock tree to 170 MHz, the USART's DMA side (DMA1 channels, DMAMUX). */
#include "br_test.h"

#include <string.h>

#include "bristle/br_stm32g4.h"
#include "port_board.h"

/* ---- clock enables ------------------------------------------------------------ */

static void g4_test_rcc_enable(void **st)
{
    (void)st;
    br_stm32g4_rcc_t rcc;
    memset(&rcc, 0, sizeof rcc);
    rcc.APB2ENR = 0x1u; /* SYSCFGEN kept */
    assert_int_equal(br_stm32g4_rcc_enable(&rcc), BR_OK);
    assert_int_equal(rcc.AHB2ENR, 0x3u);              /* GPIOA, GPIOB */
    assert_int_equal(rcc.APB1ENR1, 0x1u);             /* TIM2 */
    assert_int_equal(rcc.APB2ENR, 0x1u | (1u << 11)); /* TIM1 at bit 11 (RM0440) */
    assert_int_equal(br_stm32g4_rcc_enable(NULL), BR_E_NULL);
}

/* ---- clocks: HSI16 -> PLL 170 MHz ------------------------------------------------ */

typedef struct {
    br_stm32g4_rcc_t rcc;
    br_stm32g4_pwr_t pwr;
    br_stm32g4_flash_t flash;
} fake_clock_t;

/* reset values where they matter (RM0440), with the ready flags a running
 * part would raise already set */
static br_stm32g4_clock_regs_t clock_up(fake_clock_t *k, int pll_locks)
{
    memset(k, 0, sizeof *k);
    k->rcc.CR = BR_G4_RCC_CR_HSION | BR_G4_RCC_CR_HSIRDY | (pll_locks ? BR_G4_RCC_CR_PLLRDY : 0u);
    k->rcc.CFGR = 0x00000005u | BR_G4_RCC_CFGR_SWS_PLL; /* SW = HSI16 at reset; the switch "completes" */
    k->rcc.PLLCFGR = 0x00001000u;                        /* reset: PLLN = 16 */
    k->pwr.CR5 = BR_G4_PWR_CR5_R1MODE;                   /* reset: boost off */
    k->flash.ACR = 0x00000600u;                          /* reset: ICEN, DCEN, 0 WS */
    const br_stm32g4_clock_regs_t r = {&k->rcc, &k->pwr, &k->flash};
    return r;
}

static void g4_test_clock_tree(void **st)
{
    (void)st;
    fake_clock_t k;
    br_stm32g4_clock_regs_t r = clock_up(&k, 1);
    assert_int_equal(br_stm32g4_clock_170(&r), BR_OK);
    assert_true((k.rcc.APB1ENR1 & BR_G4_RCC_APB1ENR1_PWREN) != 0u);
    assert_int_equal(k.pwr.CR5 & BR_G4_PWR_CR5_R1MODE, 0u); /* boost */
    assert_int_equal(k.flash.ACR, 0x704u);                   /* 4 WS, PRFTEN, ICEN, DCEN */
    /* PLL: HSI16 (10), M - 1 = 3, N = 85, R enabled at /2 */
    assert_int_equal(k.rcc.PLLCFGR, 2u | (3u << 4) | (85u << 8) | (1u << 24));
    assert_true((k.rcc.CR & BR_G4_RCC_CR_PLLON) != 0u);
    /* SYSCLK = PLL; HPRE, PPRE1, PPRE2 back to /1 after the hold */
    assert_int_equal(k.rcc.CFGR & BR_G4_RCC_CFGR_SW_Msk, 3u);
    assert_int_equal(k.rcc.CFGR & (BR_G4_RCC_CFGR_HPRE_Msk | BR_G4_RCC_CFGR_PPRE_Msk), 0u);
    /* the frequency the constants state */
    assert_int_equal(16000000u / BR_STM32G4_PLL_M * BR_STM32G4_PLL_N / 2u, BR_STM32G4_SYSCLK_HZ);

    /* the PLL never locks: bounded wait, the system clock stays on HSI16 with HCLK /2 */
    r = clock_up(&k, 0);
    k.rcc.CFGR = 0x1u;
    assert_int_equal(br_stm32g4_clock_170(&r), BR_E_STATE);
    assert_int_equal(k.rcc.CFGR & BR_G4_RCC_CFGR_SW_Msk, 1u);
    assert_int_equal(k.rcc.CFGR & BR_G4_RCC_CFGR_HPRE_Msk, BR_G4_RCC_CFGR_HPRE_DIV2);
    /* HSI16 not ready: the PLL is not touched */
    r = clock_up(&k, 1);
    k.rcc.CR = 0u;
    assert_int_equal(br_stm32g4_clock_170(&r), BR_E_STATE);
    assert_int_equal(k.rcc.PLLCFGR, 0x00001000u);
    r.pwr = NULL;
    assert_int_equal(br_stm32g4_clock_170(&r), BR_E_NULL);
}

/* the G4's side of the USART channel: DMAMUX routing, the channels' CR
 * words, IFCR and the TX channel's clear bits; the clock enables; then the
 * shared driver over those fake channels starting the RX channel */
static void g4_test_usart_dma(void **st)
{
    (void)st;
    br_stm32g4_dma_t dma;
    br_stm32g4_dmamux_t mux;
    br_stm32_usart_cfg_t c;
    memset(&dma, 0, sizeof dma);
    memset(&mux, 0, sizeof mux);
    memset(&c, 0, sizeof c);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 1u, BR_G4_DMAREQ_USART2_RX, BR_G4_DMAREQ_USART2_TX, &c),
                     BR_OK);
    assert_int_equal(mux.CCR[0], 26u);
    assert_int_equal(mux.CCR[1], 27u);
    assert_ptr_equal(c.rx_dma, &dma.C[0].ch);
    assert_ptr_equal(c.tx_dma, &dma.C[1].ch);
    assert_ptr_equal(c.tx_dma_ifcr, &dma.IFCR);
    assert_int_equal(c.tx_dma_ifcr_mask, 0xFu << 4);
    /* RX: CIRC, MINC, DIR 0; TX: DIR 1, MINC; bytes, EN clear */
    assert_int_equal(c.rx_dma_cr, (1u << 5) | (1u << 7));
    assert_int_equal(c.tx_dma_cr, (1u << 4) | (1u << 7));
    /* DMA2 channels 8 (RX) and 3 (TX): DMAMUX channels 15 and 10 */
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 8u, 7u, 2u, 5u, 6u, &c), BR_OK);
    assert_int_equal(mux.CCR[15], 5u);
    assert_int_equal(mux.CCR[10], 6u);
    assert_int_equal(c.tx_dma_ifcr_mask, 0xFu << 8);
    br_stm32g4_dmamux_t mux0;
    memcpy(&mux0, &mux, sizeof mux);
    assert_int_equal(br_stm32g4_usart_dma(NULL, &mux, 0u, 0u, 1u, 26u, 27u, &c), BR_E_NULL);
    assert_int_equal(br_stm32g4_usart_dma(&dma, NULL, 0u, 0u, 1u, 26u, 27u, &c), BR_E_NULL);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 1u, 26u, 27u, NULL), BR_E_NULL);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 8u, 1u, 26u, 27u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 8u, 26u, 27u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 3u, 3u, 26u, 27u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 1u, 0u, 1u, 26u, 27u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 1u, 0u, 27u, &c), BR_E_PARAM);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 1u, 26u, 128u, &c), BR_E_PARAM);
    assert_memory_equal(&mux0, &mux, sizeof mux);

    br_stm32g4_rcc_t rcc;
    memset(&rcc, 0, sizeof rcc);
    assert_int_equal(br_stm32g4_rcc_enable_usart2(NULL), BR_E_NULL);
    assert_int_equal(br_stm32g4_rcc_enable_usart2(&rcc), BR_OK);
    assert_int_equal(rcc.AHB1ENR, (1u << 0) | (1u << 2));
    assert_int_equal(rcc.APB1ENR1, 1u << 17);

    /* the board's USART2: 170 MHz, 921 600 baud -> BRR 184; the RX channel
     * running circular, the TX channel prepared */
    br_stm32_usart_t usart;
    uint8_t rx[256]; /* 1 ms at 921 600 baud is 93 bytes: at least 186 */
    uint8_t tx[16];
    memset(&usart, 0, sizeof usart);
    memset(&dma, 0, sizeof dma);
    assert_int_equal(br_stm32g4_usart_dma(&dma, &mux, 0u, 0u, 1u, 26u, 27u, &c), BR_OK);
    c.usart = &usart;
    c.rx_buf = rx;
    c.rx_len = sizeof rx;
    c.tx_buf = tx;
    c.tx_len = sizeof tx;
    c.kernel_clock_hz = 170000000u;
    c.baud = 921600u;
    c.poll_period_ns = 1000000u;
    br_stm32_usart_chan_t u;
    assert_int_equal(br_stm32_usart_init(&u, &c), BR_OK);
    assert_int_equal(usart.BRR, 184u);
    assert_int_equal(dma.C[0].ch.CR, (1u << 5) | (1u << 7) | 1u);
    assert_int_equal(dma.C[0].ch.NDTR, sizeof rx);
    assert_int_equal(dma.C[1].ch.CR, (1u << 4) | (1u << 7));
    assert_int_equal(dma.IFCR, 0xFu << 4);
}

/* the board table's usart_dma over fake DMA1 and DMAMUX blocks: USART2's
 * requests on channels 1 (RX) and 2 (TX), as hal/stm32g4/board does */
static br_stm32g4_dma_t g4_fake_dma;
static br_stm32g4_dmamux_t g4_fake_mux;
static br_status_t g4_fake_usart_dma(br_stm32_usart_cfg_t *cfg)
{
    memset(&g4_fake_dma, 0, sizeof g4_fake_dma);
    memset(&g4_fake_mux, 0, sizeof g4_fake_mux);
    return br_stm32g4_usart_dma(&g4_fake_dma, &g4_fake_mux, 0u, 0u, 1u, BR_G4_DMAREQ_USART2_RX,
                                BR_G4_DMAREQ_USART2_TX, cfg);
}

const port_board_t port_board = {
    .name = "stm32g4",
    .cpu_hz = 170000000u,
    .tim_hz = 170000000u,
    .deadtime_ticks = 85u,
    .usart_hz = 170000000u,
    .arr_20k = 4250u,
    .ccr_quarter = 1063u,          /* 1062.5 rounds up */
    .arr_1k = 42500u,
    .load_1ms = 169999u,
    .load_1500us = 254999u,
    .usart_brr_921600 = 184u,      /* 170e6 / 921 600 = 184.5 */
    .pwm_hz_100_steps = 850000u,
    .pwm_hz_too_fast = 1000000u,   /* 85 steps */
    .tick_hz_500_cycles = 340000u,
    .tick_hz_over_2p24 = 10u,      /* 17e6 cycles */
    .period_ns_over_2p24 = 100000000u, /* 17e6 cycles */
    .usart_dma = g4_fake_usart_dma,
    .test_rcc_enable = g4_test_rcc_enable,
    .test_clock_tree = g4_test_clock_tree,
    .test_usart_dma = g4_test_usart_dma,
};
