/* SPDX-License-Identifier: Apache-2.0 */
/* Plant simulator: guards, stiction, accuracy by step halving at 0.05 m/s,
 * boundedness at every speed the axis reaches, encoder quantisation. */
#include "br_test.h"

#include "plant/br_sim_plant.h"

static const br_plant_state_t rest = {0.0, 0.0, 0.0};

static void test_init_guards(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    const br_plant_state_t bad_x = {NAN, 0.0, 0.0};
    c = br_plant_cfg_reference(); assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    assert_int_equal(br_plant_init(NULL, &c, &rest), -1);
    assert_int_equal(br_plant_init(&p, &c, &bad_x), -1);
    c = br_plant_cfg_reference(); c.J_kgm2 = 0.0;          assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.M_kg = -1.0;           assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.lead_mprad = NAN;      assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.sigma2_Nspm = -1.0;    assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.sigma0_Npm = 0.0;      assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.sigma1_Nspm = -2.0;    assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.Fc_N = 0.0;            assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.Fs_N = 1.0;            assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.vs_mps = INFINITY;     assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.counts_per_rev = 0.0;  assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.tau_per_duty_Nm = 0.0; assert_int_equal(br_plant_init(&p, &c, &rest), -1);
    c = br_plant_cfg_reference(); c.n_sub = 0;             assert_int_equal(br_plant_init(&p, &c, &rest), -1);
}

static void test_sticks_below_stiction(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    /* a force ramped over 2 s to 5/9 of Fs at the load (10 N on the reference):
     * presliding only. (The breakaway force of LuGre falls with the force rate:
     * on the reference a 15 N step breaks away, its 54 Hz presliding ring
     * reaching speeds far above vs.) */
    const double f_hold = c.Fs_N * 5.0 / 9.0;
    double duty = f_hold * c.lead_mprad / c.tau_per_duty_Nm;
    for (int k = 0; k < 2000; k++) br_plant_step(&p, duty * (k + 1) / 2000.0, 1e-3);
    double x = br_plant_pos_m(&p);
    /* a few bristle lengths (Fs/sigma0, 4.5 um on the reference) at most; once the
     * force is held, only the slow creep of LuGre below breakaway (tens of nm per second) */
    print_message("presliding at %.3g N: %.3g m\n", f_hold, x);
    assert_true(x > f_hold / c.sigma0_Npm && x < 3.0 * c.Fs_N / c.sigma0_Npm);
    for (int k = 0; k < 1000; k++) br_plant_step(&p, duty, 1e-3);
    BR_ASSERT_NEAR(br_plant_pos_m(&p), x, 1e-7);
    BR_ASSERT_NEAR(p.fnl_N, f_hold, 0.05);
    /* ramped on to twice that (> Fs): it breaks away and slides */
    for (int k = 0; k < 1000; k++) br_plant_step(&p, duty * (1.0 + (k + 1) / 1000.0), 1e-3);
    assert_true(br_plant_pos_m(&p) > 1e-4);
}

/* the long-stroke speed of ../shared/spec/reference-machine.md: a property of the
 * test (a fast move, where the bristle rate is stiff), not of the machine */
#define V_CRUISE_MPS 0.05

/* Bang-bang at V_CRUISE_MPS: accelerate, cruise, reverse, cruise. */
static void run_profile(int n_sub, double out[4])
{
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.n_sub = n_sub;
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    const double L = c.lead_mprad, Jeff = c.J_kgm2 + L * L * c.M_kg;
    /* cruise torque: viscous + Coulomb */
    const double cruise = (L * L * c.sigma2_Nspm * V_CRUISE_MPS / L + L * c.Fc_N) / c.tau_per_duty_Nm;
    double zmax = 0.0;
    for (int k = 0; k < 400; k++) {
        double v = br_plant_vel_mps(&p), duty;
        if (k < 150) duty = v < V_CRUISE_MPS ? 0.5 : cruise;
        else duty = v > -V_CRUISE_MPS ? -0.5 : -cruise;
        br_plant_step(&p, duty, 1e-3);
        if (fabs(p.x.z_m) > zmax) zmax = fabs(p.x.z_m);
    }
    (void)Jeff;
    out[0] = br_plant_pos_m(&p);
    out[1] = br_plant_vel_mps(&p);
    out[2] = p.fnl_N;
    out[3] = zmax;
}

