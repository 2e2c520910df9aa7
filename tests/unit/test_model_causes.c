/* SPDX-License-Identifier: Apache-2.0 */
/* The extended estimation model's guards and the estimators' actuator-delay
 * history (docs/modules/model.md, "Extended model"); the equations themselves
 * are held to the float64 reference by tests/golden/test_golden_model_ext.c,
 * and the extended RK4's stages (each at its own position) to a classic RK4
 * in double written here, at a state where the positions matter. */
#include "br_test.h"

#include "circle/br_circle_est.h"
#include "bristle/br_est.h"
#include "bristle/br_model.h"

#define DT_S 1.0e-3f
#define PI_D 3.14159265358979323846

static void test_causes_guards(void **st)
{
    (void)st;
    br_model_t m;
    const br_model_cfg_t ok = br_machine_model_cfg(DT_S);
    br_model_cfg_t c = ok;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_false(m.extended); /* no cause: the thesis model's kernel */
    c = ok; c.causes.offset_N = NAN;                  assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = ok; c.causes.grad_per_m = INFINITY;           assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = ok; c.causes.drift_per_s = NAN;               assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = ok; c.causes.drift_per_s = 0.01f;             assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_true(m.extended);
    /* the level in -x must stay positive */
    c = ok; c.causes.dFc_neg_N = -ok.lugre.Fc_N;      assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = ok; c.causes.dFc_neg_N = -0.5f * ok.lugre.Fc_N; assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_true(m.extended);
    BR_ASSERT_NEAR(m.c_neg, 0.5, 1e-7);
    /* the viscous friction in -x must not be negative */
    c = ok; c.causes.dsigma2_neg_Nspm = -2.0f * ok.sigma2_Nspm; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    /* a ripple needs a period */
    c = ok; c.causes.ripple_amp_N = 1.0f; c.causes.ripple_period_m = 0.0f;
    assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c.causes.ripple_period_m = 2e-3f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    /* a delay alone is the estimators' business: the model stays the thesis model */
    c = ok; c.causes.delay_s = 3e-3f;  assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_false(m.extended);
    c = ok; c.causes.delay_s = -1e-3f; assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
}

/* An offset on a particle at rest: the model decelerates it by L offset / Jeff,
 * and the force to compensate is the offset (with no friction at rest). */
static void test_offset_at_rest(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.offset_N = 0.5f * c.lugre.Fc_N;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float x[BR_NX] = {0.0f, 0.0f, 0.0f, c.lugre.Fs_N};
    float dx[BR_NX];
    br_model_deriv(&m, x, 0.0f, dx);
    const double Jeff = c.J_kgm2 + (double)c.lead_mprad * c.lead_mprad * c.M_kg;
    BR_ASSERT_NEAR(dx[BR_X_OMEGA], -c.lead_mprad * c.causes.offset_N / Jeff, 1e-5 * c.lead_mprad * c.causes.offset_N / Jeff);
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, x, 0.0f), c.causes.offset_N, 1e-6);
}

/* Sliding in -x with an asymmetry: the steady friction is the level c Fc and
 * the viscous term sigma2 + dsigma2 (the force to compensate leaves out the
 * nominal sigma2 v). */
static void test_asymmetry_in_minus_x(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.dFc_neg_N = 0.3f * c.lugre.Fc_N;
    c.causes.dsigma2_neg_Nspm = 0.5f * c.sigma2_Nspm;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float v = -0.01f, w = v / c.lead_mprad, g = c.lugre.Fc_N; /* sliding, g_p = Fc */
    const float cn = (c.lugre.Fc_N + c.causes.dFc_neg_N) / c.lugre.Fc_N;
    const float x[BR_NX] = {0.0f, w, -cn * g / c.lugre.sigma0_Npm, g}; /* steady deflection */
    BR_ASSERT_NEAR(br_model_fnl_N(&m, x), -cn * g, 1e-4 * g);
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, x, 0.0f), -cn * g + c.causes.dsigma2_neg_Nspm * v, 1e-4 * g);
    /* the same sliding in +x sees the nominal level */
    const float xp[BR_NX] = {0.0f, -w, g / c.lugre.sigma0_Npm, g};
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, xp, 0.0f), g, 1e-4 * g);
}

