/* SPDX-License-Identifier: Apache-2.0 */
/* Reversal (quadrant-error) compensation (firmware/qec): configuration and
 * input guards, the reversal rule (a start from rest, a rest at 0 keeps the
 * direction), the amplitude's floor, the feedforward under the pulse, the
 * clamp and the br_est_t adapter. The pulse's arithmetic against numpy:
 * tests/golden/test_golden_qec.c. */
#include "br_test.h"

#include <math.h>

#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_qec.h"

static br_qec_cfg_t ref_cfg(void)
{
    br_qec_cfg_t c = {0};
    c.A0_N = 4.0f;
    c.A1_kg = 1000.0f;
    c.tau_s = 0.01f;
    c.dt_s = 1.0e-3f;
    c.comp_max_N = 100.0f;
    c.with_ff = 0;
    c.ff.Fc_N = BR_MACHINE_FC_N_F;
    c.ff.Fs_N = BR_MACHINE_FS_N_F;
    c.ff.vs_mps = BR_MACHINE_VS_MPS_F;
    c.ff.sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM_F;
    c.ff.v_eps_mps = 4.0e-5f;
    c.ff.comp_max_N = 100.0f;
    return c;
}

static void expect_init(br_qec_cfg_t c, br_status_t want)
{
    br_qec_t q;
    assert_int_equal(br_qec_init(&q, &c), want);
}

static void test_init_guards(void **state)
{
    (void)state;
    br_qec_t q;
    const br_qec_cfg_t ok = ref_cfg();
    assert_int_equal(br_qec_init(NULL, &ok), BR_E_NULL);
    assert_int_equal(br_qec_init(&q, NULL), BR_E_NULL);
    expect_init(ok, BR_OK);
    br_qec_cfg_t c = ok;
    c.A0_N = -0.1f; expect_init(c, BR_E_PARAM);
    c = ok; c.A0_N = NAN; expect_init(c, BR_E_PARAM);
    c = ok; c.A1_kg = INFINITY; expect_init(c, BR_E_PARAM);
    c = ok; c.A1_kg = -1000.0f; expect_init(c, BR_OK); /* an amplitude falling with acceleration */
    c = ok; c.tau_s = 0.0f; expect_init(c, BR_E_PARAM);
    c = ok; c.tau_s = NAN; expect_init(c, BR_E_PARAM);
    c = ok; c.dt_s = 0.0f; expect_init(c, BR_E_PARAM);
    c = ok; c.dt_s = INFINITY; expect_init(c, BR_E_PARAM);
    c = ok; c.comp_max_N = 0.0f; expect_init(c, BR_E_PARAM);
    c = ok; c.with_ff = 2; expect_init(c, BR_E_PARAM);
    /* with the feedforward: its own checks */
    c = ok; c.with_ff = 1; expect_init(c, BR_OK);
    c.ff.Fs_N = 0.5f * c.ff.Fc_N; expect_init(c, BR_E_PARAM);
    c = ok; c.ff.Fs_N = 0.5f * c.ff.Fc_N; expect_init(c, BR_OK); /* not used without with_ff */
    /* a failed init leaves the module unusable */
    c = ok; c.tau_s = -1.0f;
    assert_int_equal(br_qec_init(&q, &c), BR_E_PARAM);
    const br_ff_in_t in = {1.0e-5f, 0.0f, 0.0f};
    float F = 1.0f;
    assert_int_equal(br_qec_set_ref(&q, &in), BR_E_STATE);
    assert_int_equal(br_qec_comp(&q, &F), BR_E_STATE);
    assert_true(F == 0.0f);
}

/* one period: the reference, then the compensation */
static float period(br_qec_t *q, float v, float a)
{
    const br_ff_in_t in = {v, a, 0.0f};
    float F = NAN;
    assert_int_equal(br_qec_set_ref(q, &in), BR_OK);
    assert_int_equal(br_qec_comp(q, &F), BR_OK);
    return F;
}