static void test_half_step_at_speed(void **st)
{
    (void)st;
    double a[4], b[4];
    run_profile(20, a); /* h = 50 us, the default */
    run_profile(40, b); /* h = 25 us */
    print_message("%.2g m/s profile: |dpos| = %.3g m, |dvel| = %.3g m/s, |dF| = %.3g N (h vs h/2)\n", V_CRUISE_MPS,
                  fabs(a[0] - b[0]), fabs(a[1] - b[1]), fabs(a[2] - b[2]));
    assert_true(fabs(b[1]) > 0.98 * V_CRUISE_MPS);   /* the profile did reach the speed */
    BR_ASSERT_NEAR(a[0], b[0], 1e-8);                /* about one encoder count (7.6 nm on the reference) */
    BR_ASSERT_NEAR(a[1], b[1], 1e-5 * V_CRUISE_MPS);
    const br_plant_cfg_t c = br_plant_cfg_reference();
    BR_ASSERT_NEAR(a[2], b[2], 1e-3 * c.Fc_N);
    assert_true(a[3] <= c.Fs_N / c.sigma0_Npm && b[3] <= c.Fs_N / c.sigma0_Npm); /* |z| <= Fs / sigma0 */
}

static void test_bounded_at_full_duty(void **st)
{
    (void)st;
    /* full duty for 2 s reaches the top speed (viscous limit, several m/s); with
     * one substep per ms (a h ~ 1e4) the state must stay finite and bounded */
    for (int n_sub = 1; n_sub <= 20; n_sub += 19) {
        br_plant_t p;
        br_plant_cfg_t c = br_plant_cfg_reference();
        c.n_sub = n_sub;
        assert_int_equal(br_plant_init(&p, &c, &rest), 0);
        for (int k = 0; k < 2000; k++) {
            br_plant_step(&p, k < 1000 ? 1.0 : -1.0, 1e-3);
            assert_true(isfinite(p.x.omega_radps) && isfinite(p.x.theta_rad));
            assert_true(fabs(p.x.z_m) <= c.Fs_N / c.sigma0_Npm);
        }
        double vmax = (c.tau_per_duty_Nm - c.lead_mprad * c.Fc_N) / (c.lead_mprad * c.lead_mprad * c.sigma2_Nspm) *
                      c.lead_mprad;
        assert_true(fabs(br_plant_vel_mps(&p)) < vmax);
        assert_true(br_plant_vel_mps(&p) < -1.0); /* reversed and at speed */
        BR_ASSERT_NEAR(p.fnl_N, -c.Fc_N, 1e-6);
    }
}

static void test_encoder_quantisation_and_wrap(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    const double rpc = 2.0 * 3.14159265358979323846 / c.counts_per_rev;
    br_plant_state_t x = {10.6 * rpc, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x), 0);
    assert_int_equal(br_plant_encoder(&p), 10);
    p.x.theta_rad = -0.5 * rpc;
    assert_int_equal(br_plant_encoder(&p), -1);
    /* 2^31 + 5 counts wraps to INT32_MIN + 5 */
    p.x.theta_rad = (2147483648.0 + 5.5) * rpc;
    assert_int_equal(br_plant_encoder(&p), INT32_MIN + 5);
}

static void test_initial_force_matches_state(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    br_plant_state_t x0 = {0.0, 0.0, 1.0e-6};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    BR_ASSERT_NEAR(p.fnl_N, c.sigma0_Npm * 1.0e-6, 1e-12); /* eq. 3 at rest */
}

static void test_nonfinite_duty_is_zero_torque(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    br_plant_step(&p, NAN, 1e-3);
    assert_true(p.tau_Nm == 0.0 && p.x.theta_rad == 0.0);
    br_plant_step(&p, 7.0, 1e-3); /* clamped to full duty */
    BR_ASSERT_NEAR(p.tau_Nm, c.tau_per_duty_Nm, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),          cmocka_unit_test(test_sticks_below_stiction),
        cmocka_unit_test(test_half_step_at_speed),   cmocka_unit_test(test_bounded_at_full_duty),
        cmocka_unit_test(test_encoder_quantisation_and_wrap), cmocka_unit_test(test_nonfinite_duty_is_zero_torque),
        cmocka_unit_test(test_initial_force_matches_state),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
