/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32 port test suite, one for every board (port_board.h): the shared
 * driver against fake register blocks in RAM with the board's clocks
 * (register programming at init, init guards, encoder counts across counter
 * wraps: 32-bit TIM2 and the 16-bit extension, PWM duty mapping, SysTick
 * polling, the deadline, the watchdog, br_app over the port), the board
 * bring-up from a table (bristle/br_stm32_board.h) over fake blocks, and the
 * part's own cases the board's row names (clock enables, clock tree, the
 * USART's DMA side).
 *
 * A fake block is plain memory: COUNTFLAG is not cleared by a read and
 * counters do not run, so each test sets the registers a real peripheral
 * would change. */
#include "br_test.h"

#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_encoder.h"
#include "bristle/br_stm32_board.h"
#include "port_board.h"

typedef struct {
    br_stm32_tim_t tim1;
    br_stm32_tim_t tim2;
    br_stm32_systick_t systick;
} fake_regs_t;

/* The board's clocks, 20 kHz PWM, 1 kHz control, 500 ns dead time. */
static br_stm32_cfg_t cfg_for(fake_regs_t *f)
{
    const port_board_t *b = &port_board;
    br_stm32_cfg_t c;
    memset(&c, 0, sizeof c);
    c.pwm_tim = &f->tim1;
    c.enc_tim = &f->tim2;
    c.systick = &f->systick;
    c.cpu_clock_hz = b->cpu_hz;
    c.tim_clock_hz = b->tim_hz;
    c.pwm_hz = 20000u;
    c.control_hz = 1000u;
    c.enc_counter_bits = 32u;
    c.enc_filter = 3u;
    c.deadtime_ticks = b->deadtime_ticks;
    return c;
}

/* TIM1's outputs off: no duty, channels and main output disabled */
static int pwm_off(const fake_regs_t *f)
{
    return (f->tim1.BDTR & BR_TIM_BDTR_MOE) == 0u && f->tim1.CCER == 0u && f->tim1.CCR1 == 0u &&
           f->tim1.CCR2 == 0u;
}

static void fake_fill(fake_regs_t *f, unsigned char pattern)
{
    memset(f, pattern, sizeof *f);
}

static void port_up(br_stm32_t *port, fake_regs_t *f, uint32_t enc_bits)
{
    fake_fill(f, 0);
    br_stm32_cfg_t c = cfg_for(f);
    c.enc_counter_bits = enc_bits;
    assert_int_equal(br_stm32_init(port, &c), BR_OK);
}

/* ---- init ------------------------------------------------------------- */

static void test_init_programs_registers(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    fake_fill(&f, 0);
    f.tim2.SMCR = 0x00010007u; /* stale SMS bits, incl. SMS[3], must be replaced */
    f.systick.CTRL = BR_SYSTICK_CTRL_TICKINT;
    br_stm32_cfg_t c = cfg_for(&f);
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);

    /* encoder: mode 3, both inputs on their own pins, filter, full range, running */
    assert_int_equal(f.tim2.SMCR & BR_TIM_SMCR_SMS_Msk, 3u);
    assert_int_equal(f.tim2.CCMR1, 0x3131u); /* CC1S=01 IC1F=3, CC2S=01 IC2F=3 */
    assert_int_equal(f.tim2.CCER & (BR_TIM_CCER_CC1P | BR_TIM_CCER_CC2P), 0u);
    assert_int_equal(f.tim2.ARR, 0xFFFFFFFFu);
    assert_int_equal(f.tim2.PSC, 0u);
    assert_int_equal(f.tim2.CNT, 0u);
    assert_true((f.tim2.CR1 & BR_TIM_CR1_CEN) != 0u);

    /* PWM: centre-aligned 20 kHz -> ARR = tim_hz / (2 * 20e3) (the row's) */
    assert_int_equal(f.tim1.PSC, 0u);
    assert_int_equal(f.tim1.ARR, port_board.arr_20k);
    assert_int_equal(port.pwm_arr, port_board.arr_20k);
    assert_int_equal(f.tim1.CR1, BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE | BR_TIM_CR1_CEN);
    assert_int_equal(f.tim1.CCMR1, 0x6868u); /* OC1M = OC2M = PWM1, preload on */
    /* outputs off until the arm: channels and MOE cleared at init ... */
    assert_true(pwm_off(&f));
    assert_int_equal(f.tim1.BDTR & BR_TIM_BDTR_DTG_Msk, port_board.deadtime_ticks);
    /* ... and on, complementary pairs, at pwm_enable */
    assert_int_equal(br_stm32_pwm_enable(&port), BR_OK);
    assert_int_equal(f.tim1.CCER, BR_TIM_CCER_CC1E | BR_TIM_CCER_CC1NE | BR_TIM_CCER_CC2E | BR_TIM_CCER_CC2NE);
    assert_true((f.tim1.BDTR & BR_TIM_BDTR_MOE) != 0u);
    assert_int_equal(f.tim1.BDTR & BR_TIM_BDTR_DTG_Msk, port_board.deadtime_ticks);
    assert_int_equal(f.tim1.CCR1, 0u);
    assert_int_equal(f.tim1.CCR2, 0u);
    assert_true((f.tim1.EGR & BR_TIM_EGR_UG) != 0u);

    /* SysTick: processor clock, cpu_hz / 1000 cycles per tick, polled (no interrupt) */
    assert_int_equal(f.systick.LOAD, port_board.load_1ms);
    assert_int_equal(f.systick.CTRL, BR_SYSTICK_CTRL_CLKSOURCE | BR_SYSTICK_CTRL_ENABLE);

    /* 16-bit encoder timer: ARR = 0xFFFF */
    port_up(&port, &f, 16u);
    assert_int_equal(f.tim2.ARR, 0xFFFFu);
}