/* The ripple and the gradient follow the load position p0 + L theta. */
static void test_ripple_and_gradient_follow_position(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.ripple_amp_N = 0.1f * c.lugre.Fc_N;
    c.causes.ripple_period_m = 2.0e-3f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float x[BR_NX] = {0.0f, 0.0f, 0.0f, c.lugre.Fs_N};
    /* a quarter period on: the ripple at its crest */
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, x, 0.25f * c.causes.ripple_period_m), c.causes.ripple_amp_N, 1e-5);
    /* the same point as theta relative to an origin 5 % of a period back: the
     * kernel's expansion about the origin is within its bound A d^4 / 24 */
    const float xr[BR_NX] = {0.05f * c.causes.ripple_period_m / c.lead_mprad, 0.0f, 0.0f, c.lugre.Fs_N};
    const double d = 2.0 * 3.14159265358979 * 0.05;
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, xr, 0.20f * c.causes.ripple_period_m), c.causes.ripple_amp_N,
                   c.causes.ripple_amp_N * (d * d * d * d / 24.0 + 1e-5));
    c = br_machine_model_cfg(DT_S);
    c.causes.grad_per_m = 2.0f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float g = c.lugre.Fc_N;
    const float xs[BR_NX] = {0.0f, 0.01f / c.lead_mprad, g / c.lugre.sigma0_Npm, g};
    /* friction (LuGre and viscous) scaled by 1 + grad p at p = 0.1 m */
    const double F0 = br_model_fcomp_N(&m, xs, 0.0f);
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, xs, 0.1f), 1.2 * F0 + 0.2 * c.sigma2_Nspm * 0.01, 1e-4 * F0);
}

/* friction_drift: the model's clock scales the friction (LuGre and viscous)
 * by s = max(0, 1 + r t), t = n dt; the clock starts at 0 on init, ticks by
 * one step, saturates, and stays 1 without a drift. */
static void test_drift_follows_the_clock(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.drift_per_s = 0.02f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float g = c.lugre.Fc_N;
    const float xs[BR_NX] = {0.0f, 0.01f / c.lead_mprad, g / c.lugre.sigma0_Npm, g};
    const double F0 = br_model_fcomp_N(&m, xs, 0.0f);
    assert_true(m.n_steps == 0u && m.drift_k == 1.0f);
    br_model_set_clock(&m, 10000u); /* t = 10 s: s = 1.2 */
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, xs, 0.0f), 1.2 * F0 + 0.2 * c.sigma2_Nspm * 0.01, 1e-4 * F0);
    br_model_tick(&m);
    assert_true(m.n_steps == 10001u);
    BR_ASSERT_NEAR(m.drift_k, 1.0 + 0.02 * 10.001, 1e-6);
    br_model_set_clock(&m, UINT32_MAX);
    br_model_tick(&m);
    assert_true(m.n_steps == UINT32_MAX && isfinite(m.drift_k));
    /* a falling level stops at 0: no friction, the torque alone accelerates */
    c.causes.drift_per_s = -1.0f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    br_model_set_clock(&m, 2000u);
    assert_true(m.drift_k == 0.0f);
    BR_ASSERT_NEAR(br_model_fcomp_N(&m, xs, 0.0f), -c.sigma2_Nspm * 0.01, 1e-6);
    /* without a drift the clock leaves the scale at 1 */
    c = br_machine_model_cfg(DT_S);
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    br_model_set_clock(&m, 123456u);
    assert_true(m.drift_k == 1.0f);
}

/* br_model_step on an absolute theta equals br_model_step_at about the
 * state's own position, for the extended model. */
