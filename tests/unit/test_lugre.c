/* SPDX-License-Identifier: Apache-2.0 */
/* LuGre module: configuration guards, eqs. 3-5, bounded bristle update. */
#include "br_test.h"

#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_lugre.h"

/* the machine's friction (bristle_gen/machine/br_machine.h) */
#define FC BR_MACHINE_FC_N
#define FS BR_MACHINE_FS_N
#define SIGMA0 BR_MACHINE_SIGMA0_NPM
#define SIGMA1 BR_MACHINE_SIGMA1_NSPM

static br_lugre_cfg_t ref_cfg(void)
{
    br_lugre_cfg_t c = {BR_MACHINE_SIGMA0_NPM_F, BR_MACHINE_SIGMA1_NSPM_F, BR_MACHINE_FC_N_F, BR_MACHINE_FS_N_F, BR_MACHINE_VS_MPS_F};
    return c;
}

static void test_init_accepts_machine(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    assert_true(s.z_m == 0.0f);
}

static void test_init_guards(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_lugre_init(&s, NULL), BR_E_NULL);
    /* each field: zero/negative where it must be positive, non-finite everywhere */
    c = ref_cfg(); c.sigma0_Npm = 0.0f;       assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.sigma0_Npm = -1.0f;      assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.sigma0_Npm = NAN;        assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.sigma1_Nspm = -1.0f;     assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.sigma1_Nspm = INFINITY;  assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fc_N = 0.0f;             assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fc_N = NAN;              assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fs_N = 0.9f * c.Fc_N;    assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM); /* < Fc */
    c = ref_cfg(); c.Fs_N = INFINITY;         assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.vs_mps = 0.0f;           assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    c = ref_cfg(); c.vs_mps = NAN;            assert_int_equal(br_lugre_init(&s, &c), BR_E_PARAM);
    /* sigma1 = 0 and Fs = Fc are physical (no damping, no Stribeck dip) */
    c = ref_cfg(); c.sigma1_Nspm = 0.0f; c.Fs_N = c.Fc_N; assert_int_equal(br_lugre_init(&s, &c), BR_OK);
}

static void test_stribeck_curve(void **st)
{
    (void)st;
    br_lugre_cfg_t c = ref_cfg();
    /* eq. 5: g(0) = Fs, g(vs) = Fc + (Fs - Fc)/e, g(large: 1000 vs) = Fc, even in v */
    BR_ASSERT_NEAR(br_lugre_g_N(&c, 0.0f), FS, 1e-5);
    BR_ASSERT_NEAR(br_lugre_g_N(&c, BR_MACHINE_VS_MPS_F), FC + (FS - FC) * exp(-1.0), 1e-5);
    BR_ASSERT_NEAR(br_lugre_g_N(&c, -BR_MACHINE_VS_MPS_F), FC + (FS - FC) * exp(-1.0), 1e-5);
    BR_ASSERT_NEAR(br_lugre_g_N(&c, 1000.0f * BR_MACHINE_VS_MPS_F), FC, 1e-5);
}

static void test_rate_and_force(void **st)
{
    (void)st;
    br_lugre_cfg_t c = ref_cfg();
    /* eq. 4 at the steady deflection g/sigma0 is zero; eq. 3 then gives g */
    float zss = BR_MACHINE_FC_N_F / BR_MACHINE_SIGMA0_NPM_F;
    BR_ASSERT_NEAR(br_lugre_zdot_mps(&c, zss, 0.01f, BR_MACHINE_FC_N_F), 0.0, 1e-9);
    BR_ASSERT_NEAR(br_lugre_force_N(&c, zss, 0.0f), FC, 1e-5);
    /* at z = 0 the rate is v and the force is sigma1 v */
    BR_ASSERT_NEAR(br_lugre_zdot_mps(&c, 0.0f, 1e-4f, BR_MACHINE_FS_N_F), 1e-4, 1e-4 * 1e-7);
    BR_ASSERT_NEAR(br_lugre_force_N(&c, 0.0f, 1e-4f), SIGMA1 * 1e-4, 1e-6);
}

static void test_steady_sliding_reaches_g(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    float F = 0.0f;
    /* 30 ms at 1e-3 m/s: 30 um of travel, many bristle lengths g/sigma0 (1.75 um on the reference) */
    assert_true(30e-6 > 10.0 * FC / SIGMA0);
    for (int k = 0; k < 300; k++) assert_int_equal(br_lugre_step(&s, 1e-3f, 1e-4f, &F), BR_OK);
    BR_ASSERT_NEAR(F, br_lugre_g_N(&c, 1e-3f), 1e-3);
    for (int k = 0; k < 300; k++) assert_int_equal(br_lugre_step(&s, -1e-3f, 1e-4f, &F), BR_OK);
    BR_ASSERT_NEAR(F, -br_lugre_g_N(&c, 1e-3f), 1e-3);
}