static void test_init_pwm_prescaler(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    fake_fill(&f, 0);
    br_stm32_cfg_t c = cfg_for(&f);
    c.pwm_hz = 1000u; /* tim_hz / 2000 ticks per half period > 16 bits: PSC = 1 */
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    assert_int_equal(f.tim1.PSC, 1u);
    assert_int_equal(f.tim1.ARR, port_board.arr_1k);
    /* a 64 MHz reset clock (the H7's HSI): 64 MHz timers, 20 kHz -> ARR 1600 */
    c.cpu_clock_hz = 64000000u;
    c.tim_clock_hz = 64000000u;
    c.pwm_hz = 20000u;
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    assert_int_equal(f.tim1.PSC, 0u);
    assert_int_equal(f.tim1.ARR, 1600u);
    assert_int_equal(f.systick.LOAD, 63999u);
}

/* Each rejected configuration leaves every register untouched and the port
 * unusable. */
static void expect_rejected(const br_stm32_cfg_t *c, fake_regs_t *f, br_status_t want)
{
    br_stm32_t port;
    fake_regs_t before;
    int32_t counts = 0;
    uint32_t tick = 0u;
    memcpy(&before, f, sizeof before);
    port.ready = 1;
    assert_int_equal(br_stm32_init(&port, c), want);
    assert_int_equal(memcmp(&before, f, sizeof before), 0);
    assert_int_equal(br_stm32_encoder_read(&port, &counts), BR_E_STATE);
    assert_int_equal(br_stm32_pwm_write(&port, 0.0f), BR_E_STATE);
    assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_E_STATE);
}

static void test_init_guards(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    fake_fill(&f, 0xA5);
    br_stm32_cfg_t c = cfg_for(&f);

    assert_int_equal(br_stm32_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_stm32_init(&port, NULL), BR_E_NULL);

    c = cfg_for(&f); c.pwm_tim = NULL;        expect_rejected(&c, &f, BR_E_NULL);
    c = cfg_for(&f); c.enc_tim = NULL;        expect_rejected(&c, &f, BR_E_NULL);
    c = cfg_for(&f); c.systick = NULL;        expect_rejected(&c, &f, BR_E_NULL);
    c = cfg_for(&f); c.enc_tim = &f.tim1;     expect_rejected(&c, &f, BR_E_PARAM); /* one timer, two jobs */
    c = cfg_for(&f); c.cpu_clock_hz = 0u;     expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.tim_clock_hz = 0u;     expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.pwm_hz = 0u;           expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.control_hz = 0u;       expect_rejected(&c, &f, BR_E_PARAM);
    /* PWM too fast for the timer clock: fewer than 100 steps */
    c = cfg_for(&f); c.pwm_hz = port_board.pwm_hz_too_fast; expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.pwm_hz = port_board.pwm_hz_100_steps; /* exactly 100 steps: accepted */
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    fake_fill(&f, 0xA5);
    c = cfg_for(&f); c.pwm_hz = 300000000u;   expect_rejected(&c, &f, BR_E_PARAM); /* > clock */
    /* tick: the period must be a whole number of cycles, >= 1000, <= 2^24 */
    c = cfg_for(&f); c.control_hz = 7u;       expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.control_hz = port_board.tick_hz_over_2p24;  expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.control_hz = port_board.tick_hz_500_cycles; expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.enc_counter_bits = 24u; expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.enc_counter_bits = 0u; expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.enc_filter = 16u;      expect_rejected(&c, &f, BR_E_PARAM);
    c = cfg_for(&f); c.deadtime_ticks = 128u; expect_rejected(&c, &f, BR_E_PARAM);
}

