/* SPDX-License-Identifier: Apache-2.0 */
/* Plant simulator, the causes of ../shared/spec/measured-log.md: one guard
 * test per new configuration field, and one physical check per cause
 * (offset, asymmetric friction, position ripple, position gradient, actuator
 * delay, friction drift), each against the cause switched off. The causes-off path is held
 * bit for bit by the golden plant test. */
#include "br_test.h"

#include "plant/br_sim_plant.h"

#define PI 3.14159265358979323846

static const br_plant_state_t rest = {0.0, 0.0, 0.0};

/* the sliding speed of the settling tests: a property of the test */
#define V_SLIDE_MPS 0.05

static int init_with(br_plant_cfg_t c)
{
    br_plant_t p;
    return br_plant_init(&p, &c, &rest);
}

static void test_cause_guards(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    assert_int_equal(init_with(c), 0);
    assert_int_equal(br_plant_causes_on(&c), 0);
    c = br_plant_cfg_reference(); c.offset_N = NAN;              assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.offset_N = -3.0;             assert_int_equal(init_with(c), 0);
    c = br_plant_cfg_reference(); c.dFc_neg_N = -c.Fc_N;         assert_int_equal(init_with(c), -1); /* Fc in -x = 0 */
    c = br_plant_cfg_reference(); c.dFc_neg_N = INFINITY;        assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.dFc_neg_N = 1.0 - c.Fc_N;    assert_int_equal(init_with(c), 0);  /* 1 N in -x */
    c = br_plant_cfg_reference(); c.dsigma2_neg_Nspm = -c.sigma2_Nspm - 0.1; assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.dsigma2_neg_Nspm = NAN;      assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.dsigma2_neg_Nspm = -c.sigma2_Nspm; assert_int_equal(init_with(c), 0);
    c = br_plant_cfg_reference(); c.ripple_amp_N = NAN;          assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.ripple_amp_N = 1.0;          assert_int_equal(init_with(c), -1); /* period 0 */
    c.ripple_period_m = -0.008;                                  assert_int_equal(init_with(c), -1);
    c.ripple_period_m = 0.008;                                   assert_int_equal(init_with(c), 0);
    c.ripple_phase_rad = INFINITY;                               assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.ripple_period_m = NAN;       assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.grad_per_m = NAN;            assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.drift_per_s = INFINITY;      assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.drift_per_s = -0.01;         assert_int_equal(init_with(c), 0);
    assert_int_equal(br_plant_causes_on(&c), 1);
    c = br_plant_cfg_reference(); c.delay_s = -1e-3;             assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.delay_s = BR_PLANT_DELAY_MAX_S * 1.01; assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.delay_s = NAN;              assert_int_equal(init_with(c), -1);
    c = br_plant_cfg_reference(); c.delay_s = BR_PLANT_DELAY_MAX_S; assert_int_equal(init_with(c), 0);
    assert_int_equal(br_plant_causes_on(&c), 1);
}

/* Velocity change over one very short step from rest at x0: friction has no
 * time to act (z grows with the displacement), so the difference between
 * two plants is the cause's force: Jeff dw = -L F dt. */