static void test_presliding_is_a_spring(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    float F = 0.0f;
    /* 10 nm of displacement at rest-like speed: z = (Fs/sigma0)(1 - exp(-sigma0 dx / Fs)),
     * F ~ sigma0 dx (0.04 N on the reference), far below Fs */
    assert_int_equal(br_lugre_step(&s, 1e-8f, 1.0f, &F), BR_OK);
    BR_ASSERT_NEAR(s.z_m, FS / SIGMA0 * (1.0 - exp(-SIGMA0 * 1e-8 / FS)), 1e-8 * 1e-6);
    BR_ASSERT_NEAR(br_lugre_force_N(&c, s.z_m, 0.0f), SIGMA0 * 1e-8, 1e-4);
    assert_true(SIGMA0 * 1e-8 < 0.01 * FS);
}

static void test_bounded_at_any_speed(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    const float speeds[] = {0.05f, 1.0f, 10.0f, -10.0f, 0.05f, -0.05f};
    float F = 0.0f;
    /* a h = sigma0 |v| h / g reaches 5.7e6 at 10 m/s and 1 ms: explicit RK4 would diverge */
    for (unsigned i = 0; i < sizeof speeds / sizeof speeds[0]; i++) {
        for (int k = 0; k < 50; k++) {
            assert_int_equal(br_lugre_step(&s, speeds[i], 1e-3f, &F), BR_OK);
            assert_true(isfinite(F));
            assert_true(fabsf(s.z_m) <= BR_MACHINE_FS_N_F / BR_MACHINE_SIGMA0_NPM_F * 1.0001f);
        }
        BR_ASSERT_NEAR(F, copysign(FC, speeds[i]), 1e-3 * FC);
    }
}

static void test_step_rejects_bad_input(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    float F = 123.0f;
    s.ready = 0;
    assert_int_equal(br_lugre_step(&s, 0.0f, 1e-3f, &F), BR_E_STATE);
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    assert_int_equal(br_lugre_step(&s, 1e-4f, 1e-3f, &F), BR_OK);
    float z = s.z_m;
    assert_int_equal(br_lugre_step(&s, NAN, 1e-3f, &F), BR_E_INPUT);
    assert_int_equal(br_lugre_step(&s, INFINITY, 1e-3f, &F), BR_E_INPUT);
    assert_int_equal(br_lugre_step(&s, 1e-4f, 0.0f, &F), BR_E_INPUT);
    assert_int_equal(br_lugre_step(&s, 1e-4f, NAN, &F), BR_E_INPUT);
    assert_int_equal(br_lugre_step(&s, 1e-4f, 1e-3f, NULL), BR_E_NULL);
    assert_true(s.z_m == z); /* state untouched by rejected steps */
}

/* v = 0 for 1e6 steps from a full deflection: z and F stay finite and
 * |z| <= Fs / sigma0 (reliability checklist 1). */
static void test_million_steps_at_rest(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    s.z_m = (float)(FS / SIGMA0);
    float F = 0.0f;
    for (long k = 0; k < 1000000L; k++) {
        assert_int_equal(br_lugre_step(&s, 0.0f, 1e-3f, &F), BR_OK);
    }
    assert_true(isfinite(s.z_m) && isfinite(F));
    assert_true(fabsf(s.z_m) <= (float)(FS / SIGMA0));
    BR_ASSERT_NEAR(F, FS, 1e-5 * FS); /* the deflection holds: a spring at rest */
}

/* A bristle stiffness of 1e8 N/m at 1 ms (a h up to 5e5): no oscillation or
 * NaN, and the same deflection as the exact map evaluated in double
 * (reliability checklist 2). */
static void test_stiff_bristle_matches_double(void **st)
{
    (void)st;
    br_lugre_t s;
    br_lugre_cfg_t c = ref_cfg();
    c.sigma0_Npm = 1.0e8f;
    assert_int_equal(br_lugre_init(&s, &c), BR_OK);
    const double s0 = c.sigma0_Npm, fc = c.Fc_N, fs = c.Fs_N, vs = c.vs_mps, h = 1e-3;
    double z = 0.0;
    float F = 0.0f;
    for (int k = 0; k < 4000; k++) {
        /* 50 mm/s, reversing every 0.5 s, with slow passages through zero */
        const float v = 0.05f * sinf(2.0f * 3.14159265f * (float)k / 1000.0f);
        assert_int_equal(br_lugre_step(&s, v, (float)h, &F), BR_OK);
        const double vd = (double)v, g = fc + (fs - fc) * exp(-fabs(vd) / vs), dx = vd * h;
        if (dx != 0.0) {
            const double zss = (dx > 0.0 ? 1.0 : -1.0) * g / s0;
            z = zss + (z - zss) * exp(-s0 * fabs(dx) / g);
        }
        assert_true(isfinite(F) && fabsf(s.z_m) <= (float)(fs / s0) * (1.0f + 1e-6f));
        BR_ASSERT_NEAR(s.z_m, z, 1e-5 * fs / s0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_million_steps_at_rest),
        cmocka_unit_test(test_stiff_bristle_matches_double),
        cmocka_unit_test(test_init_accepts_machine), cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_stribeck_curve),         cmocka_unit_test(test_rate_and_force),
        cmocka_unit_test(test_steady_sliding_reaches_g), cmocka_unit_test(test_presliding_is_a_spring),
        cmocka_unit_test(test_bounded_at_any_speed),   cmocka_unit_test(test_step_rejects_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