static void test_null_and_state(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    br_hal_t hal;
    int32_t counts;
    uint32_t tick;
    memset(&port, 0, sizeof port);
    assert_int_equal(br_stm32_hal(&port, &hal), BR_E_STATE);
    assert_int_equal(br_stm32_pwm_disable(&port), BR_E_STATE);
    port_up(&port, &f, 32u);
    assert_int_equal(br_stm32_encoder_read(NULL, &counts), BR_E_NULL);
    assert_int_equal(br_stm32_encoder_read(&port, NULL), BR_E_NULL);
    assert_int_equal(br_stm32_pwm_write(NULL, 0.0f), BR_E_NULL);
    assert_int_equal(br_stm32_pwm_disable(NULL), BR_E_NULL);
    assert_int_equal(br_stm32_tick_wait(NULL, &tick), BR_E_NULL);
    assert_int_equal(br_stm32_tick_wait(&port, NULL), BR_E_NULL);
    assert_int_equal(br_stm32_hal(NULL, &hal), BR_E_NULL);
    assert_int_equal(br_stm32_hal(&port, NULL), BR_E_NULL);
    assert_int_equal(br_stm32_gpio_af(NULL, 0u, 1u), BR_E_NULL);
}

/* ---- encoder ------------------------------------------------------------ */

/* Moves the fake 32-bit counter in steps across INT32_MAX -> INT32_MIN and
 * 0xFFFFFFFF -> 0: the counts equal the counter and every difference is the
 * step. */
static void test_encoder_32bit_wrap(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    port_up(&port, &f, 32u);
    const uint32_t starts[] = {0x7FFFF000u, 0xFFFFF000u};
    const int32_t steps[] = {1000, -1000, 4093};
    for (size_t s = 0; s < 2; ++s) {
        for (size_t d = 0; d < 3; ++d) {
            uint32_t raw = starts[s];
            int32_t prev = 0;
            f.tim2.CNT = raw;
            assert_int_equal(br_stm32_encoder_read(&port, &prev), BR_OK);
            assert_int_equal((uint32_t)prev, raw);
            for (int k = 0; k < 10; ++k) {
                int32_t now = 0;
                raw += (uint32_t)steps[d];
                f.tim2.CNT = raw;
                assert_int_equal(br_stm32_encoder_read(&port, &now), BR_OK);
                assert_int_equal((uint32_t)now, raw);
                assert_int_equal(br_counts_delta(now, prev), steps[d]);
                prev = now;
            }
        }
    }
}

/* A 16-bit timer: the port's extension keeps continuous counts through many
 * counter wraps, forwards and back. */
static void test_encoder_16bit_extension(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    port_up(&port, &f, 16u);
    int64_t pos = 0;
    int32_t counts = 0;
    const int32_t steps[] = {20000, 32767, -32767, -12345, 7};
    for (size_t d = 0; d < sizeof steps / sizeof steps[0]; ++d) {
        for (int k = 0; k < 25; ++k) {
            pos += steps[d];
            /* the timer holds pos mod 2^16; bits 16..31 of CNT read as 0 */
            f.tim2.CNT = (uint32_t)((uint64_t)pos & 0xFFFFu);
            assert_int_equal(br_stm32_encoder_read(&port, &counts), BR_OK);
            assert_int_equal(counts, (int32_t)pos);
        }
    }
    /* bits above the counter width are ignored */
    f.tim2.CNT = 0xABCD0000u | (uint32_t)((uint64_t)pos & 0xFFFFu);
    assert_int_equal(br_stm32_encoder_read(&port, &counts), BR_OK);
    assert_int_equal(counts, (int32_t)pos);
}

/* ---- PWM ------------------------------------------------------------------- */

static void expect_duty(br_stm32_t *port, fake_regs_t *f, float duty, br_status_t want, uint32_t ccr1,
                        uint32_t ccr2)
{
    f->tim1.CCR1 = 0xDEADu; /* stale values must be overwritten */
    f->tim1.CCR2 = 0xBEEFu;
    assert_int_equal(br_stm32_pwm_write(port, duty), want);
    assert_int_equal(f->tim1.CCR1, ccr1);
    assert_int_equal(f->tim1.CCR2, ccr2);
}