static void test_step_absolute_equals_relative(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.ripple_amp_N = 0.1f * c.lugre.Fc_N;
    c.causes.ripple_period_m = 2.0e-3f;
    c.causes.offset_N = 1.0f;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    const float th = 0.7f / c.lead_mprad * 1e-3f; /* 0.7 mm */
    float x[BR_NX] = {th, 0.02f, 0.0f, c.lugre.Fs_N}, a[BR_NX], b[BR_NX];
    const float xr[BR_NX] = {0.0f, x[1], x[2], x[3]};
    assert_int_equal(br_model_step(&m, x, 0.01f, a), BR_OK);
    assert_int_equal(br_model_step_at(&m, xr, c.lead_mprad * th, 0.01f, b), BR_OK);
    assert_true(a[BR_X_OMEGA] == b[BR_X_OMEGA] && a[BR_X_Z] == b[BR_X_Z]);
    assert_true(a[BR_X_THETA] == th + b[BR_X_THETA]);
    /* in place */
    assert_int_equal(br_model_step(&m, x, 0.01f, x), BR_OK);
    assert_memory_equal(x, a, sizeof a);
}

/* The torque that reached the axis, from the commands: a delay of 2.25
 * periods gives 0.75 u[k-3] + 0.25 u[k-4]; none gives the command itself. */
static void test_delay_history(void **st)
{
    (void)st;
    br_est_cfg_t c = br_circle_ukf_cfg_tuned(DT_S).est;
    br_est_delay_t d;
    br_est_delay_init(&d, &c);
    assert_true(br_est_delay_apply(&d, 0.125f) == 0.125f); /* no delay: the command itself */
    c.model.causes.delay_s = 2.25f * DT_S;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    br_est_delay_init(&d, &c);
    const float u[] = {1.0f, 2.0f, 4.0f, 8.0f, 16.0f, 32.0f};
    for (int k = 0; k < 6; k++) {
        const float ua = br_est_delay_apply(&d, u[k]);
        const double expect = 0.75 * (k >= 2 ? u[k - 2] : 0.0) + 0.25 * (k >= 3 ? u[k - 3] : 0.0);
        BR_ASSERT_NEAR(ua, expect, 1e-5 * (fabs(expect) + 1.0));
    }
    /* the history's length bounds the delay */
    c.model.causes.delay_s = (float)(BR_EST_DELAY_HIST - 2u) * DT_S;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c.model.causes.delay_s = (float)(BR_EST_DELAY_HIST - 1u) * DT_S;
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
}

/* ---- The extended model's RK4 step against classic RK4 in float64 ----
 * The right-hand side of docs/modules/model.md, "Extended model", in double,
 * written here from the equations (not from the kernel): p = p0 + L theta,
 * v = L omega, z' = v - sigma0 |v| z / g (g = c g_p for v < 0),
 * F = k(p) (sigma2_d v + sigma0 z + sigma1 z') + offset + A sin(2 pi p / P + phi),
 * omega' = (u - L F) / Jeff; the drift is left out (s = 1 at the clock's 0). */
typedef struct {
    double L, Jeff, s0, s1, s2, s2n, cn, off, grad, A, P, phi, p0, u;
} ref_rhs_t;

/* dx = f(x); returns the absolute sum of F's terms (its rounding scale) */
static double ref_deriv(const ref_rhs_t *r, const double x[3], double gp, double dx[3], double *th_max)
{
    *th_max = fmax(*th_max, fabs(x[0]));
    const double v = r->L * x[1];
    const double g = (v < 0.0) ? r->cn * gp : gp;
    const double zd = v - r->s0 * fabs(v) * x[2] / g;
    const double k = fmax(0.0, 1.0 + r->grad * (r->p0 + r->L * x[0]));
    const double rip = r->A * sin(2.0 * PI_D * (r->p0 + r->L * x[0]) / r->P + r->phi);
    const double s2d = (v < 0.0) ? r->s2n : r->s2;
    const double F = k * (s2d * v + r->s0 * x[2] + r->s1 * zd) + r->off + rip;
    dx[0] = x[1];
    dx[1] = (r->u - r->L * F) / r->Jeff;
    dx[2] = zd;
    return k * (fabs(s2d * v) + fabs(r->s0 * x[2]) + fabs(r->s1 * zd)) + fabs(r->off) + fabs(r->A);
}

