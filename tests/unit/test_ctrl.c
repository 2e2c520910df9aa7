/* SPDX-License-Identifier: Apache-2.0 */
/* Controller (eq. 7): guards, control law, saturation with anti-windup,
 * wrap-safe velocity, compensation input. */
#include "br_test.h"

#include "bristle/br_ctrl.h"
#include "bristle_gen/machine/br_machine.h"

/* the machine's period, torque limit, amplifier, encoder and lead */
#define DT BR_MACHINE_CTRL_PERIOD_S_F
#define TAU_MAX BR_MACHINE_TORQUE_LIMIT_NM_F
#define TAU_DUTY BR_MACHINE_TAU_PER_DUTY_NM_F
#define RPC BR_MACHINE_RAD_PER_COUNT_F
#define LEAD BR_MACHINE_LEAD_MPRAD_F

/* the test's gains (round numbers, not the H-inf design) on the machine */
static br_ctrl_cfg_t cfg(void)
{
    br_ctrl_cfg_t c = {{-0.5f, -0.01f, -10.0f}, DT, TAU_MAX, TAU_DUTY, RPC, LEAD};
    return c;
}

static br_ctrl_in_t in_at(int32_t enc, int32_t ref)
{
    br_ctrl_in_t in = {enc, ref, 0.0f, 0.0f, 0.0f};
    return in;
}

static void test_init_guards(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    assert_int_equal(br_ctrl_init(NULL, &k), BR_E_NULL);
    assert_int_equal(br_ctrl_init(&c, NULL), BR_E_NULL);
    k = cfg(); assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    k = cfg(); k.K[0] = NAN;             assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.K[2] = INFINITY;        assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.dt_s = 0.0f;            assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.dt_s = NAN;             assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.tau_max_Nm = 0.0f;      assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.tau_max_Nm = -1.0f;     assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    /* beyond full duty */
    k = cfg(); k.tau_max_Nm = 1.1f * k.tau_per_duty_Nm; assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.tau_per_duty_Nm = 0.0f; assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.rad_per_count = 0.0f;   assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    k = cfg(); k.lead_mprad = -1e-3f;    assert_int_equal(br_ctrl_init(&c, &k), BR_E_PARAM);
    br_ctrl_in_t in = in_at(0, 0);
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_STATE); /* last init failed */
}

static void test_control_law(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    /* first call primes the velocity: omega = 0; e = (100 - 50 - 0.25) counts */
    br_ctrl_in_t in = {100, 50, 0.25f, 0.0f, 0.0f};
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    double e = 49.75 * RPC;
    BR_ASSERT_NEAR(out.e_theta_rad, e, 1e-6 * e);
    BR_ASSERT_NEAR(out.tau_Nm, -0.5 * e, 1e-6 * 0.5 * e);
    BR_ASSERT_NEAR(out.duty, -0.5 * e / TAU_DUTY, 1e-6 * 0.5 * e / TAU_DUTY);
    BR_ASSERT_NEAR(c.eps_rads, e * DT, 1e-6 * e * DT);
    /* second call: 10 counts moved in one period, reference velocity 0.02 rad/s */
    in.enc_counts = 110;
    in.ref_omega_radps = 0.02f;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    double e2 = 59.75 * RPC, w = 10 * RPC / DT;
    BR_ASSERT_NEAR(out.omega_radps, w, 1e-6 * w);
    BR_ASSERT_NEAR(out.tau_Nm, -0.5 * e2 - 0.01 * (w - 0.02) - 10.0 * e * DT, 1e-6 * 0.5 * e2);
    assert_int_equal(out.saturated, 0);
}

static void test_compensation_adds_torque(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    br_ctrl_in_t in = {0, 0, 0.0f, 0.0f, BR_MACHINE_FS_N_F};
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    BR_ASSERT_NEAR(out.tau_Nm, LEAD * BR_MACHINE_FS_N, 1e-6 * LEAD * BR_MACHINE_FS_N); /* tau = L F_comp */
}

