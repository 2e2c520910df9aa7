/* SPDX-License-Identifier: Apache-2.0 */
/* Plant simulator, the Maxwell-slip friction (sim/lib/plant/br_gms.h,
 * ../shared/spec/presliding.md): one guard test per configuration field,
 * the elements bounded at any step for both laws, the slip law tending to
 * the clamp at a large C, presliding_m against presliding.md's example, and
 * the hardware-like plant of the demo. The trajectories themselves are held
 * to golden/ref/gms.py by test_golden_plant. */
#include "br_test.h"

#include "circle/br_circle.h"
#include "plant/br_sim_plant.h"

#define TWO_PI 6.283185307179586

static const br_plant_state_t rest = {0.0, 0.0, 0.0};

/* a valid Maxwell-slip plant: the reference machine with the demo's
 * hardware-like elements (slip law) */
static br_plant_cfg_t gms_cfg(void)
{
    return br_circle_cfg_hardware_like(BR_CTRL_HINF_ONLY).plant;
}

static int init_with(br_plant_cfg_t c)
{
    br_plant_t p;
    return br_plant_init(&p, &c, &rest);
}

static void test_gms_guards(void **st)
{
    (void)st;
    br_plant_cfg_t c = gms_cfg();
    assert_int_equal(init_with(c), 0);
    c = gms_cfg(); c.gms.n = BR_GMS_MAX + 1;          assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.n = -1;                      assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.clamp = 2;                   assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.C_mps = 0.0;                 assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.C_mps = NAN;                 assert_int_equal(init_with(c), -1);
    c.gms.clamp = 1;                                  assert_int_equal(init_with(c), 0); /* C unused by the clamp */
    c = gms_cfg(); c.gms.delta = 0.0;                 assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.delta = 10.5;                assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.k_Npm[2] = 0.0;              assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.k_Npm[3] = INFINITY;         assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.alpha[0] = 0.0;              assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.sigma1_Nspm[1] = -1.0;       assert_int_equal(init_with(c), -1);
    c = gms_cfg(); c.gms.sigma1_Nspm[1] = 0.0;        assert_int_equal(init_with(c), 0);
    c = gms_cfg(); c.gms.alpha[0] += 1e-6;            assert_int_equal(init_with(c), -1); /* shares sum 1 */
    c = gms_cfg(); c.gms.n = 0;                       assert_int_equal(init_with(c), 0);  /* LuGre */
}

/* full duty both ways for 2 s: every element within its largest slip
 * deflection alpha_i Fs / k_i, whatever the substep */
static void test_gms_bounded_any_step(void **st)
{
    (void)st;
    const int nsubs[2] = {1, 20};
    for (int law = 0; law < 2; law++) {
        for (int s = 0; s < 2; s++) {
            br_plant_cfg_t c = gms_cfg();
            c.gms.clamp = law;
            c.gms.C_mps = 10.0; /* a fast slip law: the stiffest case for a step */
            c.n_sub = nsubs[s];
            br_plant_t p;
            assert_int_equal(br_plant_init(&p, &c, &rest), 0);
            double vmax = 0.0;
            for (int k = 0; k < 2000; k++) {
                br_plant_step(&p, k < 1000 ? 1.0 : -1.0, 1e-3);
                assert_true(isfinite(p.x.omega_radps) && isfinite(p.fnl_N));
                vmax = fmax(vmax, fabs(br_plant_vel_mps(&p)));
                for (int i = 0; i < c.gms.n; i++) {
                    const double dmax = c.gms.alpha[i] * c.Fs_N / c.gms.k_Npm[i];
                    assert_true(fabs(p.gms.z_m[i]) <= dmax * (1.0 + 1e-12));
                }
            }
            assert_true(vmax > 0.05); /* it did slide fast */
        }
    }
}

/* the largest force difference between the slip law at C and the clamp
 * over a travel at held speeds around vs, each with its Stribeck level;
 * rising speeds in each direction, so Delta_i never rises during a slip
 * (where it rises the laws differ at any C: docs/modules/plant.md) */