static void test_pwm_duty_mapping(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    port_up(&port, &f, 32u);
    const uint32_t arr = port_board.arr_20k; /* even on every board: duty 0.5 is ARR / 2 */
    expect_duty(&port, &f, 0.0f, BR_OK, 0u, 0u);
    expect_duty(&port, &f, -0.0f, BR_OK, 0u, 0u);
    expect_duty(&port, &f, 0.5f, BR_OK, arr / 2u, 0u);
    expect_duty(&port, &f, -0.5f, BR_OK, 0u, arr / 2u);
    expect_duty(&port, &f, 1.0f, BR_OK, arr, 0u);
    expect_duty(&port, &f, -1.0f, BR_OK, 0u, arr);
    expect_duty(&port, &f, 0.25f, BR_OK, port_board.ccr_quarter, 0u);
    expect_duty(&port, &f, 0.6f / (float)arr, BR_OK, 1u, 0u); /* 0.6 steps rounds to 1 */
    expect_duty(&port, &f, 0.4f / (float)arr, BR_OK, 0u, 0u); /* 0.4 steps to 0 */
    expect_duty(&port, &f, 1.7f, BR_OK, arr, 0u);             /* clamped */
    expect_duty(&port, &f, -1.7f, BR_OK, 0u, arr);
    expect_duty(&port, &f, 1.0e30f, BR_OK, arr, 0u);
    expect_duty(&port, &f, NAN, BR_E_INPUT, 0u, 0u);    /* rejected: output 0 */
    expect_duty(&port, &f, INFINITY, BR_E_INPUT, 0u, 0u);
    expect_duty(&port, &f, -INFINITY, BR_E_INPUT, 0u, 0u);

    /* safe stop: duty 0 and the main output enable cleared */
    f.tim1.CCR1 = 100u;
    assert_int_equal(br_stm32_pwm_disable(&port), BR_OK);
    assert_int_equal(f.tim1.CCR1, 0u);
    assert_int_equal(f.tim1.BDTR & BR_TIM_BDTR_MOE, 0u);
    assert_int_equal(f.tim1.BDTR & BR_TIM_BDTR_DTG_Msk, port_board.deadtime_ticks);
}

/* ---- tick ------------------------------------------------------------------ */

static void test_tick_polling(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    uint32_t tick = 99u;
    port_up(&port, &f, 32u);

    /* no wrap within LOAD + 1 polls: SysTick is not running */
    assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_E_STATE);
    assert_int_equal(tick, 99u);

    /* COUNTFLAG present: the tick is taken and indexed 0, 1, 2, ... The fake
     * keeps the flag (hardware clears it on the read), so each call here sees
     * it on entry, which the port counts as an overrun. */
    for (uint32_t k = 0; k < 3u; ++k) {
        f.systick.CTRL |= BR_SYSTICK_CTRL_COUNTFLAG;
        assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_OK);
        assert_int_equal(tick, k);
        assert_int_equal(port.overruns, k + 1u);
    }
    f.systick.CTRL &= ~BR_SYSTICK_CTRL_COUNTFLAG;
    assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_E_STATE);
    assert_int_equal(port.next_tick, 3u);
    /* init restarts the index */
    port_up(&port, &f, 32u);
    f.systick.CTRL |= BR_SYSTICK_CTRL_COUNTFLAG;
    assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_OK);
    assert_int_equal(tick, 0u);
}

/* ---- br_hal_t and board helpers ------------------------------------------ */

static void test_hal_adapter(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    br_hal_t hal;
    int32_t counts = 0;
    uint32_t tick = 0u;
    port_up(&port, &f, 32u);
    assert_int_equal(br_stm32_hal(&port, &hal), BR_OK);
    assert_ptr_equal(hal.ctx, &port);
    f.tim2.CNT = 0xFFFFFFFEu;
    assert_int_equal(hal.encoder_read(hal.ctx, &counts), BR_OK);
    assert_int_equal(counts, -2);
    assert_int_equal(hal.pwm_write(hal.ctx, -0.5f), BR_OK);
    assert_int_equal(f.tim1.CCR2, port_board.arr_20k / 2u);
    assert_int_equal(hal.pwm_write(hal.ctx, NAN), BR_E_INPUT);
    assert_int_equal(f.tim1.CCR2, 0u);
    f.systick.CTRL |= BR_SYSTICK_CTRL_COUNTFLAG;
    assert_int_equal(hal.tick_wait(hal.ctx, &tick), BR_OK);
}