static void test_reversal_rule(void **state)
{
    (void)state;
    const br_qec_cfg_t c = ref_cfg();
    br_qec_t q;
    assert_int_equal(br_qec_init(&q, &c), BR_OK);
    const double rho = exp(-(double)c.dt_s / c.tau_s);
    /* at rest: no pulse */
    assert_true(period(&q, 0.0f, 0.0f) == 0.0f);
    /* a start from rest in +x at a = 2e-3: A0 + A1 |a| = 6 N */
    BR_ASSERT_NEAR(period(&q, 1.0e-6f, 2.0e-3f), 6.0, 1e-5);
    /* decays by rho per period */
    BR_ASSERT_NEAR(period(&q, 2.0e-6f, 2.0e-3f), 6.0 * rho, 1e-5);
    BR_ASSERT_NEAR(period(&q, 3.0e-6f, 2.0e-3f), 6.0 * rho * rho, 1e-5);
    /* a rest at exactly 0, then on the same way: no new pulse */
    BR_ASSERT_NEAR(period(&q, 0.0f, 0.0f), 6.0 * pow(rho, 3), 1e-5);
    BR_ASSERT_NEAR(period(&q, 1.0e-6f, 0.0f), 6.0 * pow(rho, 4), 1e-5);
    /* a reversal to -x with a = -1e-3 (the sign of a does not matter): -5 N */
    BR_ASSERT_NEAR(period(&q, -1.0e-6f, -1.0e-3f), -5.0, 1e-5);
    /* back to +x: +4 N at a = 0 */
    BR_ASSERT_NEAR(period(&q, 1.0e-7f, 0.0f), 4.0, 1e-5);
}

static void test_amplitude_floor_and_clamp(void **state)
{
    (void)state;
    br_qec_cfg_t c = ref_cfg();
    c.A1_kg = -1000.0f;
    br_qec_t q;
    assert_int_equal(br_qec_init(&q, &c), BR_OK);
    /* A0 + A1 |a| = 4 - 5 < 0: the floor 0, never a pulse against the motion */
    assert_true(period(&q, 1.0e-6f, 5.0e-3f) == 0.0f);
    BR_ASSERT_NEAR(period(&q, -1.0e-6f, 1.0e-3f), -3.0, 1e-5);
    /* the clamp */
    c = ref_cfg();
    c.comp_max_N = 5.0f;
    assert_int_equal(br_qec_init(&q, &c), BR_OK);
    assert_true(period(&q, 1.0e-6f, 2.0e-2f) == 5.0f);
    assert_true(period(&q, -1.0e-6f, 2.0e-2f) == -5.0f);
}

static void test_inputs_and_overflow(void **state)
{
    (void)state;
    const br_qec_cfg_t c = ref_cfg();
    br_qec_t q;
    assert_int_equal(br_qec_init(&q, &c), BR_OK);
    const float F0 = period(&q, 1.0e-6f, 0.0f);
    const br_ff_in_t bad[3] = {{NAN, 0.0f, 0.0f}, {1.0e-6f, INFINITY, 0.0f}, {-1.0e-6f, 0.0f, NAN}};
    for (int i = 0; i < 3; i++) {
        /* nothing changes: no reversal taken from a NaN, no decay */
        assert_int_equal(br_qec_set_ref(&q, &bad[i]), BR_E_INPUT);
        float F = NAN;
        assert_int_equal(br_qec_comp(&q, &F), BR_OK);
        assert_true(F == F0);
    }
    assert_int_equal(br_qec_set_ref(NULL, &bad[0]), BR_E_NULL);
    assert_int_equal(br_qec_set_ref(&q, NULL), BR_E_NULL);
    assert_int_equal(br_qec_comp(&q, NULL), BR_E_NULL);
    /* an amplitude that overflows float (A1 |a| = inf): an error and 0, never inf */
    const br_ff_in_t huge = {-1.0e-6f, 3.0e38f, 0.0f};
    assert_int_equal(br_qec_set_ref(&q, &huge), BR_OK);
    float F = 1.0f;
    assert_int_equal(br_qec_comp(&q, &F), BR_E_INPUT);
    assert_true(F == 0.0f);
}

static void test_on_feedforward_and_adapter(void **state)
{
    (void)state;
    br_qec_cfg_t c = ref_cfg();
    c.with_ff = 1;
    br_qec_t q;
    br_ff_t ff;
    assert_int_equal(br_qec_init(&q, &c), BR_OK);
    assert_int_equal(br_ff_init(&ff, &c.ff), BR_OK);
    const br_ff_in_t in = {2.0e-5f, 1.0e-3f, 1.0e-6f};
    float Fff = NAN, F = NAN, Fe = NAN;
    assert_int_equal(br_ff_step(&ff, &in, &Fff), BR_OK);
    assert_int_equal(br_qec_set_ref(&q, &in), BR_OK);
    assert_int_equal(br_qec_comp(&q, &F), BR_OK);
    /* the pulse (5 N) on top of the feedforward at the same reference */
    BR_ASSERT_NEAR(F, (double)Fff + 5.0, 1e-5);
    assert_int_equal(br_qec_est_step(&q, NULL, 0.0f, &Fe), BR_OK);
    assert_true(Fe == F);
    assert_int_equal(br_qec_est_step(NULL, NULL, 0.0f, &Fe), BR_E_NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_reversal_rule),
        cmocka_unit_test(test_amplitude_floor_and_clamp),
        cmocka_unit_test(test_inputs_and_overflow),
        cmocka_unit_test(test_on_feedforward_and_adapter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