static double slip_vs_clamp_N(double C_mps)
{
    const br_plant_cfg_t c = gms_cfg();
    br_gms_cfg_t slip = c.gms, clamp = c.gms;
    slip.C_mps = C_mps;
    clamp.clamp = 1;
    br_gms_state_t a = {{0}, {0}}, b = {{0}, {0}}, a1, b1;
    const double v[6] = {1e-5, 3e-5, 8e-5, -5e-6, -2e-5, -2e-4};
    double err = 0.0;
    for (int k = 0; k < 600; k++) {
        const double vk = v[k / 100], h = 1e-3;
        const double s_N = c.Fc_N + (c.Fs_N - c.Fc_N) * exp(-fabs(vk) / c.vs_mps);
        br_gms_advance(&slip, &a, &a1, vk, h, s_N);
        br_gms_advance(&clamp, &b, &b1, vk, h, s_N);
        a = a1;
        b = b1;
        err = fmax(err, fabs(br_gms_force_N(&slip, &a, vk, s_N) - br_gms_force_N(&clamp, &b, vk, s_N)));
    }
    return err;
}

/* the clamp is the slip law's limit C -> infinity: the difference falls with C */
static void test_gms_slip_tends_to_clamp(void **st)
{
    (void)st;
    const double e2 = slip_vs_clamp_N(1e-2), e1 = slip_vs_clamp_N(1e-1), e0 = slip_vs_clamp_N(1.0);
    print_message("slip law vs clamp, largest force difference: C 0.01 m/s %.3g N, 0.1 m/s %.3g N, 1 m/s %.3g N\n",
                  e2, e1, e0);
    assert_true(e2 > 0.1);
    assert_true(e1 < e2 && e0 < e1);
    assert_true(e0 < 0.1);
}

/* presliding.md: four equal elements breaking away at 1, 3, 8, 20 um give 24 um */
static void test_gms_presliding_m(void **st)
{
    (void)st;
    br_gms_cfg_t g = {0};
    const double d[4] = {1e-6, 3e-6, 8e-6, 20e-6}, a[4] = {0.25, 0.25, 0.25, 0.25};
    br_gms_from_breakaway(&g, 4, d, a, 18.0, 0.0);
    assert_float_equal(br_gms_presliding_m(&g, 18.0), 24e-6, 1e-12);
}

/* the demo's hardware-like plant: initial stiffness within 5 % of the
 * reference machine's sigma0 (presliding.md: comparable), same Stribeck curve */
static void test_hardware_like_plant(void **st)
{
    (void)st;
    const br_plant_cfg_t c = gms_cfg(), ref = br_plant_cfg_reference();
    double k0 = 0.0;
    for (int i = 0; i < c.gms.n; i++) k0 += c.gms.k_Npm[i];
#ifdef BR_TEST_THESIS_MACHINE
    /* comparable to LuGre's on the reference machine (docs/demo.md); another machine's
     * sigma0 is its own, the breakaway displacements the demo's */
    assert_true(fabs(k0 / ref.sigma0_Npm - 1.0) < 0.05);
#else
    assert_true(isfinite(k0) && k0 > 0.0);
#endif
    assert_true(c.Fc_N == ref.Fc_N && c.Fs_N == ref.Fs_N && c.vs_mps == ref.vs_mps && c.gms.delta == 1.0);
    assert_int_equal(c.gms.clamp, 0);
}

/* The free decay of the load on sticking elements with the damping of
 * br_gms_damping_ratio (zeta per element), from an initial speed with no
 * torque and no viscous friction: the damping ratio from the logarithmic
 * decrement of the velocity's peaks over `cycles` periods, delta = ln(p0 / pn) / n,
 * zeta = delta / sqrt(4 pi^2 + delta^2); *wn_radps the undamped frequency from
 * the peaks' spacing, wd / sqrt(1 - zeta^2). Breakaways of a millimetre: the
 * sub-micrometre swing never reaches a slip. */