static void test_gpio_af(void **st)
{
    (void)st;
    br_stm32_gpio_t gpio;
    memset(&gpio, 0, sizeof gpio);
    gpio.MODER = 0xFFFFFFFFu; /* reset state of most ports: analog */
    gpio.AFR[1] = 0xFFFFFFFFu;
    assert_int_equal(br_stm32_gpio_af(&gpio, 9u, 1u), BR_OK); /* PA9 TIM1_CH2 */
    assert_int_equal(gpio.MODER, 0xFFFBFFFFu);                  /* bits 19:18 = 10 */
    assert_int_equal(gpio.AFR[1], 0xFFFFFF1Fu);                 /* pin 9 -> AFRH nibble 1 */
    assert_int_equal((gpio.OSPEEDR >> 18) & 3u, 2u);
    assert_int_equal(br_stm32_gpio_af(&gpio, 0u, 1u), BR_OK);
    assert_int_equal(gpio.AFR[0] & 0xFu, 1u);
    assert_int_equal(gpio.MODER & 3u, 2u);
    assert_int_equal(br_stm32_gpio_af(&gpio, 16u, 1u), BR_E_PARAM);
    assert_int_equal(br_stm32_gpio_af(&gpio, 3u, 16u), BR_E_PARAM);
}

/* ---- fail-safe: the PWM goes off (docs/reliability.md) --------------------- */

static void test_deadline_disables_pwm(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    uint32_t tick = 0u;
    port_up(&port, &f, 32u);
    assert_int_equal(br_stm32_pwm_enable(&port), BR_OK);
    assert_int_equal(br_stm32_pwm_write(&port, 0.5f), BR_OK);
    /* the fake keeps COUNTFLAG: every tick_wait is a missed period */
    f.systick.CTRL |= BR_SYSTICK_CTRL_COUNTFLAG;
    for (uint32_t k = 0u; k < 2u; ++k) {
        assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_OK);
        assert_int_equal(br_stm32_deadline_check(&port, 2u), BR_OK);
        assert_false(pwm_off(&f));
    }
    assert_int_equal(br_stm32_tick_wait(&port, &tick), BR_OK);
    assert_int_equal(br_stm32_deadline_check(&port, 2u), BR_E_FAULT); /* 3 > 2 */
    assert_true(pwm_off(&f));
    /* an arm restarts the count */
    assert_int_equal(br_stm32_pwm_enable(&port), BR_OK);
    assert_int_equal(br_stm32_deadline_check(&port, 2u), BR_OK);
    assert_int_equal(br_stm32_deadline_check(NULL, 2u), BR_E_NULL);
}

/* br_app over the port on the fake registers: a latched fault turns TIM1 off */
typedef struct {
    fake_regs_t f;
    br_stm32_t port;
    br_hal_t hal;
    br_ctrl_cfg_t k;
    br_app_cfg_t c;
    br_app_t app;
} app_rig_t;

static void app_up(app_rig_t *g)
{
    memset(g, 0, sizeof *g);
    port_up(&g->port, &g->f, 32u);
    assert_int_equal(br_stm32_hal(&g->port, &g->hal), BR_OK);
    g->k = (br_ctrl_cfg_t){{-0.5f, -0.01f, -10.0f}, 1e-3f, 0.64f, 0.64f, 6.0e-6f, 1.27e-3f};
    const br_app_guard_cfg_t guard = {100u, 3u, 10u, 2u};
    g->c = (br_app_cfg_t){&g->k, BR_APP_EST_NONE, NULL, NULL, NULL, guard, BR_TEST_WIDE_MOTION};
    assert_int_equal(br_app_init(&g->app, &g->c, &g->hal, NULL), BR_OK);
    assert_true(pwm_off(&g->f)); /* disarmed */
    assert_int_equal(br_app_arm(&g->app), BR_OK);
    assert_true((g->f.tim1.BDTR & BR_TIM_BDTR_MOE) != 0u);
    /* a large position error: a large duty */
    const br_ref_t r = {120000, 0.0f, 0.0f};
    assert_int_equal(br_app_step(&g->app, &r), BR_OK);
    assert_true(g->f.tim1.CCR1 > port_board.arr_20k / 2u);
    assert_false(pwm_off(&g->f));
}

