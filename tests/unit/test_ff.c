/* SPDX-License-Identifier: Apache-2.0 */
/* Friction feedforward (firmware/ff): configuration guards, the map of
 * br_ff.h against the same equation in double, the clamp, input guards and
 * the br_est_t adapter. */
#include "br_test.h"

#include <math.h>

#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_ff.h"
#include "bristle/br_ff_pred.h"

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


/* the hardware-like plant's element set (breakaways 2, 5, 10, 20 um at Fs, equal shares) */
static br_ff_cfg_t pred_cfg(float tau)
{
    br_ff_cfg_t c = ref_cfg();
    const double d[4] = {2e-6, 5e-6, 10e-6, 20e-6};
    c.mslip.n = 4;
    for (int i = 0; i < 4; i++) {
        c.mslip.k_Npm[i] = (float)(0.25 * c.Fs_N / d[i]);
        c.mslip.share[i] = 0.25f;
    }
    c.pred_ahead_s = tau;
    return c;
}

/* the horizon's guards at init and br_ff_pred_N's */
static void test_pred_guards(void **st)
{
    (void)st;
    br_ff_t ff;
    br_ff_cfg_t c = pred_cfg(1e-3f);
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    c = pred_cfg(0.0f);                 assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    c = pred_cfg(BR_FF_PRED_MAX_S);     assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    c = pred_cfg(-1e-3f);               assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = pred_cfg(NAN);                  assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = pred_cfg(INFINITY);             assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = pred_cfg(BR_FF_PRED_MAX_S * 1.01f); assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    c = ref_cfg(); c.pred_ahead_s = 1e-3f; /* a horizon without elements */
    assert_int_equal(br_ff_init(&ff, &c), BR_E_PARAM);
    float dF = 1.0f;
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, &dF), BR_E_STATE); /* the refused init */
    assert_true(dF == 0.0f);
    c = pred_cfg(1e-3f);
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    assert_int_equal(br_ff_pred_N(NULL, NULL, NULL, &dF), BR_E_NULL);
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, NULL), BR_E_NULL);
    const float z_nan[4] = {0.0f, NAN, 0.0f, 0.0f}, z_big[4] = {3e38f, 3e38f, 0.0f, 0.0f}, z0[4] = {0};
    dF = 1.0f;
    assert_int_equal(br_ff_pred_N(&ff, z_nan, NULL, &dF), BR_E_INPUT);
    assert_true(dF == 0.0f);
    const float g0 = 0.0f, ginf = INFINITY, g1 = 10.0f;
    assert_int_equal(br_ff_pred_N(&ff, z0, &g0, &dF), BR_E_INPUT);
    assert_int_equal(br_ff_pred_N(&ff, z0, &ginf, &dF), BR_E_INPUT);
    assert_int_equal(br_ff_pred_N(&ff, z0, &g1, &dF), BR_OK);
    dF = 1.0f;
    assert_int_equal(br_ff_pred_N(&ff, z_big, NULL, &dF), BR_E_NUMERIC); /* sum k z overflows */
    assert_true(dF == 0.0f);
    /* no horizon: no change, and the feedforward's output as without it */
    c = pred_cfg(0.0f);
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    const br_ff_in_t in = {5e-5f, 1e-3f, 3e-6f};
    assert_int_equal(br_ff_set_ref(&ff, &in), BR_OK);
    dF = 1.0f;
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, &dF), BR_OK);
    assert_true(dF == 0.0f);
}

/* The prediction at a reversal: the reference at rest, accelerating into +x,
 * every element at its -x bound at the sliding level g(-2e-5 m/s). Over tau
 * the travel a tau^2 / 2 moves each element off its bound, clamped at the
 * level at the horizon's end g(a tau): the clamp written here in double.
 * br_ff_est_step with the horizon is the map plus that change; without the
 * term it would be the map alone. */
