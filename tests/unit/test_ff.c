/* SPDX-License-Identifier: Apache-2.0 */
/* Friction feedforward (firmware/ff): configuration guards, the map of
 * br_ff.h against the same equation in double, the clamp, input guards and
 * the br_est_t adapter. */
#include "br_test.h"

#include <math.h>

#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_ff.h"

static br_ff_cfg_t ref_cfg(void)
{
    br_ff_cfg_t c = {0};
    c.Fc_N = BR_MACHINE_FC_N_F;
    c.Fs_N = BR_MACHINE_FS_N_F;
    c.vs_mps = BR_MACHINE_VS_MPS_F;
    c.sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM_F;
    c.v_eps_mps = 1.0e-6f;
    c.mass_kg = 0.0f;
    c.comp_max_N = 1000.0f;
    return c;
}

/* the map in double, written from br_ff.h's equations */
static double ff_ref(const br_ff_cfg_t *c, double v, double a, double p)
{
    const br_causes_t *k = &c->causes;
    double g = c->Fc_N + (c->Fs_N - c->Fc_N) * exp(-fabs(v) / c->vs_mps);
    double s2 = c->sigma2_Nspm;
    if (v < 0.0) {
        g *= ((double)c->Fc_N + k->dFc_neg_N) / c->Fc_N;
        s2 += k->dsigma2_neg_Nspm;
    }
    double f = tanh(v / c->v_eps_mps) * g + s2 * v;
    f *= fmax(0.0, 1.0 + (double)k->grad_per_m * p);
    f += k->offset_N;
    if (k->ripple_amp_N != 0.0f) f += k->ripple_amp_N * sin(2.0 * 3.14159265358979323846 * p / k->ripple_period_m + k->ripple_phase_rad);
    f += (double)c->mass_kg * a;
    return fmin(fmax(f, -(double)c->comp_max_N), c->comp_max_N);
}

static void test_init_guards(void **st)
{
    (void)st;
    br_ff_t ff;
    br_ff_cfg_t c = ref_cfg();
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    assert_int_equal(br_ff_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_ff_init(&ff, NULL), BR_E_NULL);
    c = ref_cfg(); c.Fc_N = 0.0f;              assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fc_N = NAN;               assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fs_N = c.Fc_N * 0.5f;     assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.Fs_N = INFINITY;          assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.vs_mps = 0.0f;            assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.sigma2_Nspm = -1.0f;      assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.v_eps_mps = 0.0f;         assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.mass_kg = -1.0f;          assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.comp_max_N = 0.0f;        assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.causes.offset_N = NAN;    assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.causes.dFc_neg_N = -c.Fc_N; assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.causes.dsigma2_neg_Nspm = -2.0f * c.sigma2_Nspm; assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.causes.ripple_amp_N = 1.0f; assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM); /* no period */
    c = ref_cfg(); c.causes.grad_per_m = INFINITY; assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    assert_int_equal(ff.ready, 0); /* a failed init leaves it unusable */
    float comp = 1.0f;
    const br_ff_in_t in = {1e-5f, 0.0f, 0.0f};
    assert_int_equal(br_ff_step(&ff, &in, &comp), BR_E_STATE);
    assert_true(comp == 0.0f);
}

static void check_against_ref(const br_ff_cfg_t *c)
{
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, c), BR_OK);
    const float vs[] = {-1e-3f, -5e-5f, -1e-5f, -1e-6f, 0.0f, 2e-7f, 1e-6f, 1e-5f, 3e-5f, 1e-3f};
    for (unsigned i = 0; i < sizeof vs / sizeof vs[0]; i++) {
        const br_ff_in_t in = {vs[i], 0.3f * (float)i - 1.0f, 1e-3f * (float)i - 4e-3f};
        float comp;
        assert_int_equal(br_ff_step(&ff, &in, &comp), BR_OK);
        const double want = ff_ref(c, in.v_mps, in.a_mps2, in.p_m);
        /* float32 evaluation of a sum of terms up to ~30 N: 1e-5 relative plus 1e-5 N */
        assert_true(fabs((double)comp - want) <= 1e-5 * fabs(want) + 1e-5);
    }
}