static void test_app_faults_disable_pwm(void **st)
{
    (void)st;
    app_rig_t g;
    const br_ref_t r = {120000, 0.0f, 0.0f};
    /* encoder jump: the counter leaps 101 counts in one period */
    app_up(&g);
    g.f.tim2.CNT += 101u;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_JUMP);
    assert_true(pwm_off(&g.f));
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT); /* stays off */
    assert_true(pwm_off(&g.f));
    /* a latched application fault (a non-finite reference) */
    app_up(&g);
    const br_ref_t bad = {0, 0.0f, NAN};
    assert_int_equal(br_app_step(&g.app, &bad), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_CTRL_INPUT);
    /* the position is trusted: the braking ramp (from standstill: its
     * settle periods) with the PWM on, then off */
    assert_int_equal(g.app.stop, BR_APP_STOP_BRAKING);
    assert_false(pwm_off(&g.f));
    for (int i = 0; i < 100 && g.app.stop == BR_APP_STOP_BRAKING; i++) {
        assert_int_equal(br_app_step(&g.app, &bad), BR_E_FAULT);
    }
    assert_true(pwm_off(&g.f));
    /* deadline: the port trips, the application latches */
    app_up(&g);
    uint32_t tick = 0u;
    g.f.systick.CTRL |= BR_SYSTICK_CTRL_COUNTFLAG;
    assert_int_equal(br_stm32_tick_wait(&g.port, &tick), BR_OK);
    assert_int_equal(br_stm32_deadline_check(&g.port, 0u), BR_E_FAULT);
    assert_true(pwm_off(&g.f));
    assert_int_equal(br_app_fault(&g.app, BR_APP_FAULT_DEADLINE), BR_E_FAULT);
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_true(pwm_off(&g.f));
    /* re-arm: on again */
    g.f.tim2.CNT += 1u;
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    assert_false(pwm_off(&g.f));
}

/* ---- control period that is no whole frequency ---------------------------- */

static void test_control_period_ns(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    fake_fill(&f, 0);
    br_stm32_cfg_t c = cfg_for(&f);
    c.control_hz = 0u;
    c.control_period_ns = 1500000u; /* the PF's 1.5 ms: cpu_hz * 1.5e-3 cycles */
    assert_int_equal(br_stm32_init(&port, &c), BR_OK);
    assert_int_equal(f.systick.LOAD, port_board.load_1500us);
    c.control_hz = 1000u; /* both */
    assert_int_equal(br_stm32_init(&port, &c), BR_E_PARAM);
    c.control_hz = 0u;
    c.control_period_ns = 0u; /* neither */
    assert_int_equal(br_stm32_init(&port, &c), BR_E_PARAM);
    c.control_period_ns = 1500001u; /* not a whole number of cycles */
    assert_int_equal(br_stm32_init(&port, &c), BR_E_PARAM);
    c.control_period_ns = port_board.period_ns_over_2p24; /* more than 2^24 cycles */
    assert_int_equal(br_stm32_init(&port, &c), BR_E_PARAM);
}

/* ---- watchdog ---------------------------------------------------------------- */

static void test_iwdg(void **st)
{
    (void)st;
    br_stm32_iwdg_t w;
    memset(&w, 0, sizeof w);
    assert_int_equal(br_stm32_iwdg_start(&w, 0u, 79u), BR_OK); /* /4, 80 ticks: 10 ms */
    assert_int_equal(w.PR, 0u);
    assert_int_equal(w.RLR, 79u);
    assert_int_equal(w.KR, 0xAAAAu); /* the last key: the first refresh */
    w.KR = 0u;
    br_stm32_iwdg_refresh(&w);
    assert_int_equal(w.KR, 0xAAAAu);
    memset(&w, 0, sizeof w);
    assert_int_equal(br_stm32_iwdg_start(&w, 7u, 79u), BR_E_PARAM);
    assert_int_equal(br_stm32_iwdg_start(&w, 0u, 0x1000u), BR_E_PARAM);
    assert_int_equal(br_stm32_iwdg_start(&w, 0u, 0u), BR_E_PARAM);
    assert_int_equal(w.KR, 0u); /* rejected before any key */
    assert_int_equal(br_stm32_iwdg_start(NULL, 0u, 79u), BR_E_NULL);
    w.SR = 1u; /* a prescaler update that never ends: bounded, no refresh */
    assert_int_equal(br_stm32_iwdg_start(&w, 0u, 79u), BR_E_STATE);
    assert_int_equal(w.KR, 0x5555u);
}

/* ---- the board's bring-up from its table (bristle/br_stm32_board.h) ------------ */