static void test_pred_at_reversal(void **st)
{
    (void)st;
    const float tau = 2e-3f;
    br_ff_cfg_t c = pred_cfg(tau);
    br_ff_t ff, ff0;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    br_ff_cfg_t c0 = c;
    c0.pred_ahead_s = 0.0f;
    assert_int_equal(br_ff_init(&ff0, &c0), BR_OK);
    /* slide 60 um in -x (every element to its -x bound), then stop with a = +0.5 m/s^2 */
    const double vs = -2e-5;
    for (int j = 1; j <= 60; j++) {
        const br_ff_in_t in = {(float)vs, 0.0f, -1e-6f * (float)j};
        assert_int_equal(br_ff_set_ref(&ff, &in), BR_OK);
        assert_int_equal(br_ff_set_ref(&ff0, &in), BR_OK);
    }
    const float a = 0.5f;
    const br_ff_in_t rev = {0.0f, a, -60e-6f};
    assert_int_equal(br_ff_set_ref(&ff, &rev), BR_OK);
    assert_int_equal(br_ff_set_ref(&ff0, &rev), BR_OK);
    const double dp = 0.5 * (double)a * (double)tau * (double)tau; /* 1 um */
    const double g0 = c.Fc_N + ((double)c.Fs_N - c.Fc_N) * exp(vs / c.vs_mps);
    const double g1 = c.Fc_N + ((double)c.Fs_N - c.Fc_N) * exp(-(double)a * tau / c.vs_mps);
    double want = 0.0;
    for (int i = 0; i < 4; i++) {
        const double ci = 0.25 / c.mslip.k_Npm[i], z = -ci * g0;
        want += c.mslip.k_Npm[i] * (fmin(fmax(z + dp, -ci * g1), ci * g1) - z);
    }
    float dF = 0.0f, F = 0.0f, F0 = 0.0f;
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, &dF), BR_OK);
    BR_ASSERT_NEAR(dF, want, 1e-4 * c.Fs_N);
    assert_true(dF > 1.0f);
    assert_int_equal(br_ff_est_step(&ff, NULL, 0.0f, &F), BR_OK);
    assert_int_equal(br_ff_est_step(&ff0, NULL, 0.0f, &F0), BR_OK);
    BR_ASSERT_NEAR(F - F0, want, 1e-4 * c.Fs_N);
    /* sliding on in +x at the bound: only the level changes (g(v + a tau) against g(v)) */
    const br_ff_in_t slide = {1e-4f, 0.0f, 0.0f};
    for (int j = 0; j < 3; j++) assert_int_equal(br_ff_set_ref(&ff, &slide), BR_OK); /* 60 um: at +bounds */
    const br_ff_in_t slide2 = {1e-4f, 0.0f, 100e-6f};
    assert_int_equal(br_ff_set_ref(&ff, &slide2), BR_OK);
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, &dF), BR_OK);
    assert_true(fabsf(dF) < 1e-5f * c.Fs_N); /* the same level: the bounds do not move */
}

/* a stand-in estimator: F_hat = 2 N with the status it is told */
typedef struct {
    br_status_t st;
    int resets, predicts;
} fake_est_t;
static br_status_t fake_step(void *ctx, const br_meas_t *y, float u, float *F)
{
    (void)y;
    (void)u;
    *F = 2.0f;
    return ((fake_est_t *)ctx)->st;
}
static br_status_t fake_predict(void *ctx, float u, float *F)
{
    (void)u;
    ((fake_est_t *)ctx)->predicts++;
    *F = 2.0f;
    return ((fake_est_t *)ctx)->st;
}
static br_status_t fake_reset(void *ctx)
{
    ((fake_est_t *)ctx)->resets++;
    return BR_OK;
}