static double first_step_dw(br_plant_cfg_t c, double x0_m, double duty, double dt)
{
    br_plant_t p;
    br_plant_state_t x0 = {x0_m / c.lead_mprad, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    br_plant_step(&p, duty, dt);
    return p.x.omega_radps;
}

static void test_offset_and_ripple_force(void **st)
{
    (void)st;
    const br_plant_cfg_t ref = br_plant_cfg_reference();
    const double dt = 1e-7, L = ref.lead_mprad, Jeff = ref.J_kgm2 + L * L * ref.M_kg;
    const double w_ref = first_step_dw(ref, 0.0, 0.01, dt);
    br_plant_cfg_t c = ref;
    c.offset_N = 2.5;
    const double dw_off = first_step_dw(c, 0.0, 0.01, dt) - w_ref;
    BR_ASSERT_NEAR(dw_off, -L * 2.5 * dt / Jeff, 1e-3 * L * 2.5 * dt / Jeff);
    /* ripple: A sin(2 pi x / P + phase) at three positions */
    c = ref;
    c.ripple_amp_N = 1.5;
    c.ripple_period_m = 0.008;
    c.ripple_phase_rad = 0.3;
    for (int i = 0; i < 3; i++) {
        const double x = 0.0017 * i + 0.0005;
        const double f = 1.5 * sin(2.0 * PI * x / 0.008 + 0.3);
        const double dw = first_step_dw(c, x, 0.01, dt) - first_step_dw(ref, x, 0.01, dt);
        BR_ASSERT_NEAR(dw, -L * f * dt / Jeff, 1e-3 * L * 1.5 * dt / Jeff);
    }
    /* and fdist_N reports it */
    br_plant_t p;
    br_plant_state_t x0 = {0.002 / L, 0.0, 0.0};
    c.offset_N = 0.5;
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    br_plant_step(&p, 0.0, 1e-3);
    BR_ASSERT_NEAR(p.fdist_N, 0.5 + 1.5 * sin(2.0 * PI * br_plant_pos_m(&p) / 0.008 + 0.3), 1e-12);
}

/* Constant torque until the velocity settles: tau/L = sigma2 v + g (+ offset). */
static double settle(br_plant_cfg_t c, double F_N, double *fnl)
{
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    const double duty = F_N * c.lead_mprad / c.tau_per_duty_Nm;
    for (int k = 0; k < 6000; k++) br_plant_step(&p, duty, 1e-3); /* 6 s, 8.5 mechanical time constants */
    *fnl = p.fnl_N;
    return br_plant_vel_mps(&p);
}

static void test_offset_shifts_sliding(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    double fnl;
    /* F = Fc + sigma2 V slides at V without the offset (9.5 N, 0.05 m/s on the
     * reference); an offset of 0.8 sigma2 V leaves 0.2 sigma2 V: 0.2 V */
    const double F = c.Fc_N + c.sigma2_Nspm * V_SLIDE_MPS, off = 0.8 * c.sigma2_Nspm * V_SLIDE_MPS;
    BR_ASSERT_NEAR(settle(c, F, &fnl), V_SLIDE_MPS, 1e-4);
    c.offset_N = off;
    BR_ASSERT_NEAR(settle(c, F, &fnl), 0.2 * V_SLIDE_MPS, 1e-4);
    BR_ASSERT_NEAR(settle(c, -F, &fnl), -(F + off - c.Fc_N) / c.sigma2_Nspm, 1e-4);
}

static void test_asymmetric_friction(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.dFc_neg_N = 1.0;          /* Fc + 1 N in -x (8 N on the reference) */
    c.dsigma2_neg_Nspm = 30.0;  /* sigma2 + 30 N s/m in -x (80 N s/m on the reference) */
    double fnl;
    /* +x unchanged: Fc + sigma2 V slides at V */
    BR_ASSERT_NEAR(settle(c, c.Fc_N + c.sigma2_Nspm * V_SLIDE_MPS, &fnl), V_SLIDE_MPS, 1e-4);
    BR_ASSERT_NEAR(fnl, c.Fc_N, 1e-3);
    /* -x: the larger levels, (Fc + 1) + (sigma2 + 30) V slides at V (12 N on the
     * reference), LuGre at -(Fc + 1) */
    const double Fneg = (c.Fc_N + 1.0) + (c.sigma2_Nspm + 30.0) * V_SLIDE_MPS;
    BR_ASSERT_NEAR(settle(c, -Fneg, &fnl), -V_SLIDE_MPS, 1e-4);
    BR_ASSERT_NEAR(fnl, -(c.Fc_N + 1.0), 1e-3);
}

/* The oracle's force (br_plant_comp_force_N): at steady sliding the axis does
 * not accelerate, so the applied force F is the whole load force, and the
 * oracle's is F less the nominal viscous sigma2 v, in either direction, with
 * offset and asymmetry on; without causes it is fnl_N itself. */
static void test_comp_force_balances_the_drive(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.dFc_neg_N = 1.0;
    c.dsigma2_neg_Nspm = 30.0;
    c.offset_N = 0.4;
    const double Fs[2] = {c.Fc_N + c.sigma2_Nspm * V_SLIDE_MPS + 0.4,
                          -((c.Fc_N + 1.0) + (c.sigma2_Nspm + 30.0) * V_SLIDE_MPS) + 0.4};
    for (int d = 0; d < 2; d++) {
        br_plant_t p;
        assert_int_equal(br_plant_init(&p, &c, &rest), 0);
        const double duty = Fs[d] * c.lead_mprad / c.tau_per_duty_Nm;
        for (int k = 0; k < 6000; k++) br_plant_step(&p, duty, 1e-3);
        const double v = br_plant_vel_mps(&p);
        BR_ASSERT_NEAR(fabs(v), V_SLIDE_MPS, 1e-4);
        /* 1e-3 N: the settling's remaining acceleration (as test_asymmetric_friction) */
        BR_ASSERT_NEAR(br_plant_comp_force_N(&p), Fs[d] - c.sigma2_Nspm * v, 1e-3);
    }
    br_plant_cfg_t r = br_plant_cfg_reference();
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &r, &rest), 0);
    for (int k = 0; k < 50; k++) br_plant_step(&p, 0.01, 1e-3);
    assert_true(br_plant_comp_force_N(&p) == p.fnl_N);
    /* before the first step, at rest (z = 0, v = 0): the offset and the ripple at
     * the start position are the whole force, already (the first period's oracle) */
    c.ripple_amp_N = 0.3;
    c.ripple_period_m = 0.01;
    c.ripple_phase_rad = 0.5;
    br_plant_state_t x0 = {0.0025 / c.lead_mprad, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    BR_ASSERT_NEAR(br_plant_comp_force_N(&p), 0.4 + 0.3 * cos(0.5), 1e-12); /* sin(2 pi 1/4 + 0.5) */
}

