/* SPDX-License-Identifier: Apache-2.0 */
/* br_math.h's three forms of the PF's exponentials give the same float
 * (docs/modules/pf.md, "The exponential"): the reference (branches,
 * br_exp_neg_kb), the float-SIMD kernel's (masks, br_exp_neg_kb_mask) and
 * the Cortex-M7 kernel's (roundf's rounding of x log2 e, ties away from
 * zero, and the scale 2^(n + s) as a fixed-point conversion,
 * br_exp_neg_kb_rinta; its C form here, the M7's vcvt in the QEMU replay),
 * each as e^x (s = 0) and as e^x 2^16 (the quantisation's, s = 16). The
 * rounding differs from the branches' round-half-down only if ties were
 * handled the other way, so the test takes every float x near each tie
 * x log2 e = k + 1/2 (k = -126 .. -1), where x log2 e rounds to the tie
 * itself for a few x, and a sweep of the range and its edges. */
#include "br_test.h"

#include <string.h>

#include "br_math.h"

static int same_bits(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* x through the three forms of both functions; 1 when all agree */
static int forms_agree(float x)
{
    const br_exp_k_t k = br_exp_k();
    const float w = br_exp_neg_w16_k(x, k), e = br_exp_neg_k(x, k);
    /* the mask form has no top argument: its e^0 2^s comes from the polynomial */
    return same_bits(w, br_exp_neg_kb_mask(x, k, 127 + 16)) &&
           same_bits(w, br_exp_neg_kb_rinta(x, k, 127 + 16, 65536.0f)) && same_bits(e, br_exp_neg_kb_mask(x, k, 127)) &&
           same_bits(e, br_exp_neg_kb_rinta(x, k, 127, k.one));
}

static void test_ties(void **st)
{
    (void)st;
    long n = 0, ties = 0, bad = 0;
    for (int k = -126; k <= -1; k++) {
        const float tie = (float)k + 0.5f;
        /* x log2 e = tie near x = tie ln 2; 512 floats either side */
        float x = (float)((double)tie * 0.69314718055994531);
        for (int i = 0; i < 512; i++) {
            x = nextafterf(x, -INFINITY);
        }
        for (int i = 0; i < 1025; i++) {
            ties += (x * 1.44269504f == tie);
            bad += !forms_agree(x);
            n++;
            x = nextafterf(x, 0.0f);
        }
    }
    print_message("exp forms: %ld floats near the ties, %ld ties, %ld differ\n", n, ties, bad);
    assert_true(ties > 0);
    assert_int_equal(bad, 0);
}

static void test_sweep_and_edges(void **st)
{
    (void)st;
    long bad = 0;
    float x = -88.0f;
    while (x <= -86.0f) { /* every float where 2^n e^y turns subnormal and the range ends */
        bad += !forms_agree(x);
        x = nextafterf(x, 0.0f);
    }
    for (int i = 0; i <= 1000000; i++) {
        bad += !forms_agree(-86.0f * (float)i / 1.0e6f);
    }
    const float edge[] = {0.0f, -0.0f, 2.5f, INFINITY, -INFINITY, NAN, -NAN, -87.0f, -1.0e-30f, -1.0e-45f};
    for (size_t i = 0; i < sizeof edge / sizeof edge[0]; i++) {
        bad += !forms_agree(edge[i]);
    }
    assert_int_equal(bad, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ties),
        cmocka_unit_test(test_sweep_and_edges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
