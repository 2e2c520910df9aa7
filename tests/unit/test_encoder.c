/* SPDX-License-Identifier: Apache-2.0 */
/* Wrap-safe count differences. */
#include "br_test.h"

#include "bristle/br_encoder.h"

static void test_delta_plain(void **st)
{
    (void)st;
    assert_int_equal(br_counts_delta(10, 3), 7);
    assert_int_equal(br_counts_delta(3, 10), -7);
    assert_int_equal(br_counts_delta(0, 0), 0);
}

static void test_delta_across_wrap(void **st)
{
    (void)st;
    /* the counter wraps from INT32_MAX to INT32_MIN: +1 step, and back: -1 */
    assert_int_equal(br_counts_delta(INT32_MIN, INT32_MAX), 1);
    assert_int_equal(br_counts_delta(INT32_MAX, INT32_MIN), -1);
    assert_int_equal(br_counts_delta(INT32_MIN + 99, INT32_MAX - 100), 200);
    assert_int_equal(br_counts_delta(INT32_MAX - 100, INT32_MIN + 99), -200);
    /* the extremes of the representable difference */
    assert_int_equal(br_counts_delta(INT32_MAX, 0), INT32_MAX);
    assert_int_equal(br_counts_delta(INT32_MIN, 0), INT32_MIN);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_delta_plain), cmocka_unit_test(test_delta_across_wrap)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
