/* SPDX-License-Identifier: Apache-2.0 */
/* Maxwell-slip clamp kernel (firmware/mslip): every configuration and input
 * guard, the bound |z_i| <= Delta_i at any travel, and the non-local memory
 * (an inner loop closed leaves the elements where they were: the
 * wiping-out property of presliding.md's Maxwell-slip model). */
#include "br_test.h"

#include <math.h>
#include <string.h>

#include "bristle/br_mslip.h"

/* four elements, shares 0.1-0.4 (a test choice; no machine value involved) */
static br_mslip_cfg_t cfg4(void)
{
    br_mslip_cfg_t c;
    memset(&c, 0, sizeof c);
    c.n = 4;
    const float k[4] = {9.0e5f, 7.2e5f, 5.4e5f, 3.6e5f}, a[4] = {0.1f, 0.2f, 0.3f, 0.4f};
    for (int i = 0; i < 4; i++) {
        c.k_Npm[i] = k[i];
        c.share[i] = a[i];
    }
    c.sigma2_Nspm = 50.0f;
    return c;
}

static void test_cfg_guards(void **state)
{
    (void)state;
    br_mslip_t s;
    br_mslip_cfg_t c = cfg4();
    assert_int_equal(br_mslip_cfg_check(&c), BR_OK);
    assert_int_equal(br_mslip_init(&s, &c), BR_OK);
    assert_int_equal(br_mslip_cfg_check(NULL), BR_E_NULL);
    assert_int_equal(br_mslip_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_mslip_init(&s, NULL), BR_E_NULL);
    /* n out of range; n = 0 is "no elements" for the check, but no friction to init */
    c = cfg4(); c.n = -1; assert_int_equal(br_mslip_cfg_check(&c), BR_E_PARAM);
    c = cfg4(); c.n = BR_MSLIP_MAX + 1; assert_int_equal(br_mslip_cfg_check(&c), BR_E_PARAM);
    c = cfg4(); c.n = 0;
    assert_int_equal(br_mslip_cfg_check(&c), BR_OK);
    assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    assert_int_equal(s.ready, 0);
    /* stiffness > 0 and finite */
    c = cfg4(); c.k_Npm[2] = 0.0f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.k_Npm[2] = -1.0f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.k_Npm[3] = INFINITY; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    /* shares in (0, 1], finite, summing to 1 */
    c = cfg4(); c.share[0] = 0.0f; c.share[1] = 0.3f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.share[0] = NAN; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.n = 1; c.share[0] = 1.5f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.share[3] = 0.41f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.share[3] = 0.39f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    /* the tolerance is the float rounding of written shares, no more */
    c = cfg4(); c.share[3] = 0.4f + 2.0f * BR_MSLIP_SHARE_TOL; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    /* the viscous term */
    c = cfg4(); c.sigma2_Nspm = -1.0f; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    c = cfg4(); c.sigma2_Nspm = NAN; assert_int_equal(br_mslip_init(&s, &c), BR_E_PARAM);
    /* the elements beyond n are not read */
    c = cfg4(); c.k_Npm[5] = NAN; c.share[6] = -3.0f; assert_int_equal(br_mslip_init(&s, &c), BR_OK);
}

static void test_step_guards(void **state)
{
    (void)state;
    br_mslip_t s;
    const br_mslip_cfg_t c = cfg4();
    float F = 123.0f;
    memset(&s, 0, sizeof s);
    assert_int_equal(br_mslip_step(&s, 1e-6f, 0.0f, 18.0f, &F), BR_E_STATE);
    assert_int_equal(br_mslip_init(&s, &c), BR_OK);
    assert_int_equal(br_mslip_step(NULL, 1e-6f, 0.0f, 18.0f, &F), BR_E_NULL);
    assert_int_equal(br_mslip_step(&s, 1e-6f, 0.0f, 18.0f, NULL), BR_E_NULL);
    assert_int_equal(br_mslip_step(&s, 3e-6f, 1e-3f, 18.0f, &F), BR_OK);
    const br_mslip_t kept = s;
    const float Fk = F;
    const float bad[][3] = {{NAN, 0.0f, 18.0f}, {INFINITY, 0.0f, 18.0f}, {1e-6f, NAN, 18.0f},
                            {1e-6f, 0.0f, 0.0f}, {1e-6f, 0.0f, -1.0f}, {1e-6f, 0.0f, NAN},
                            {1e-6f, 0.0f, INFINITY}};
    for (size_t j = 0; j < sizeof bad / sizeof bad[0]; j++) {
        assert_int_equal(br_mslip_step(&s, bad[j][0], bad[j][1], bad[j][2], &F), BR_E_INPUT);
        assert_memory_equal(&s, &kept, sizeof s);
        assert_true(F == Fk);
    }
    /* a finite input whose force overflows: BR_E_NUMERIC, the state kept */
    br_mslip_cfg_t big = cfg4();
    big.sigma2_Nspm = 1e30f;
    assert_int_equal(br_mslip_init(&s, &big), BR_OK);
    assert_int_equal(br_mslip_step(&s, 1e-6f, 1e-6f, 18.0f, &F), BR_OK);
    const br_mslip_t kept2 = s;
    assert_int_equal(br_mslip_step(&s, 1e-6f, 1e10f, 18.0f, &F), BR_E_NUMERIC);
    assert_memory_equal(&s, &kept2, sizeof s);
}