static void test_saturation_and_antiwindup(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    /* a huge error: u = -0.5 * (-2e6 rpc), 6 N m on the reference, beyond the limit */
    br_ctrl_in_t in = in_at(0, 2000000);
    assert_true(0.5 * 2e6 * RPC > 2.0 * TAU_MAX);
    for (int i = 0; i < 100; i++) {
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
        assert_int_equal(out.saturated, 1);
        BR_ASSERT_NEAR(out.tau_Nm, TAU_MAX, 0.0);
        BR_ASSERT_NEAR(out.duty, TAU_MAX / TAU_DUTY, 0.0);
    }
    /* integrating would push deeper into saturation: eps held at zero */
    BR_ASSERT_NEAR(c.eps_rads, 0.0, 0.0);
    /* saturated but the error now reduces the command: the integral runs */
    /* K2 eps = 0.9 tau_max, inside the clamp tau_max / |K2| */
    c.eps_rads = -0.09f * TAU_MAX;
    in = in_at(1000, 0);          /* e > 0: K2 e < 0, opposite to u */
    in.comp_N = 0.3f * TAU_MAX / LEAD; /* L F_comp = 0.3 tau_max: u > 1.1 tau_max, saturated high */
    assert_true(0.5 * 1000 * RPC < 0.1 * TAU_MAX);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    assert_int_equal(out.saturated, 1);
    BR_ASSERT_NEAR(c.eps_rads, -0.09 * TAU_MAX + 1000 * RPC * DT, 1e-7);
    /* negative side */
    br_ctrl_t c2;
    assert_int_equal(br_ctrl_init(&c2, &k), BR_OK);
    in = in_at(2000000, 0);
    assert_int_equal(br_ctrl_step(&c2, &in, &out), BR_OK);
    BR_ASSERT_NEAR(out.duty, -TAU_MAX / TAU_DUTY, 0.0);
    BR_ASSERT_NEAR(c2.eps_rads, 0.0, 0.0);
}

static void test_velocity_across_wrap(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    br_ctrl_in_t in = in_at(INT32_MAX - 4, INT32_MAX - 4);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    /* the counter wraps: +10 counts, and the reference wraps with it */
    in = in_at(INT32_MIN + 5, INT32_MIN + 5);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    BR_ASSERT_NEAR(out.omega_radps, 10 * RPC / DT, 1e-6 * 10 * RPC / DT);
    BR_ASSERT_NEAR(out.e_theta_rad, 0.0, 0.0);
    /* reference on the other side of the wrap: error of 3 counts */
    in = in_at(INT32_MIN + 1, INT32_MAX - 1);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    BR_ASSERT_NEAR(out.e_theta_rad, 3 * RPC, 1e-6 * 3 * RPC);
}

static void test_step_rejects_bad_input(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    br_ctrl_in_t in = in_at(10, 0);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    float eps = c.eps_rads;
    const float bad[] = {NAN, INFINITY, -INFINITY};
    for (int i = 0; i < 3; i++) {
        in = in_at(10, 0); in.comp_N = bad[i];
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_INPUT);
        assert_true(out.tau_Nm == 0.0f && out.duty == 0.0f && out.e_theta_rad == 0.0f && out.omega_radps == 0.0f);
        in = in_at(10, 0); in.ref_frac_counts = bad[i];
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_INPUT);
        in = in_at(10, 0); in.ref_omega_radps = bad[i];
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_INPUT);
    }
    assert_true(c.eps_rads == eps);
    assert_int_equal(br_ctrl_step(&c, NULL, &out), BR_E_NULL);
    assert_int_equal(br_ctrl_step(&c, &in, NULL), BR_E_NULL);
}

/* Out-of-range inputs and unusable states give zero duty and an error: the
 * axis loop latches them (docs/reliability.md). */
