/* SPDX-License-Identifier: Apache-2.0 */
/* The conversions every port shares (bristle/br_port.h, docs/porting.md):
 * the encoder counter's extension to int32, the duty's sign-magnitude split,
 * the exact control tick. The ports' own tests (tests/target) check them
 * again through their registers. */
#include "br_test.h"

#include <math.h>

#include "bristle/br_encoder.h"
#include "bristle/br_port.h"

/* The generic extension: past the int32 range it wraps like a free-running
 * int32 counter (br_counts_delta stays exact); a move of exactly half the
 * counter range is read backwards (the documented limit). */
static void test_count_ext_generic(void **st)
{
    (void)st;
    br_count_ext_t e;
    assert_int_equal(br_count_ext_init(NULL, 16u, 0u), BR_E_NULL);
    assert_int_equal(br_count_ext_init(&e, 1u, 0u), BR_E_PARAM);
    assert_int_equal(br_count_ext_init(&e, 33u, 0u), BR_E_PARAM);

    assert_int_equal(br_count_ext_init(&e, 16u, 0xFFF0u), BR_OK);
    uint32_t raw = 0xFFF0u;
    uint64_t total = 0xFFF0u;
    int32_t prev = (int32_t)0xFFF0;
    for (int k = 0; k < 100000; ++k) { /* 3e9 counts: beyond INT32_MAX */
        raw = (raw + 30000u) & 0xFFFFu;
        total += 30000u;
        int32_t now = br_count_ext_update(&e, raw);
        assert_int_equal(br_counts_delta(now, prev), 30000);
        assert_int_equal((uint32_t)now, (uint32_t)total);
        prev = now;
    }

    /* 12-bit counter, half-range limit */
    assert_int_equal(br_count_ext_init(&e, 12u, 0u), BR_OK);
    assert_int_equal(br_count_ext_update(&e, 2047u), 2047);
    assert_int_equal(br_count_ext_update(&e, 0u), 0);
    assert_int_equal(br_count_ext_update(&e, 2048u), -2048);
    assert_int_equal(br_count_ext_update(&e, 4095u), -1);
    assert_int_equal(br_count_ext_update(&e, 1u), 1);

    /* 32-bit counter: the extension is the counter itself */
    assert_int_equal(br_count_ext_init(&e, 32u, 0x7FFFFFFFu), BR_OK);
    assert_int_equal(br_count_ext_update(&e, 0x80000000u), INT32_MIN);
    assert_int_equal(br_count_ext_update(&e, 0xFFFFFFFFu), -1);
    assert_int_equal(br_count_ext_update(&e, 0x00000002u), 2);
}

static void expect_split(float duty, uint32_t full, br_status_t want, uint32_t a, uint32_t b)
{
    uint32_t ca = 0xDEADu;
    uint32_t cb = 0xBEEFu; /* stale values must be overwritten */
    assert_int_equal(br_duty_split(duty, full, &ca, &cb), want);
    assert_int_equal(ca, a);
    assert_int_equal(cb, b);
}

/* Sign to leg A or B, rounding to nearest, the clamp at |duty| = 1, and the
 * guard: a non-finite duty gives 0 on both legs and BR_E_INPUT. */
static void test_duty_split(void **st)
{
    (void)st;
    expect_split(0.0f, 6000u, BR_OK, 0u, 0u);
    expect_split(-0.0f, 6000u, BR_OK, 0u, 0u);
    expect_split(0.5f, 6000u, BR_OK, 3000u, 0u);
    expect_split(-0.5f, 6000u, BR_OK, 0u, 3000u);
    expect_split(1.0e-4f, 6000u, BR_OK, 1u, 0u);   /* 0.6 steps rounds to 1 */
    expect_split(0.5f / 6000.0f * 0.98f, 6000u, BR_OK, 0u, 0u); /* 0.49 steps rounds to 0 */
    expect_split(1.7f, 6000u, BR_OK, 6000u, 0u);   /* clamped */
    expect_split(-1.0e30f, 6000u, BR_OK, 0u, 6000u);
    expect_split(1.0f, 1u << 24, BR_OK, 1u << 24, 0u); /* the largest full range */
    expect_split(NAN, 6000u, BR_E_INPUT, 0u, 0u);
    expect_split(INFINITY, 6000u, BR_E_INPUT, 0u, 0u);
    expect_split(-INFINITY, 6000u, BR_E_INPUT, 0u, 0u);
    expect_split(0.5f, (1u << 24) + 1u, BR_E_PARAM, 0u, 0u);
    uint32_t a;
    assert_int_equal(br_duty_split(0.5f, 100u, NULL, &a), BR_E_NULL);
    assert_int_equal(br_duty_split(0.5f, 100u, &a, NULL), BR_E_NULL);
}

/* Exactly one of the rate and the period; the tick exact in cycles; bounds. */
static void test_tick_cycles(void **st)
{
    (void)st;
    uint32_t c = 0u;
    assert_int_equal(br_tick_cycles(480000000u, 1000u, 0u, 1000u, 1u << 24, &c), BR_OK);
    assert_int_equal(c, 480000u);
    assert_int_equal(br_tick_cycles(480000000u, 0u, 1500000u, 1000u, 1u << 24, &c), BR_OK);
    assert_int_equal(c, 720000u);
    assert_int_equal(br_tick_cycles(170000000u, 0u, 1500000u, 1000u, 1u << 24, &c), BR_OK);
    assert_int_equal(c, 255000u);
    assert_int_equal(br_tick_cycles(480000000u, 1000u, 1500000u, 1000u, 1u << 24, &c), BR_E_PARAM); /* both */
    assert_int_equal(br_tick_cycles(480000000u, 0u, 0u, 1000u, 1u << 24, &c), BR_E_PARAM);          /* neither */
    assert_int_equal(br_tick_cycles(0u, 1000u, 0u, 1000u, 1u << 24, &c), BR_E_PARAM);
    assert_int_equal(br_tick_cycles(480000000u, 7u, 0u, 1000u, 1u << 24, &c), BR_E_PARAM);   /* not exact */
    assert_int_equal(br_tick_cycles(1000000u, 0u, 1000001u, 1000u, 1u << 24, &c), BR_E_PARAM); /* 1000.001 cycles */
    assert_int_equal(br_tick_cycles(480000000u, 1000000u, 0u, 1000u, 1u << 24, &c), BR_E_PARAM); /* 480 < min */
    assert_int_equal(br_tick_cycles(480000000u, 10u, 0u, 1000u, 1u << 24, &c), BR_E_PARAM);     /* > max */
    assert_int_equal(br_tick_cycles(480000000u, 1000u, 0u, 1000u, 1u << 24, NULL), BR_E_NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_count_ext_generic),
        cmocka_unit_test(test_duty_split),
        cmocka_unit_test(test_tick_cycles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
