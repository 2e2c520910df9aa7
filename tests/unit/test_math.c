/* br_exp_neg (br_math.h): accuracy over its range against double exp, the
 * edges (underflow, NaN, -inf, positive input), monotonicity. */
#include "br_test.h"

#include "br_math.h"

/* every float in (-87, 0] would be 1.1e9 points; a dense geometric-plus-linear
 * sweep of 2e6 points covers each binade and every exponent n */
static void test_accuracy(void **st)
{
    (void)st;
    double worst = 0.0, at = 0.0;
    const int n = 2000000;
    for (int i = 0; i < n; i++) { /* (-87, 0]: -87 itself gives 0 */
        const float x = -87.0f * (float)i / (float)n;
        const double rel = fabs((double)br_exp_neg(x) / exp((double)x) - 1.0);
        if (rel > worst) {
            worst = rel;
            at = (double)x;
        }
    }
    for (int e = -40; e <= 6; e++) { /* tiny arguments: e^x ~ 1 + x */
        const float x = -ldexpf(1.0f, e);
        const double rel = fabs((double)br_exp_neg(x) / exp((double)x) - 1.0);
        if (rel > worst) {
            worst = rel;
            at = (double)x;
        }
    }
    print_message("br_exp_neg: worst relative error %.3g at x = %.9g\n", worst, at);
    assert_true(worst < 5e-6); /* the bound br_math.h states and the golden PF test uses */
}

static void test_edges(void **st)
{
    (void)st;
    assert_true(br_exp_neg(0.0f) == 1.0f);
    assert_true(br_exp_neg(-0.0f) == 1.0f);
    assert_true(br_exp_neg(2.5f) == 1.0f); /* positive input is taken as 0 */
    assert_true(br_exp_neg(INFINITY) == 1.0f);
    assert_true(br_exp_neg(-87.0f) == 0.0f); /* below the normal range */
    assert_true(br_exp_neg(-1000.0f) == 0.0f);
    assert_true(br_exp_neg(-INFINITY) == 0.0f);
    assert_true(br_exp_neg(NAN) == 0.0f);
    assert_true(br_exp_neg(-86.99f) > 0.0f && isnormal(br_exp_neg(-86.99f)));
}

/* Weights must not reorder particles: e^x is non-decreasing over a sweep. */
static void test_monotone(void **st)
{
    (void)st;
    float prev = 0.0f;
    int n_bad = 0;
    for (int i = 0; i <= 1000000; i++) {
        const float x = -87.0f + 87.0f * (float)i / 1e6f;
        const float v = br_exp_neg(x);
        n_bad += v < prev;
        prev = v;
    }
    print_message("br_exp_neg: %d decreases over 1e6 increasing arguments\n", n_bad);
    assert_int_equal(n_bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accuracy),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_monotone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