typedef struct {
    fake_regs_t t;
    br_stm32_gpio_t gpioa;
    br_stm32_gpio_t gpiob;
    br_stm32_usart_t usart;
    br_stm32_iwdg_t iwdg;
} fake_board_t;

/* the clock tree as the board's clocks function sees it: a test-set status */
static br_status_t fake_clocks_status;
static int fake_clocks_calls;
static br_status_t fake_clocks(void)
{
    ++fake_clocks_calls;
    return fake_clocks_status;
}
static int fake_reset_by_watchdog(void)
{
    return 0;
}

/* a table like hal/<part>/board's, over fake blocks, with the board's clocks
 * and its part's USART DMA side (port_board.usart_dma) */
static br_stm32_board_t board_for(fake_board_t *f)
{
    memset(f, 0, sizeof *f);
    fake_clocks_status = BR_OK;
    fake_clocks_calls = 0;
    br_stm32_board_t b;
    memset(&b, 0, sizeof b);
    b.clocks = fake_clocks;
    b.port = cfg_for(&f->t);
    b.port.control_hz = 0u;
    const br_stm32_pin_t pins[6] = {{&f->gpioa, 0u, 1u}, {&f->gpioa, 1u, 1u},  {&f->gpioa, 8u, 6u},
                                    {&f->gpioa, 9u, 6u}, {&f->gpiob, 13u, 6u}, {&f->gpiob, 14u, 6u}};
    memcpy(b.pins, pins, sizeof pins);
    b.n_pins = 6u;
    b.usart_dma = port_board.usart_dma;
    b.usart = &f->usart;
    b.usart_clock_hz = port_board.usart_hz;
    b.baud = 921600u;
    b.usart_pins[0] = (br_stm32_pin_t){&f->gpioa, 2u, 7u};
    b.usart_pins[1] = (br_stm32_pin_t){&f->gpioa, 3u, 7u};
    b.iwdg = &f->iwdg;
    b.iwdg_pr = 0u;
    b.iwdg_rlr = 79u;
    b.reset_by_watchdog = fake_reset_by_watchdog;
    return b;
}

static void test_board_bringup(void **st)
{
    (void)st;
    fake_board_t f;
    br_stm32_board_t b = board_for(&f);
    br_stm32_t port;
    br_hal_t hal;
    /* the control period is the caller's: the PF's 1.5 ms */
    assert_int_equal(br_stm32_board_init(&b, 1500000u, &port, &hal), BR_OK);
    assert_int_equal(fake_clocks_calls, 1);
    assert_int_equal(f.t.systick.LOAD, port_board.load_1500us);
    assert_int_equal(f.t.tim1.ARR, port_board.arr_20k);
    assert_true(pwm_off(&f.t));
    assert_ptr_equal(hal.ctx, &port);
    /* the pins on their functions: PA8 AF6 (AFRH nibble 0), PB14 AF6 (nibble 6) */
    assert_int_equal((f.gpioa.MODER >> 16) & 3u, 2u);
    assert_int_equal(f.gpioa.AFR[1] & 0xFu, 6u);
    assert_int_equal((f.gpiob.AFR[1] >> 24) & 0xFu, 6u);
    assert_int_equal(f.gpioa.AFR[0] & 0xFFu, 0x11u);

    /* a clock tree that fails: its status, no timer register written */
    b = board_for(&f);
    fake_clocks_status = BR_E_STATE;
    fake_board_t before;
    memcpy(&before, &f, sizeof before);
    assert_int_equal(br_stm32_board_init(&b, 1000000u, &port, &hal), BR_E_STATE);
    assert_memory_equal(&before, &f, sizeof before);
    /* a pin that does not exist: refused before the port */
    b = board_for(&f);
    b.pins[2].pin = 16u;
    assert_int_equal(br_stm32_board_init(&b, 1000000u, &port, &hal), BR_E_PARAM);
    assert_int_equal(f.t.tim1.ARR, 0u);
    b = board_for(&f);
    b.n_pins = BR_STM32_BOARD_PINS_MAX + 1u;
    assert_int_equal(br_stm32_board_init(&b, 1000000u, &port, &hal), BR_E_PARAM);
    assert_int_equal(fake_clocks_calls, 0);
    b.n_pins = 6u;
    b.clocks = NULL;
    assert_int_equal(br_stm32_board_init(&b, 1000000u, &port, &hal), BR_E_NULL);
    assert_int_equal(br_stm32_board_init(NULL, 1000000u, &port, &hal), BR_E_NULL);
    b = board_for(&f);
    assert_int_equal(br_stm32_board_init(&b, 1000000u, NULL, &hal), BR_E_NULL);
    assert_int_equal(br_stm32_board_init(&b, 1000000u, &port, NULL), BR_E_NULL);
    /* a period that is no whole number of cycles: the port's guard */
    assert_int_equal(br_stm32_board_init(&b, 1000001u, &port, &hal), BR_E_PARAM);
}