static void test_position_gradient(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.grad_per_m = 2.0; /* +20 % over 0.1 m */
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    /* slide at V or faster over the first 0.1 m for 2 s (the force holds V at
     * Fc (1 + 2 * 0.1)): the Coulomb level follows Fc (1 + 2 x) */
    const double duty = (1.2 * c.Fc_N + c.sigma2_Nspm * V_SLIDE_MPS) * c.lead_mprad / c.tau_per_duty_Nm;
    for (int k = 0; k < 2000; k++) {
        br_plant_step(&p, duty, 1e-3);
        if (k > 1000) {
            const double x = br_plant_pos_m(&p);
            BR_ASSERT_NEAR(p.fnl_N, c.Fc_N * (1.0 + 2.0 * x), 1e-3);
        }
    }
    assert_true(br_plant_pos_m(&p) > 0.05);
    /* the factor stops at 0: friction vanishes, it never pushes */
    c.grad_per_m = -20.0; /* k = 0 beyond x = 0.05 m */
    br_plant_state_t x0 = {0.06 / c.lead_mprad, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    br_plant_step(&p, duty, 1e-3);
    assert_true(p.fnl_N == 0.0);
    /* no friction: the torque accelerates the axis freely */
    const double Jeff = c.J_kgm2 + c.lead_mprad * c.lead_mprad * c.M_kg;
    BR_ASSERT_NEAR(p.x.omega_radps, duty * c.tau_per_duty_Nm * 1e-3 / Jeff, 1e-9);
}

/* Friction drift: sliding under a force that grows like the friction
 * level, the Coulomb level follows Fc (1 + r t) with the plant's time; with
 * r < 0 the level stops at 0 (friction vanishes, never pushes). */
static void test_friction_drift(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.drift_per_s = 0.1; /* +20 % after 2 s */
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    for (int k = 0; k < 2000; k++) {
        const double t = p.t_s + 0.5e-3;
        const double duty = (1.0 + c.drift_per_s * t) * (c.Fc_N + c.sigma2_Nspm * V_SLIDE_MPS) * c.lead_mprad /
                            c.tau_per_duty_Nm;
        br_plant_step(&p, duty, 1e-3);
        if (k > 1000) {
            BR_ASSERT_NEAR(p.fnl_N, c.Fc_N * (1.0 + c.drift_per_s * p.t_s), 1e-3);
        }
    }
    c.drift_per_s = -1.0; /* s = 0 from t = 1 s */
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    for (int k = 0; k < 1001; k++) {
        br_plant_step(&p, 0.0, 1e-3);
    }
    const double duty = 0.01, w0 = p.x.omega_radps;
    br_plant_step(&p, duty, 1e-3);
    assert_true(p.fnl_N == 0.0);
    const double Jeff = c.J_kgm2 + c.lead_mprad * c.lead_mprad * c.M_kg;
    BR_ASSERT_NEAR(p.x.omega_radps - w0, duty * c.tau_per_duty_Nm * 1e-3 / Jeff, 1e-9);
}

/* Actuator delay: a plant with a 2 ms dead time reproduces, two steps later,
 * the plant without one; a 2.5 ms dead time reproduces a plant stepped at
 * 0.5 ms whose commands come 5 half-steps late. */
static void test_delay_shifts_the_command(void **st)
{
    (void)st;
    br_plant_cfg_t c0 = br_plant_cfg_reference(), cd = c0;
    cd.delay_s = 2e-3;
    br_plant_t a, b;
    assert_int_equal(br_plant_init(&a, &c0, &rest), 0);
    assert_int_equal(br_plant_init(&b, &cd, &rest), 0);
    double xa[400];
    for (int k = 0; k < 400; k++) {
        const double duty = 0.05 * sin(0.02 * k) + (k % 100 < 50 ? 0.03 : -0.03);
        br_plant_step(&a, duty, 1e-3);
        br_plant_step(&b, duty, 1e-3);
        xa[k] = br_plant_pos_m(&a);
        if (k < 2) assert_true(b.x.theta_rad == 0.0); /* nothing applied yet */
        else BR_ASSERT_NEAR(br_plant_pos_m(&b), xa[k - 2], 1e-12 + 1e-9 * fabs(xa[k - 2]));
    }
    cd.delay_s = 2.5e-3;
    br_plant_cfg_t ch = c0;
    ch.n_sub = 10; /* same substep, 50 us, at 0.5 ms */
    assert_int_equal(br_plant_init(&a, &ch, &rest), 0);
    assert_int_equal(br_plant_init(&b, &cd, &rest), 0);
    double duties[400];
    for (int k = 0; k < 400; k++) duties[k] = 0.05 * sin(0.02 * k) + (k % 100 < 50 ? 0.03 : -0.03);
    for (int k = 0; k < 400; k++) {
        br_plant_step(&b, duties[k], 1e-3);
        for (int half = 0; half < 2; half++) {
            const int j = 2 * k + half - 5; /* half-step index of the command reaching the axis */
            br_plant_step(&a, j >= 0 ? duties[j / 2] : 0.0, 0.5e-3);
        }
        BR_ASSERT_NEAR(br_plant_pos_m(&b), br_plant_pos_m(&a), 1e-12 + 1e-9 * fabs(br_plant_pos_m(&a)));
    }
    assert_true(b.delay_overruns == 0);
    assert_true(fabs(br_plant_pos_m(&b)) > 1e-4); /* it did move */
}

/* A dead time longer than the history: the oldest command is used and the
 * steps are counted; the state stays finite. */
static void test_delay_overrun_is_counted(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.delay_s = 0.05;
    c.n_sub = 1;
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    /* 10 us steps: the history spans 1024 x 10 us = 10 ms < 50 ms */
    for (int k = 0; k < 3000; k++) br_plant_step(&p, 0.1, 1e-5);
    assert_true(p.delay_overruns > 0 && p.delay_overruns <= 3000 - BR_PLANT_DELAY_RING + 1);
    assert_true(isfinite(p.x.omega_radps) && p.x.omega_radps > 0.0);
    /* 1 ms steps: 1 s of history, no overrun */
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    for (int k = 0; k < 3000; k++) br_plant_step(&p, 0.1, 1e-3);
    assert_true(p.delay_overruns == 0);
}

/* Every cause on at once, full duty both ways: finite and bounded. */
static void test_all_causes_bounded(void **st)
{
    (void)st;
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.offset_N = 3.0;
    c.dFc_neg_N = 2.0;
    c.dsigma2_neg_Nspm = 20.0;
    c.ripple_amp_N = 2.0;
    c.ripple_period_m = 0.004;
    c.grad_per_m = 1.0;
    c.delay_s = 3e-3;
    for (int n_sub = 1; n_sub <= 20; n_sub += 19) {
        c.n_sub = n_sub;
        br_plant_t p;
        assert_int_equal(br_plant_init(&p, &c, &rest), 0);
        for (int k = 0; k < 2000; k++) {
            br_plant_step(&p, k < 1000 ? 1.0 : -1.0, 1e-3);
            assert_true(isfinite(p.x.omega_radps) && isfinite(p.x.theta_rad) && isfinite(p.fnl_N));
            /* |z| <= the larger stiction level over sigma0 (in -x: Fs scaled by (Fc + dFc) / Fc) */
            assert_true(fabs(p.x.z_m) <= c.Fs_N * (c.Fc_N + c.dFc_neg_N) / c.Fc_N / c.sigma0_Npm);
        }
        assert_true(br_plant_vel_mps(&p) < -1.0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cause_guards),
        cmocka_unit_test(test_offset_and_ripple_force),
        cmocka_unit_test(test_offset_shifts_sliding),
        cmocka_unit_test(test_asymmetric_friction),
        cmocka_unit_test(test_comp_force_balances_the_drive),
        cmocka_unit_test(test_position_gradient),
        cmocka_unit_test(test_friction_drift),
        cmocka_unit_test(test_delay_shifts_the_command),
        cmocka_unit_test(test_delay_overrun_is_counted),
        cmocka_unit_test(test_all_causes_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
