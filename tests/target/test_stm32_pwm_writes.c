/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32 PWM driver (every STM32 port's: hal/stm32) never drives both legs
 * of the bridge at once, at any single register store: the driver is built
 * here with BR_STM32_REG_HOOK (hal/stm32/br_stm32_access.h), so every
 * compare-register store of br_stm32_pwm_write comes through br_stm32_reg_write below, which
 * makes the store and checks the pair (CCR1, CCR2) right after it. The
 * final-state test (test_stm32h7) cannot see an intermediate store: writing
 * the active leg before releasing the idle one ends in the same registers. */
#include "br_test.h"

#include <string.h>

#include "bristle/br_stm32.h"
#include "br_stm32_access.h"

typedef struct {
    br_stm32_tim_t tim1;
    br_stm32_tim_t tim2;
    br_stm32_systick_t systick;
} fake_regs_t;

/* the recorder (test code: one instance, reset per test) */
typedef struct {
    const br_stm32_tim_t *tim;  /* the bridge's timer */
    long stores;                  /* CCR1 / CCR2 stores seen */
    long both_on;                 /* stores after which CCR1 and CCR2 were both non-zero */
    long other;                   /* stores to any other register */
} recorder_t;

static recorder_t rec;

void br_stm32_reg_write(volatile uint32_t *reg, uint32_t value)
{
    *reg = value;
    if (reg == &rec.tim->CCR1 || reg == &rec.tim->CCR2) {
        rec.stores++;
        rec.both_on += (rec.tim->CCR1 != 0u && rec.tim->CCR2 != 0u);
    } else {
        rec.other++;
    }
}

static void port_up(br_stm32_t *port, fake_regs_t *f)
{
    memset(f, 0, sizeof *f);
    br_stm32_cfg_t c;
    memset(&c, 0, sizeof c);
    c.pwm_tim = &f->tim1;
    c.enc_tim = &f->tim2;
    c.systick = &f->systick;
    c.cpu_clock_hz = 480000000u;
    c.tim_clock_hz = 240000000u;
    c.pwm_hz = 20000u;
    c.control_hz = 1000u;
    c.enc_counter_bits = 32u;
    c.enc_filter = 3u;
    c.deadtime_ticks = 48u;
    assert_int_equal(br_stm32_init(port, &c), BR_OK);
    memset(&rec, 0, sizeof rec);
    rec.tim = &f->tim1;
}

/* the hook sees the stores: a write sets both compare registers, idle leg first */
static void test_stores_are_recorded(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    port_up(&port, &f);
    assert_int_equal(br_stm32_pwm_write(&port, 0.5f), BR_OK);
    assert_int_equal(rec.stores, 2);
    assert_int_equal(f.tim1.CCR1, 3000u);
    assert_int_equal(f.tim1.CCR2, 0u);
    assert_int_equal(rec.other, 0);
}

/* Reversals between every pair of duties of a grid, both ways, then a
 * pseudo-random walk and the rejected inputs: after no single store are both
 * legs driven. */
static void test_never_both_legs(void **st)
{
    (void)st;
    fake_regs_t f;
    br_stm32_t port;
    port_up(&port, &f);
    const float grid[] = {-1.5f, -1.0f, -0.5f, -1.0e-4f, -0.0f, 0.0f, 1.0e-4f, 0.25f, 0.5f, 1.0f, 1.5f};
    const unsigned n = (unsigned)(sizeof grid / sizeof grid[0]);
    long writes = 0;
    for (unsigned a = 0; a < n; a++) {
        for (unsigned b = 0; b < n; b++) {
            assert_int_equal(br_stm32_pwm_write(&port, grid[a]), BR_OK);
            assert_int_equal(br_stm32_pwm_write(&port, grid[b]), BR_OK);
            writes += 2;
        }
    }
    uint32_t s = 12345u;
    for (int k = 0; k < 10000; k++) {
        s = s * 1664525u + 1013904223u; /* LCG: a reproducible walk over [-1.2, 1.2] */
        const float duty = 2.4f * ((float)(s >> 8) / 16777216.0f) - 1.2f;
        assert_int_equal(br_stm32_pwm_write(&port, duty), BR_OK);
        writes++;
        if ((k % 997) == 0) {
            assert_int_equal(br_stm32_pwm_write(&port, NAN), BR_E_INPUT); /* output 0 */
            writes++;
        }
    }
    print_message("  %ld writes, %ld compare-register stores, %ld with both legs on\n", writes, rec.stores,
                  rec.both_on);
    assert_int_equal(rec.stores, 2 * writes);
    assert_int_equal(rec.both_on, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stores_are_recorded),
        cmocka_unit_test(test_never_both_legs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