/* one classic RK4 step of h: stages at x, x + h/2 k1, x + h/2 k2, x + h k3;
 * with stage4_theta_w2 the 4th stage's position is t0 + h w2 instead of
 * t0 + h w3 (the mutant the test is there to see). Returns the largest force
 * scale over the stages, and in *th_max the largest |theta| of a stage. */
static double ref_rk4(const ref_rhs_t *r, const double x[3], double gp, double h, int stage4_theta_w2,
                      double out[3], double *th_max)
{
    double k1[3], k2[3], k3[3], k4[3], xs[3];
    *th_max = 0.0;
    double fs = ref_deriv(r, x, gp, k1, th_max);
    for (int i = 0; i < 3; i++) {
        xs[i] = x[i] + 0.5 * h * k1[i];
    }
    fs = fmax(fs, ref_deriv(r, xs, gp, k2, th_max));
    for (int i = 0; i < 3; i++) {
        xs[i] = x[i] + 0.5 * h * k2[i];
    }
    fs = fmax(fs, ref_deriv(r, xs, gp, k3, th_max));
    for (int i = 0; i < 3; i++) {
        xs[i] = x[i] + h * k3[i];
    }
    if (stage4_theta_w2) {
        xs[0] = x[0] + h * (x[1] + 0.5 * h * k1[1]); /* t0 + h w2 */
    }
    fs = fmax(fs, ref_deriv(r, xs, gp, k4, th_max));
    for (int i = 0; i < 3; i++) {
        out[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    return fs;
}

/* br_model_step_at's RK4 (the extended kernel br_model_kx_rk4) is classic
 * RK4 of the extended right-hand side, each stage at its own position. The
 * state makes the positions matter: a short ripple of large amplitude
 * (period 200 um, A = 2 Fc, at its steepest at the origin: phase 0, p0 = 0)
 * and a gradient; the bristle deflected in +x to twice the level g_p / sigma0
 * while the axis moves in -x at 0.5 rad/s, so that omega' changes by some
 * 130 rad/s^2 between stages 1 and 2. The 4th stage's position t0 + h w3
 * then differs from t0 + h w2 by h^2/2 |wd2 - wd1| (6e-5 rad), which moves
 * the ripple force at that stage by 2 pi L A / P times that (0.035 N), and the
 * step's omega by 1.3e-4 rad/s: some 25 times the float32 tolerance (the test
 * holds a margin of ten itself, below). */
static void test_ext_rk4_is_classic_rk4(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = br_machine_model_cfg(DT_S);
    c.causes.ripple_amp_N = 2.0f * c.lugre.Fc_N;
    c.causes.ripple_period_m = 200e-6f;
    c.causes.grad_per_m = 5.0f;
    c.causes.offset_N = 0.2f * c.lugre.Fc_N;
    c.causes.dFc_neg_N = 0.3f * c.lugre.Fc_N;
    c.causes.dsigma2_neg_Nspm = 0.5f * c.sigma2_Nspm;
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_true(m.extended && m.drift_k == 1.0f);
    const float gp = c.lugre.Fs_N, p0 = 0.0f, u = 0.0f;
    const float x[BR_NX] = {0.0f, -0.5f, 2.0f * gp / c.lugre.sigma0_Npm, gp};
    float xn[BR_NX];
    const ref_rhs_t r = {c.lead_mprad, (double)c.J_kgm2 + (double)c.lead_mprad * c.lead_mprad * c.M_kg,
                         c.lugre.sigma0_Npm, c.lugre.sigma1_Nspm, c.sigma2_Nspm,
                         (double)c.sigma2_Nspm + c.causes.dsigma2_neg_Nspm,
                         ((double)c.lugre.Fc_N + c.causes.dFc_neg_N) / c.lugre.Fc_N,
                         c.causes.offset_N, c.causes.grad_per_m, c.causes.ripple_amp_N,
                         c.causes.ripple_period_m, c.causes.ripple_phase_rad, p0, u};
    const double h = c.dt_s, xd[3] = {x[0], x[1], x[2]};
    double ref[3], mut[3], th_max, th_max_mut;
    const double fs = ref_rk4(&r, xd, gp, h, 0, ref, &th_max);
    (void)ref_rk4(&r, xd, gp, h, 1, mut, &th_max_mut);
    /* the kernel's RK4, not the bounded scheme: a h = sigma0 L h |omega| / g
     * within half the limit at both ends, with the smaller level
     * (min(c, 1) g_p = g_p here), so float32 rounding cannot tip the test */
    const double ah = r.s0 * r.L * h / gp;
    assert_true(ah * fabs(xd[1]) <= 0.5 * BR_MODEL_RK4_AH_MAX && ah * fabs(ref[1]) <= 0.5 * BR_MODEL_RK4_AH_MAX);
    assert_int_equal(br_model_step_at(&m, x, p0, u, xn), BR_OK);
    /* Tolerances: float32 rounding of the stages, docs/golden.md's one-step
     * chains (32u of each signal's scale: some dozens of float32 operations,
     * each within u of its operands; the stage errors propagate with a gain
     * h L^2 sigma1 (1 + sigma0 |z| / g) / Jeff < 0.2 per stage here), with
     * the force scale the largest absolute sum of F's terms over the stages;
     * omega also gets the kernel's cubic expansion of the ripple about the
     * origin (the reference's sine is exact), 2 (h/Jeff) L A d^4 / 24 with
     * d = 2 pi L |theta| / P of the farthest stage. */
    const double u32 = 5.9604644775390625e-08;
    const double S_th = fabs(ref[0]) + h * (fabs(xd[1]) + fabs(ref[1]));
    const double S_w = fabs(xd[1]) + fabs(ref[1]) + h / r.Jeff * (fabs((double)u) + r.L * fs);
    const double S_z = fmax(fmax(fabs(xd[2]), fabs(ref[2])), gp / r.s0);
    const double d = 2.0 * PI_D * r.L * th_max / r.P;
    const double tol_w = 32.0 * u32 * S_w + 2.0 * h / r.Jeff * r.L * r.A * d * d * d * d / 24.0;
    /* the state is one where the 4th stage's position matters: at t0 + h w2,
     * the step's omega moves by more than ten tolerances */
    print_message("ext rk4: omega %.9g, with stage 4 at t0 + h w2 %.9g, tolerance %.3g\n", ref[1], mut[1], tol_w);
    assert_true(fabs(mut[1] - ref[1]) > 10.0 * tol_w);
    BR_ASSERT_NEAR(xn[BR_X_THETA], ref[0], 32.0 * u32 * S_th);
    BR_ASSERT_NEAR(xn[BR_X_OMEGA], ref[1], tol_w);
    BR_ASSERT_NEAR(xn[BR_X_Z], ref[2], 64.0 * u32 * S_z);
    assert_true(xn[BR_X_GP] == gp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_causes_guards),
        cmocka_unit_test(test_offset_at_rest),
        cmocka_unit_test(test_asymmetry_in_minus_x),
        cmocka_unit_test(test_ripple_and_gradient_follow_position),
        cmocka_unit_test(test_drift_follows_the_clock),
        cmocka_unit_test(test_step_absolute_equals_relative),
        cmocka_unit_test(test_delay_history),
        cmocka_unit_test(test_ext_rk4_is_classic_rk4),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
