/* SPDX-License-Identifier: Apache-2.0 */
/* Maxwell-slip clamp kernel (firmware/mslip): every configuration and input
 * guard, the bound |z_i| <= Delta_i at any travel, and the non-local memory
 * (an inner loop closed leaves the elements where they were: the
 * wiping-out property of presliding.md's Maxwell-slip model). */
#include "br_test.h"

#include <math.h>
#include <string.h>

#include "bristle/br_model.h"
#include "bristle/br_mslip.h"
#include "bristle_gen/machine/br_machine.h"

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

/* the estimation model with elements (docs/modules/model.md, "Maxwell-slip model") */
static br_model_cfg_t model_cfg4(void)
{
    br_model_cfg_t c;
    memset(&c, 0, sizeof c);
    c.J_kgm2 = BR_MACHINE_J_KGM2_F;
    c.M_kg = BR_MACHINE_M_KG_F;
    c.lead_mprad = BR_MACHINE_LEAD_MPRAD_F;
    c.sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM_F;
    c.lugre.sigma0_Npm = BR_MACHINE_SIGMA0_NPM_F;
    c.lugre.sigma1_Nspm = BR_MACHINE_SIGMA1_NSPM_F;
    c.lugre.Fc_N = BR_MACHINE_FC_N_F;
    c.lugre.Fs_N = BR_MACHINE_FS_N_F;
    c.lugre.vs_mps = BR_MACHINE_VS_MPS_F;
    c.dt_s = 1e-3f;
    c.mslip = cfg4();
    c.mslip.sigma2_Nspm = 0.0f;
    return c;
}

static void test_model_guards(void **state)
{
    (void)state;
    br_model_t m;
    br_model_cfg_t c = model_cfg4();
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    /* the element set is checked, its viscous term is the model's sigma2 (must be 0) */
    c = model_cfg4(); c.mslip.share[0] = 0.5f; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = model_cfg4(); c.mslip.n = BR_MSLIP_MAX + 1; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = model_cfg4(); c.mslip.sigma2_Nspm = 1.0f; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    /* no cause but the delay with elements */
    c = model_cfg4(); c.causes.offset_N = 1.0f; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = model_cfg4(); c.causes.drift_per_s = 0.01f; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = model_cfg4(); c.causes.delay_s = 1e-3f; assert_int_equal(br_model_init(&m, &c), BR_OK);
    /* the element step needs elements */
    float x[BR_NX] = {0.0f, 0.01f, 0.0f, 18.0f}, z[BR_MSLIP_MAX] = {1e-7f, 0.0f, 0.0f, 0.0f}, x1[BR_NX], z1[BR_MSLIP_MAX];
    c = model_cfg4(); c.mslip.n = 0;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_int_equal(br_model_ms_step(&m, x, z, 0.0f, x1, z1), BR_E_STATE);
    c = model_cfg4();
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_int_equal(br_model_ms_step(&m, x, NULL, 0.0f, x1, z1), BR_E_NULL);
    /* bad input: BR_E_INPUT, outputs = inputs */
    const float bad_gp[] = {0.0f, -1.0f, NAN};
    for (size_t j = 0; j < 3; j++) {
        float xb[BR_NX] = {0.0f, 0.01f, 0.0f, bad_gp[j]};
        assert_int_equal(br_model_ms_step(&m, xb, z, 0.0f, x1, z1), BR_E_INPUT);
        assert_memory_equal(x1, xb, sizeof xb);
        assert_memory_equal(z1, z, 4 * sizeof(float));
    }
    z[2] = INFINITY;
    assert_int_equal(br_model_ms_step(&m, x, z, 0.0f, x1, z1), BR_E_INPUT);
    assert_memory_equal(x1, x, sizeof x);
    z[2] = 0.0f;
    assert_int_equal(br_model_ms_step(&m, x, z, NAN, x1, z1), BR_E_INPUT);
    /* an overflowing torque: BR_E_NUMERIC, outputs = inputs */
    assert_int_equal(br_model_ms_step(&m, x, z, 3e38f, x1, z1), BR_E_NUMERIC);
    assert_memory_equal(x1, x, sizeof x);
    assert_memory_equal(z1, z, 4 * sizeof(float));
    /* in place, and at rest below the breakaway the axis sticks: over 20 s of a constant
     * force of 0.5 Fs it stays within the largest element's breakaway (20 um), the
     * elements carry the force, and the axis comes to rest (sigma2 damps it at
     * sigma2 / (2 M_load) = 0.7 /s) */
    float xs[BR_NX] = {0.0f, 0.0f, 0.0f, BR_MACHINE_FS_N_F}, zs[BR_MSLIP_MAX] = {0};
    for (int j = 0; j < 20000; j++) {
        assert_int_equal(br_model_ms_step(&m, xs, zs, 0.5f * BR_MACHINE_FS_N_F * BR_MACHINE_LEAD_MPRAD_F, xs, zs),
                         BR_OK);
    }
    assert_true(fabsf(BR_MACHINE_LEAD_MPRAD_F * xs[BR_X_THETA]) < 0.4f * BR_MACHINE_FS_N_F / cfg4().k_Npm[3]);
    BR_ASSERT_NEAR(br_model_ms_fnl_N(&m, zs), 0.5f * BR_MACHINE_FS_N_F, 0.05 * BR_MACHINE_FS_N_F);
    assert_true(fabsf(BR_MACHINE_LEAD_MPRAD_F * xs[BR_X_OMEGA]) < 1e-6f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cfg_guards),
        cmocka_unit_test(test_step_guards),
        cmocka_unit_test(test_bounded_and_sliding),
        cmocka_unit_test(test_inner_loop_closes),
        cmocka_unit_test(test_model_guards),
    };
    return cmocka_run_group_tests_name("mslip", tests, NULL, NULL);
}
