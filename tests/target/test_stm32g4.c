/* SPDX-License-Identifier: Apache-2.0 */
/* STM32G474 port against fake register blocks in RAM (docs/porting.md, "Test
 * a port on fake registers"): the shared STM32 driver programmed for the
 * G4's clocks (170 MHz: ARR, SysTick reload, prescaler), br_app over it
 * latching a fault with TIM1's outputs off, and what is the G4's own: the
 * clock enables (RM0440's RCC) and the clock tree to 170 MHz. The shared
 * driver's guards, wraps, duty table, tick and watchdog are tested in
 * test_stm32h7.c (the same code).
 *
 * A fake block is plain memory: COUNTFLAG is not cleared by a read and
 * counters do not run, so each test sets what a real peripheral would. */
#include "br_test.h"

#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_stm32g4.h"

typedef struct {
    br_stm32_tim_t tim1;
    br_stm32_tim_t tim2;
    br_stm32_systick_t systick;
} fake_regs_t;

/* 170 MHz core and timer clock, 20 kHz PWM, 1 kHz control, 500 ns dead time. */
static br_stm32_cfg_t cfg_for(fake_regs_t *f)
{
    br_stm32_cfg_t c;
    memset(&c, 0, sizeof c);
    c.pwm_tim = &f->tim1;
    c.enc_tim = &f->tim2;
    c.systick = &f->systick;
    c.cpu_clock_hz = 170000000u;
    c.tim_clock_hz = 170000000u;
    c.pwm_hz = 20000u;
    c.control_hz = 1000u;
    c.enc_counter_bits = 32u;
    c.enc_filter = 3u;
    c.deadtime_ticks = 85u;
    return c;
}

static void port_up(br_stm32_t *port, fake_regs_t *f, uint32_t enc_bits)
{
    memset(f, 0, sizeof *f);
    br_stm32_cfg_t c = cfg_for(f);
    c.enc_counter_bits = enc_bits;
    assert_int_equal(br_stm32_init(port, &c), BR_OK);
}

static int pwm_off(const fake_regs_t *f)
{
    return (f->tim1.BDTR & BR_TIM_BDTR_MOE) == 0u && f->tim1.CCER == 0u && f->tim1.CCR1 == 0u &&
           f->tim1.CCR2 == 0u;
}

/* ---- init ------------------------------------------------------------- */

static void test_init_programs_registers(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    memset(&f, 0, sizeof f);
    f.tim2.SMCR = 0x00010007u; /* stale SMS bits, incl. SMS[3], must be replaced */
    br_stm32_cfg_t c = cfg_for(&f);
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);

    /* encoder: mode 3, filter 3 on both inputs, full range, running */
    assert_int_equal(f.tim2.SMCR & BR_TIM_SMCR_SMS_Msk, 3u);
    assert_int_equal(f.tim2.CCMR1, 0x3131u);
    assert_int_equal(f.tim2.ARR, 0xFFFFFFFFu);
    assert_int_equal(f.tim2.PSC, 0u);
    assert_true((f.tim2.CR1 & BR_TIM_CR1_CEN) != 0u);

    /* PWM: centre-aligned 20 kHz at 170 MHz -> ARR = 170e6 / (2 * 20e3) = 4250 */
    assert_int_equal(f.tim1.PSC, 0u);
    assert_int_equal(f.tim1.ARR, 4250u);
    assert_int_equal(f.tim1.CR1, BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE | BR_TIM_CR1_CEN);
    assert_int_equal(f.tim1.CCMR1, 0x6868u); /* PWM mode 1, preload, both channels */
    assert_true(pwm_off(&f));                /* outputs off until the arm */
    assert_int_equal(f.tim1.BDTR & BR_TIM_BDTR_DTG_Msk, 85u);
    assert_int_equal(br_stm32_pwm_enable(&port), BR_OK);
    assert_int_equal(f.tim1.CCER,
                     BR_TIM_CCER_CC1E | BR_TIM_CCER_CC1NE | BR_TIM_CCER_CC2E | BR_TIM_CCER_CC2NE);
    assert_true((f.tim1.BDTR & BR_TIM_BDTR_MOE) != 0u);

    /* SysTick: processor clock, 170000 cycles per 1 ms tick, no interrupt */
    assert_int_equal(f.systick.LOAD, 169999u);
    assert_int_equal(f.systick.CTRL, BR_SYSTICK_CTRL_CLKSOURCE | BR_SYSTICK_CTRL_ENABLE);

    /* the PF's 1.5 ms as a period in ns: 255000 cycles */
    c.control_hz = 0u;
    c.control_period_ns = 1500000u;
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    assert_int_equal(f.systick.LOAD, 254999u);
    /* a slow PWM needs the prescaler: 1 kHz -> 85000 ticks per half period */
    c = cfg_for(&f);
    c.pwm_hz = 1000u;
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    assert_int_equal(f.tim1.PSC, 1u);
    assert_int_equal(f.tim1.ARR, 42500u);
}

/* ---- br_hal_t through br_app: a latched fault turns TIM1 off ----------------- */

static void test_app_on_port(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    br_hal_t hal;
    br_app_t app;
    port_up(&port, &f, 32u);
    assert_int_equal(br_stm32_hal(&port, &hal), BR_OK);
    assert_ptr_equal(hal.ctx, &port);
    const br_ctrl_cfg_t k = {{-0.5f, -0.01f, -10.0f}, 1e-3f, 0.64f, 0.64f, 6.0e-6f, 1.27e-3f};
    const br_app_guard_cfg_t guard = {100u, 3u, 10u, 2u};
    const br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL, guard, BR_TEST_WIDE_MOTION};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_true(pwm_off(&f)); /* disarmed */
    assert_int_equal(br_app_arm(&app), BR_OK);
    const br_ref_t r = {120000, 0.0f, 0.0f};
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_true(f.tim1.CCR1 > 2125u); /* a large error: a large duty on leg A */
    assert_false(pwm_off(&f));
    /* the encoder leaps 101 counts in one period: latched, outputs off */
    f.tim2.CNT += 101u;
    assert_int_equal(br_app_step(&app, &r), BR_E_FAULT);
    assert_int_equal(app.fault, BR_APP_FAULT_ENC_JUMP);
    assert_true(pwm_off(&f));
    assert_int_equal(br_app_step(&app, &r), BR_E_FAULT); /* stays off */
    assert_true(pwm_off(&f));
}

/* ---- board helpers ------------------------------------------------------------ */

static void test_rcc_enable(void **st)
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

static void test_clock_170(void **st)
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
static void test_usart_dma(void **st)
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_programs_registers),
        cmocka_unit_test(test_app_on_port),
        cmocka_unit_test(test_rcc_enable),
        cmocka_unit_test(test_clock_170),
        cmocka_unit_test(test_usart_dma),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