/* br_ff_pred: the estimate plus dF when the estimator gave one, its status kept */
static void test_pred_adapter(void **st)
{
    (void)st;
    br_ff_cfg_t c = pred_cfg(1e-3f);
    br_ff_t ff;
    assert_int_equal(br_ff_init(&ff, &c), BR_OK);
    const br_ff_in_t in = {0.0f, 1.0f, 0.0f}; /* a start into +x: dF = k0 a tau^2 / 2 > 0 */
    assert_int_equal(br_ff_set_ref(&ff, &in), BR_OK);
    float dF = 0.0f;
    assert_int_equal(br_ff_pred_N(&ff, NULL, NULL, &dF), BR_OK);
    assert_true(dF > 0.5f);
    fake_est_t fe = {BR_OK, 0, 0};
    const br_est_t inner = {&fe, fake_step, fake_predict, fake_reset};
    br_ff_pred_t p;
    assert_int_equal(br_ff_pred_init(NULL, inner, &ff, NULL, NULL), BR_E_NULL);
    assert_int_equal(br_ff_pred_init(&p, inner, NULL, NULL, NULL), BR_E_NULL);
    const br_est_t no_step = {&fe, NULL, NULL, NULL};
    assert_int_equal(br_ff_pred_init(&p, no_step, &ff, NULL, NULL), BR_E_NULL);
    br_ff_t ff0;
    br_ff_cfg_t c0 = c;
    c0.pred_ahead_s = 0.0f;
    assert_int_equal(br_ff_init(&ff0, &c0), BR_OK);
    assert_int_equal(br_ff_pred_init(&p, inner, &ff0, NULL, NULL), BR_E_PARAM); /* no horizon */
    const br_est_t e0 = br_ff_pred_est(&p);
    float F = 0.0f;
    assert_int_equal(e0.step(e0.ctx, NULL, 0.0f, &F), BR_E_STATE); /* the refused init */
    assert_int_equal(br_ff_pred_init(&p, inner, &ff, NULL, NULL), BR_OK);
    const br_est_t e = br_ff_pred_est(&p);
    const br_meas_t y = {0, 0.0f};
    assert_int_equal(br_est_period(&e, &y, 0.0f, &F), BR_OK);
    assert_true(F == 2.0f + dF);
    fe.st = BR_W_OUTLIER; /* an outlier step still gives an estimate */
    assert_int_equal(br_est_period(&e, &y, 0.0f, &F), BR_W_OUTLIER);
    assert_true(F == 2.0f + dF);
    fe.st = BR_E_NUMERIC; /* an error passes through without the term */
    assert_int_equal(br_est_period(&e, &y, 0.0f, &F), BR_E_NUMERIC);
    assert_true(F == 2.0f);
    fe.st = BR_OK;
    assert_int_equal(br_est_period(&e, NULL, 0.0f, &F), BR_OK); /* predict-only */
    assert_int_equal(fe.predicts, 1);
    assert_true(F == 2.0f + dF);
    assert_int_equal(br_est_restart(&e), BR_OK);
    assert_int_equal(fe.resets, 1);
    /* without the inner's predict: F held */
    const br_est_t inner2 = {&fe, fake_step, NULL, NULL};
    assert_int_equal(br_ff_pred_init(&p, inner2, &ff, NULL, NULL), BR_OK);
    F = 7.0f;
    assert_int_equal(br_est_period(&e, NULL, 0.0f, &F), BR_OK);
    assert_true(F == 7.0f);
    assert_int_equal(br_est_restart(&e), BR_OK);
    assert_int_equal(fe.resets, 1);
    /* an anchor: the elements and level it names, not the feedforward's */
    const float z[4] = {2e-6f, 0.0f, 0.0f, 0.0f}, g = 18.0f; /* the first element at its bound */
    assert_int_equal(br_ff_pred_init(&p, inner, &ff, z, &g), BR_OK);
    float dFa = 0.0f;
    assert_int_equal(br_ff_pred_N(&ff, z, &g, &dFa), BR_OK);
    assert_int_equal(br_est_period(&e, &y, 0.0f, &F), BR_OK);
    assert_true(F == 2.0f + dFa);
    assert_true(dFa < dF); /* the first element clamped: less than the feedforward's (undeflected) */
    const float z_nan[4] = {NAN, 0.0f, 0.0f, 0.0f};
    assert_int_equal(br_ff_pred_init(&p, inner, &ff, z_nan, NULL), BR_OK);
    assert_int_equal(br_est_period(&e, &y, 0.0f, &F), BR_E_INPUT); /* the axis stops */
    assert_int_equal(e.step(NULL, &y, 0.0f, &F), BR_E_NULL);
    assert_int_equal(e.predict(NULL, 0.0f, &F), BR_E_NULL);
    assert_int_equal(e.reset(NULL), BR_E_NULL);
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
        cmocka_unit_test(test_pred_guards),
        cmocka_unit_test(test_pred_at_reversal),
        cmocka_unit_test(test_pred_adapter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