/* the link's USART from the table: the part's DMA side, the pins, the baud
 * rate from the board's kernel clock, the RX stream running */
static void test_board_usart(void **st)
{
    (void)st;
    fake_board_t f;
    const br_stm32_board_t b = board_for(&f);
    uint8_t rx[256]; /* 1 ms at 921 600 baud is 93 bytes: at least 186 */
    uint8_t tx[16];
    br_stm32_usart_chan_t u;
    assert_int_equal(br_stm32_board_usart_init(&b, &u, rx, sizeof rx, tx, sizeof tx, 1000000u), BR_OK);
    assert_int_equal(f.usart.BRR, port_board.usart_brr_921600);
    assert_int_equal(f.usart.CR3, BR_USART_CR3_DMAR | BR_USART_CR3_DMAT);
    assert_int_equal(u.cfg.rx_dma->NDTR, sizeof rx);
    assert_true((u.cfg.rx_dma->CR & BR_DMA_CR_EN) != 0u);
    assert_int_equal(u.cfg.tx_dma->CR & BR_DMA_CR_EN, 0u);
    assert_int_equal((f.gpioa.AFR[0] >> 8) & 0xFFu, 0x77u); /* PA2, PA3 AF7 */
    /* the channel's own guard (a buffer the line laps in two periods) comes through */
    assert_int_equal(br_stm32_board_usart_init(&b, &u, rx, 185u, tx, sizeof tx, 1000000u), BR_E_PARAM);
    br_stm32_board_t nodma = b;
    nodma.usart_dma = NULL;
    assert_int_equal(br_stm32_board_usart_init(&nodma, &u, rx, sizeof rx, tx, sizeof tx, 1000000u), BR_E_NULL);
    assert_int_equal(br_stm32_board_usart_init(NULL, &u, rx, sizeof rx, tx, sizeof tx, 1000000u), BR_E_NULL);
}

/* the watchdog from the table: started with the board's prescaler and
 * reload, refreshed */
static void test_board_watchdog(void **st)
{
    (void)st;
    fake_board_t f;
    br_stm32_board_t b = board_for(&f);
    assert_int_equal(br_stm32_board_watchdog_start(&b), BR_OK);
    assert_int_equal(f.iwdg.RLR, 79u);
    assert_int_equal(f.iwdg.KR, 0xAAAAu);
    f.iwdg.KR = 0u;
    br_stm32_board_watchdog_refresh(&b);
    assert_int_equal(f.iwdg.KR, 0xAAAAu);
    assert_int_equal(br_stm32_board_watchdog_start(NULL), BR_E_NULL);
    br_stm32_board_watchdog_refresh(NULL); /* nothing to refresh: returns */
    b.iwdg = NULL;
    assert_int_equal(br_stm32_board_watchdog_start(&b), BR_E_NULL);
}

/* the suite's cases, then the board's own (port_board.h) */
int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_programs_registers),
        cmocka_unit_test(test_init_pwm_prescaler),
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_null_and_state),
        cmocka_unit_test(test_encoder_32bit_wrap),
        cmocka_unit_test(test_encoder_16bit_extension),
        cmocka_unit_test(test_pwm_duty_mapping),
        cmocka_unit_test(test_tick_polling),
        cmocka_unit_test(test_hal_adapter),
        cmocka_unit_test(test_gpio_af),
        cmocka_unit_test(test_deadline_disables_pwm),
        cmocka_unit_test(test_app_faults_disable_pwm),
        cmocka_unit_test(test_control_period_ns),
        cmocka_unit_test(test_iwdg),
        cmocka_unit_test(test_board_bringup),
        cmocka_unit_test(test_board_usart),
        cmocka_unit_test(test_board_watchdog),
        {"rcc_enable", port_board.test_rcc_enable, NULL, NULL, NULL},
        {"clock_tree", port_board.test_clock_tree, NULL, NULL, NULL},
        {"usart_dma", port_board.test_usart_dma, NULL, NULL, NULL},
    };
    print_message("board %s\n", port_board.name);
    return cmocka_run_group_tests_name(port_board.name, tests, NULL, NULL);
}
