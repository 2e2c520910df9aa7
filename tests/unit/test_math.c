/* SPDX-License-Identifier: Apache-2.0 */
/* br_exp_neg (br_math.h): accuracy over its range against double exp, the
 * edges (underflow, NaN, -inf, positive input), monotonicity; the PF's
 * quantised form br_exp_neg_w16_k against the product it replaces. */
#include "br_test.h"

#include "br_math.h"
#include "br_lugre_kernel.h"

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
/* br_exp_neg_w16_k: the PF's quantised weight (uint32_t)(e^x 2^16) with the
 * scale in the exponent equals the product's, on every float of (-88, -85]
 * (where 2^n e^y turns subnormal), a sweep of (-85, 0], the edges */
static void test_w16_is_quantised_product(void **st)
{
    (void)st;
    const br_exp_k_t k = br_exp_k();
    long n = 0, bad = 0;
    float x = -88.0f;
    while (x <= -85.0f) {
        bad += (uint32_t)br_exp_neg_w16_k(x, k) != (uint32_t)(br_exp_neg_k(x, k) * 65536.0f);
        x = nextafterf(x, 0.0f);
        n++;
    }
    for (int i = 0; i <= 1000000; i++) {
        const float y = -85.0f * (float)i / 1.0e6f;
        bad += (uint32_t)br_exp_neg_w16_k(y, k) != (uint32_t)(br_exp_neg_k(y, k) * 65536.0f);
        n++;
    }
    const float edge[] = {0.0f, -0.0f, 2.5f, INFINITY, -INFINITY, NAN, -87.0f, -1.0e-30f};
    for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++) {
        bad += (uint32_t)br_exp_neg_w16_k(edge[i], k) != (uint32_t)(br_exp_neg_k(edge[i], k) * 65536.0f);
        n++;
    }
    assert_true(br_exp_neg_w16_k(0.0f, k) == 65536.0f); /* the best particle: W = 2^16 */
    print_message("br_exp_neg_w16_k: %ld inputs, %ld differ from the product\n", n, bad);
    assert_int_equal(bad, 0);
}

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

/* The LuGre kernel's move over a step (br_lk_move_over, docs/modules/lugre.md)
 * where r = sigma0 |dx| / g is below 1e-6 and (1 - e^-r) / r is taken by its
 * series 1 - r/2: from rest (z0 = 0) the bristle deflects linearly, so
 * int z dt = h zss (1 - q) = h zss r / 2 + O(r^2) (= h dx / 2). A series with the
 * wrong sign or order gives the wrong sign or size here. */
static void test_lk_move_over_series(void **st)
{
    (void)st;
    const float sigma0 = 1.0e5f, g = 20.0f, h = 1.0e-3f;
    const float rs[] = {9.0e-7f, 5.0e-7f};
    for (unsigned i = 0; i < 2; i++) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            const float dx = (float)sgn * rs[i] * g / sigma0;
            const br_lk_step_t s = br_lk_move_over(sigma0, 0.0f, dx, g, h);
            const double want = 0.5 * (double)h * (double)dx; /* h zss r / 2 */
            /* zss + (z0 - zss) q rounds q and the sum: 4u of h |zss| (27 % of want at
             * r = 9e-7, 48 % at 5e-7); the wrong series gives -want, off by 200 % */
            const double zss = (double)g / (double)sigma0;
            BR_ASSERT_NEAR(s.zint_ms, want, 4.0 * 5.9604644775390625e-08 * (double)h * zss);
            BR_ASSERT_NEAR(s.z1_m, (double)dx, 1e-3 * fabs((double)dx)); /* z1 = zss r = dx to first order */
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accuracy),
        cmocka_unit_test(test_edges),
        cmocka_unit_test(test_w16_is_quantised_product),
        cmocka_unit_test(test_monotone),
        cmocka_unit_test(test_lk_move_over_series),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