static void test_map_nominal(void **st)
{
    (void)st;
    br_ff_cfg_t c = ref_cfg();
    check_against_ref(&c);
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    /* well past v_eps the map is the Stribeck curve plus viscous friction, odd in v */
    float fp, fn;
    br_ff_in_t in = {1e-4f, 0.0f, 0.0f};
    assert_int_equal(br_ff_step(&ff, &in, &fp), BR_OK);
    in.v_mps = -1e-4f;
    assert_int_equal(br_ff_step(&ff, &in, &fn), BR_OK);
    assert_true(fp == -fn);
    assert_true(fp > c.Fc_N && fp < c.Fs_N);
    /* at rest: nothing (no offset) */
    in.v_mps = 0.0f;
    assert_int_equal(br_ff_step(&ff, &in, &fp), BR_OK);
    assert_true(fp == 0.0f);
}

static void test_map_causes_and_inertia(void **st)
{
    (void)st;
    br_ff_cfg_t c = ref_cfg();
    c.causes.offset_N = 2.5f;
    c.causes.dFc_neg_N = 2.1f;
    c.causes.dsigma2_neg_Nspm = 15.0f;
    c.causes.ripple_amp_N = 1.0f;
    c.causes.ripple_period_m = 0.004f;
    c.causes.ripple_phase_rad = 0.5f;
    c.causes.grad_per_m = 4.0f;
    c.mass_kg = 35.0f;
    check_against_ref(&c);
    /* the asymmetry alone: -x is stronger by (Fc + dFc) / Fc */
    br_ff_cfg_t a = ref_cfg();
    a.causes.dFc_neg_N = 2.1f;
    a.sigma2_Nspm = 0.0f;
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, &a), BR_OK);
    float fp, fn;
    br_ff_in_t in = {1e-4f, 0.0f, 0.0f};
    assert_int_equal(br_ff_step(&ff, &in, &fp), BR_OK);
    in.v_mps = -1e-4f;
    assert_int_equal(br_ff_step(&ff, &in, &fn), BR_OK);
    assert_float_equal(-fn / fp, (a.Fc_N + 2.1f) / a.Fc_N, 1e-5);
}

static void test_clamp_and_inputs(void **st)
{
    (void)st;
    br_ff_cfg_t c = ref_cfg();
    c.comp_max_N = 10.0f;
    c.mass_kg = 100.0f;
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    float comp;
    br_ff_in_t in = {1e-4f, 1.0f, 0.0f}; /* 100 N of inertia */
    assert_int_equal(br_ff_step(&ff, &in, &comp), BR_OK);
    assert_true(comp == 10.0f);
    in.a_mps2 = -1.0f;
    assert_int_equal(br_ff_step(&ff, &in, &comp), BR_OK);
    assert_true(comp == -10.0f);
    /* each input non-finite: BR_E_INPUT and 0 */
    const br_ff_in_t bad[] = {{NAN, 0.0f, 0.0f}, {0.0f, INFINITY, 0.0f}, {0.0f, 0.0f, NAN}};
    for (unsigned i = 0; i < 3; i++) {
        comp = 5.0f;
        assert_int_equal(br_ff_step(&ff, &bad[i], &comp), BR_E_INPUT);
        assert_true(comp == 0.0f);
    }
    /* an overflowing sum is not finite: rejected, not clamped (no force from a NaN) */
    c.comp_max_N = 1e38f;
    c.mass_kg = 3e38f;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    in = (br_ff_in_t){1e-4f, 3e38f, 0.0f};
    assert_int_equal(br_ff_step(&ff, &in, &comp), BR_E_INPUT);
    assert_int_equal(br_ff_step(&ff, NULL, &comp), BR_E_NULL);
    assert_int_equal(br_ff_step(&ff, &in, NULL), BR_E_NULL);
}