static double decay_ratio(int n, const double d_m[], double zeta, double *wn_radps)
{
    br_plant_cfg_t c = br_plant_cfg_reference();
    c.sigma2_Nspm = 0.0;
    double share[BR_GMS_MAX];
    for (int i = 0; i < n; i++) share[i] = 1.0 / n;
    br_gms_from_breakaway(&c.gms, n, d_m, share, c.Fs_N, 0.0);
    c.gms.clamp = 1;
    c.gms.delta = 1.0;
    br_gms_damping_ratio(&c.gms, zeta, br_plant_meff_kg(&c));
    const br_plant_state_t moving = {0.0, 1e-5 / c.lead_mprad, 0.0}; /* 10 um/s at the load */
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &c, &moving), 0);
    const double dt = 1e-4;
    const int cycles = 3;
    double v_prev2 = 0.0, v_prev = br_plant_vel_mps(&p), peak[4] = {0.0}, t_peak[4] = {0.0};
    int found = 0;
    for (int k = 1; k <= 200000 && found <= cycles; k++) {
        br_plant_step(&p, 0.0, dt);
        const double v = br_plant_vel_mps(&p);
        for (int i = 0; i < n; i++) /* within half its slip deflection: sticking throughout */
            assert_true(fabs(p.gms.z_m[i]) < 0.5 * c.gms.alpha[i] * c.Fc_N / c.gms.k_Npm[i]);
        if (k >= 2 && v_prev > v_prev2 && v_prev >= v && v_prev > 0.0) { /* a positive peak at step k - 1 */
            peak[found] = v_prev;
            t_peak[found] = (k - 1) * dt;
            found++;
        }
        v_prev2 = v_prev;
        v_prev = v;
    }
    assert_int_equal(found, cycles + 1);
    const double delta = log(peak[0] / peak[cycles]) / cycles;
    const double z = delta / sqrt(TWO_PI * TWO_PI + delta * delta);
    *wn_radps = TWO_PI / ((t_peak[cycles] - t_peak[0]) / cycles) / sqrt(1.0 - z * z);
    return z;
}

/* br_gms_damping_ratio: one element on the moving mass is a mode sqrt(k / M)
 * of damping ratio zeta; four elements sticking together a mode
 * sqrt(sum k_i / M) of ratio zeta sum sqrt(k_i) / sqrt(sum k_i)
 * (docs/modules/plant.md, "Element damping") */
static void test_gms_damping_ratio(void **st)
{
    (void)st;
    const br_plant_cfg_t ref = br_plant_cfg_reference();
    const double meff = br_plant_meff_kg(&ref);
    assert_float_equal(meff, ref.M_kg + ref.J_kgm2 / (ref.lead_mprad * ref.lead_mprad), 1e-12);
    const double one[1] = {1e-3}, four[4] = {1e-4, 2.5e-4, 5e-4, 1e-3};
    for (int z = 0; z < 2; z++) {
        const double zeta = z == 0 ? 0.085 : 0.3;
        double wn, wn4;
        const double z1 = decay_ratio(1, one, zeta, &wn);
        const double z4 = decay_ratio(4, four, zeta, &wn4);
        double ksum = 0.0, sqsum = 0.0;
        for (int i = 0; i < 4; i++) {
            const double k = 0.25 * ref.Fs_N / four[i];
            ksum += k;
            sqsum += sqrt(k);
        }
        print_message("zeta %.3g: one element %.4g (wn %.4g, sqrt(k/M) %.4g rad/s); four elements %.4g "
                      "(expected %.4g, wn %.4g, sqrt(sum k/M) %.4g rad/s)\n", zeta, z1, wn,
                      sqrt(ref.Fs_N / one[0] / meff), z4, zeta * sqsum / sqrt(ksum), wn4, sqrt(ksum / meff));
        assert_true(fabs(z1 / zeta - 1.0) < 0.01);
        assert_true(fabs(wn / sqrt(ref.Fs_N / one[0] / meff) - 1.0) < 0.005);
        assert_true(fabs(z4 / (zeta * sqsum / sqrt(ksum)) - 1.0) < 0.01);
        assert_true(fabs(wn4 / sqrt(ksum / meff) - 1.0) < 0.005);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gms_guards),
        cmocka_unit_test(test_gms_bounded_any_step),
        cmocka_unit_test(test_gms_slip_tends_to_clamp),
        cmocka_unit_test(test_gms_presliding_m),
        cmocka_unit_test(test_hardware_like_plant),
        cmocka_unit_test(test_gms_damping_ratio),
    };
    return cmocka_run_group_tests_name("plant_gms", tests, NULL, NULL);
}