/* |z_i| <= share_i g / k_i after any travel, and a full slip gives F = g + sigma2 v */
static void test_bounded_and_sliding(void **state)
{
    (void)state;
    br_mslip_t s;
    const br_mslip_cfg_t c = cfg4();
    assert_int_equal(br_mslip_init(&s, &c), BR_OK);
    float F = 0.0f;
    const float g = 12.5f;
    const float moves[] = {1.0f, -1e-3f, 3e-6f, -0.5f, 2e-7f};
    for (size_t j = 0; j < sizeof moves / sizeof moves[0]; j++) {
        assert_int_equal(br_mslip_step(&s, moves[j], 0.0f, g, &F), BR_OK);
        for (int i = 0; i < c.n; i++) {
            assert_true(fabsf(s.z_m[i]) <= c.share[i] * g / c.k_Npm[i] * (1.0f + 1e-6f));
        }
    }
    /* after a long move in +x every element is at its bound: F = sum share_i g + sigma2 v */
    assert_int_equal(br_mslip_step(&s, 1e-3f, 2e-3f, g, &F), BR_OK);
    BR_ASSERT_NEAR(F, g + 50.0f * 2e-3f, 1e-5 * g);
}

/* Non-local memory: after an outer reversal, a smaller inner loop (out and
 * back by the same travel) leaves every element exactly where it was, and
 * the force after the loop is the one before it (Masing / wiping-out). A
 * single-state friction could not; here the elements that did not slip in
 * the inner loop carry the outer loop's memory. */
static void test_inner_loop_closes(void **state)
{
    (void)state;
    br_mslip_t s;
    const br_mslip_cfg_t c = cfg4();
    assert_int_equal(br_mslip_init(&s, &c), BR_OK);
    const float g = 18.0f, step = 0.25e-6f;
    float F = 0.0f, F_before = 0.0f;
    int j;
    for (j = 0; j < 200; j++) { /* 50 um in +x: all slip */
        assert_int_equal(br_mslip_step(&s, step, 0.0f, g, &F), BR_OK);
    }
    for (j = 0; j < 40; j++) { /* 10 um back: elements 1, 2 slipped the other way, 3, 4 not */
        assert_int_equal(br_mslip_step(&s, -step, 0.0f, g, &F), BR_OK);
    }
    F_before = F;
    float z_before[BR_MSLIP_MAX];
    memcpy(z_before, s.z_m, sizeof z_before);
    for (j = 0; j < 16; j++) { /* an inner loop: 4 um out and back */
        assert_int_equal(br_mslip_step(&s, step, 0.0f, g, &F), BR_OK);
    }
    assert_true(F > F_before + 1.0f); /* it moved the force */
    for (j = 0; j < 16; j++) {
        assert_int_equal(br_mslip_step(&s, -step, 0.0f, g, &F), BR_OK);
    }
    BR_ASSERT_NEAR(F, F_before, 1e-5);
    for (int i = 0; i < c.n; i++) {
        BR_ASSERT_NEAR(s.z_m[i], z_before[i], 1e-12);
    }
    /* elements 3 and 4 still hold the outer loop's deflection (not at their bound) */
    assert_true(fabsf(s.z_m[3]) < c.share[3] * g / c.k_Npm[3]);
    /* reset: every element back to 0 */
    br_mslip_reset(&s);
    for (int i = 0; i < BR_MSLIP_MAX; i++) {
        assert_true(s.z_m[i] == 0.0f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cfg_guards),
        cmocka_unit_test(test_step_guards),
        cmocka_unit_test(test_bounded_and_sliding),
        cmocka_unit_test(test_inner_loop_closes),
    };
    return cmocka_run_group_tests_name("mslip", tests, NULL, NULL);
}