static void test_est_adapter(void **st)
{
    (void)st;
    br_ff_cfg_t c = ref_cfg();
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    const br_est_t est = {&ff, br_ff_est_step, NULL, NULL};
    const br_meas_t y = {123, 0.5f};
    const br_ff_in_t in = {2e-5f, 0.0f, 0.0f};
    float want, got;
    assert_int_equal(br_ff_step(&ff, &in, &want), BR_OK);
    assert_int_equal(br_ff_set_ref(&ff, &in), BR_OK);
    assert_int_equal(est.step(est.ctx, &y, 0.1f, &got), BR_OK);
    assert_true(got == want);
    /* a non-finite reference is refused and the stored one kept */
    const br_ff_in_t nan_in = {NAN, 0.0f, 0.0f};
    assert_int_equal(br_ff_set_ref(&ff, &nan_in), BR_E_INPUT);
    assert_int_equal(est.step(est.ctx, &y, 0.1f, &got), BR_OK);
    assert_true(got == want);
    assert_int_equal(br_ff_est_step(NULL, &y, 0.0f, &got), BR_E_NULL);
}

/* the Maxwell-slip feedforward: guards, and the elements along the reference's
 * path against the clamp written here in double, through a reversal and an inner loop */
static void test_mslip_elements(void **st)
{
    (void)st;
    br_ff_t ff;
    br_ff_cfg_t c = ref_cfg();
    c.mslip.n = 2;
    c.mslip.k_Npm[0] = 2.25e6f; c.mslip.k_Npm[1] = 2.25e5f; /* breakaways 2 and 20 um at 18 N, shares 1/4, 3/4 */
    c.mslip.share[0] = 0.25f; c.mslip.share[1] = 0.75f;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    br_ff_cfg_t b = c;
    b.mslip.share[1] = 0.5f; /* shares not summing to 1 */
    assert_int_equal(br_ff_init(&ff, &b), BR_E_PARAM);
    b = c;
    b.mslip.sigma2_Nspm = 1.0f; /* the viscous term is the feedforward's sigma2 */
    assert_int_equal(br_ff_init(&ff, &b), BR_E_PARAM);
    b = c;
    b.mslip.n = -1;
    assert_int_equal(br_ff_init(&ff, &b), BR_E_PARAM);
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    double z[2] = {0.0, 0.0}, p_prev = 0.0;
    const double k[2] = {2.25e6, 2.25e5}, a[2] = {0.25, 0.75};
    for (int j = 0; j < 400; j++) {
        /* 30 um out, 12 um back (an inner reversal), out again */
        const double p = (j < 150) ? 0.2e-6 * j : (j < 210) ? 30e-6 - 0.2e-6 * (j - 150) : 18e-6 + 0.2e-6 * (j - 210);
        const double v = (j < 150 || j >= 210) ? 2e-5 : -2e-5;
        const br_ff_in_t in = {(float)v, 0.0f, (float)p};
        if (j == 209) { /* after the inner reversal the 20 um element holds a deflection inside its bound */
            assert_true(fabsf(ff.ms_z_m[1]) < 0.5f * 0.75f * c.Fs_N / 2.25e5f && ff.ms_z_m[1] != 0.0f);
        }
        float F = 0.0f, F2 = 0.0f;
        /* evaluated before it is stored: the elements moved by the travel, not stored */
        assert_int_equal(br_ff_step(&ff, &in, &F), BR_OK);
        assert_int_equal(br_ff_set_ref(&ff, &in), BR_OK);
        assert_int_equal(br_ff_est_step(&ff, NULL, 0.0f, &F2), BR_OK);
        assert_true(F == F2);
        const double g = (double)c.Fc_N + ((double)c.Fs_N - c.Fc_N) * exp(-fabs(v) / c.vs_mps);
        double f = 0.0;
        for (int i = 0; i < 2; i++) {
            const double d = a[i] * g / k[i];
            z[i] = fmin(fmax(z[i] + ((double)(float)p - p_prev), -d), d);
            f += k[i] * z[i];
        }
        p_prev = (double)(float)p;
        BR_ASSERT_NEAR(F, f + (double)c.sigma2_Nspm * (float)v, 1e-4 * (double)c.Fs_N);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_map_nominal),
        cmocka_unit_test(test_map_causes_and_inertia),
        cmocka_unit_test(test_clamp_and_inputs),
        cmocka_unit_test(test_est_adapter),
        cmocka_unit_test(test_mslip_elements),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