static void test_out_of_range_gives_zero_duty(void **st)
{
    (void)st;
    br_ctrl_t c;
    br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    br_ctrl_in_t in = in_at(0, 5);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    const float eps = c.eps_rads;
    /* a reference fraction of 1e30 once gave duty +1 */
    const float bad_frac[] = {1e30f, -0.01f, 1.0001f, -INFINITY};
    for (unsigned i = 0; i < sizeof bad_frac / sizeof bad_frac[0]; i++) {
        in = in_at(0, 5); in.ref_frac_counts = bad_frac[i];
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_INPUT);
        assert_true(out.duty == 0.0f && out.tau_Nm == 0.0f);
    }
    in = in_at(0, 5); in.ref_frac_counts = 1.0f;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    /* a compensation beyond what the actuator can exert (tau_max / L) */
    in = in_at(0, 5); in.comp_N = 1.01f * TAU_MAX / LEAD;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_INPUT);
    assert_true(out.duty == 0.0f);
    in = in_at(0, 5); in.comp_N = -0.99f * TAU_MAX / LEAD;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    /* a velocity reference that makes the law overflow */
    in = in_at(0, 5); in.ref_omega_radps = 3e38f;
    c.eps_rads = eps;
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK); /* K1 e_omega = 3e36: saturates, finite */
    k.K[1] = -1e10f;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_NUMERIC); /* K1 e_omega overflows */
    assert_true(out.duty == 0.0f);
    /* a NaN or infinite integrator once gave duty -1 with BR_OK */
    k = cfg();
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    const float bad_eps[] = {NAN, INFINITY, -INFINITY, 1.0f};
    for (unsigned i = 0; i < sizeof bad_eps / sizeof bad_eps[0]; i++) {
        c.eps_rads = bad_eps[i];
        in = in_at(0, 5);
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_E_NUMERIC);
        assert_true(out.duty == 0.0f && out.tau_Nm == 0.0f);
    }
}

/* The integral is clamped both ways where its term alone saturates the
 * torque: a compensation that holds the command at the opposite limit lets it
 * integrate (the anti-windup sees the error reducing the command), and
 * without the clamp it would run on to twice that. */
static void test_integrator_clamped_both_ways(void **st)
{
    (void)st;
    const br_ctrl_cfg_t k = cfg();
    const double eps_max = k.tau_max_Nm / fabs(k.K[2]);
    /* steps to integrate 1000 counts of error up to twice the clamp */
    const long n = (long)(2.0 * eps_max / (1000.0 * RPC * DT)) + 1;
    assert_true(0.5 * 1000 * RPC < 0.05 * TAU_MAX);
    for (int sign = -1; sign <= 1; sign += 2) {
        br_ctrl_t c;
        br_ctrl_out_t out;
        assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
        BR_ASSERT_NEAR(c.eps_max_rads, eps_max, 1e-6 * eps_max);
        for (long i = 0; i < n; i++) {
            br_ctrl_in_t in = in_at(sign * 1000, 0);
            in.comp_N = (float)sign * 0.9f * TAU_MAX / LEAD; /* L F_comp = 0.9 tau_max against the integral */
            assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
            assert_true(fabs(c.eps_rads) <= eps_max * (1.0 + 1e-6));
        }
        BR_ASSERT_NEAR(c.eps_rads, sign * eps_max, 1e-6 * eps_max);
    }
}

/* Saturated for 10 s, then the setpoint reverses: no windup, the command
 * leaves the limit at the first period (reliability checklist). */
static void test_no_windup_after_long_saturation(void **st)
{
    (void)st;
    br_ctrl_t c;
    const br_ctrl_cfg_t k = cfg();
    br_ctrl_out_t out;
    assert_int_equal(br_ctrl_init(&c, &k), BR_OK);
    const long n = (long)(10.0 / DT);
    br_ctrl_in_t in = in_at(0, 2000000); /* far behind: saturated high */
    for (long i = 0; i < n; i++) {
        assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
        assert_int_equal(out.saturated, 1);
    }
    BR_ASSERT_NEAR(c.eps_rads, 0.0, 0.0);
    in = in_at(0, -1000); /* the setpoint reverses */
    assert_int_equal(br_ctrl_step(&c, &in, &out), BR_OK);
    assert_true(out.tau_Nm < 0.0f);
    assert_int_equal(out.saturated, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_out_of_range_gives_zero_duty),
        cmocka_unit_test(test_no_windup_after_long_saturation),
        cmocka_unit_test(test_integrator_clamped_both_ways),
        cmocka_unit_test(test_init_guards),           cmocka_unit_test(test_control_law),
        cmocka_unit_test(test_compensation_adds_torque), cmocka_unit_test(test_saturation_and_antiwindup),
        cmocka_unit_test(test_velocity_across_wrap),  cmocka_unit_test(test_step_rejects_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
