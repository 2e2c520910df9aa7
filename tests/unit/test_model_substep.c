/* SPDX-License-Identifier: Apache-2.0 */
/* The estimation model's sub-steps (docs/modules/model.md, "Sub-steps"): the
 * number chosen at init (eqs. S1, S2) against the same formula in double, n = 1
 * on the reference machine at both estimators' periods, the guard on
 * BR_MODEL_SUB_MAX, and on an axis whose presliding mode is faster than the
 * period (omega_n h = 5.1) the sub-stepped step accurate against a fine
 * double-precision integration and bounded over a long run, where one RK4
 * step over the whole period diverges. */
#include "br_test.h"

#include "bristle/br_model.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"

#define PF_H BR_EST_PF_PERIOD_S_F

/* the reference machine's model, sigma0 times s0_k */
static br_model_cfg_t cfg_k(float dt, float s0_k)
{
    br_model_cfg_t c = br_machine_model_cfg(dt);
    c.lugre.sigma0_Npm *= s0_k;
    return c;
}

/* eqs. S1, S2 in double: the presliding mode's spectral radius and n */
static double rho_of(const br_model_cfg_t *c)
{
    const double L2 = (double)c->lead_mprad * c->lead_mprad;
    const double meff = ((double)c->J_kgm2 + L2 * c->M_kg) / L2;
    const double wn = sqrt(c->lugre.sigma0_Npm / meff), b = ((double)c->lugre.sigma1_Nspm + c->sigma2_Nspm) / meff;
    return (b <= 2.0 * wn) ? wn : 0.5 * (b + sqrt(b * b - 4.0 * wn * wn));
}

static int n_of(const br_model_cfg_t *c)
{
    const double n = ceil(rho_of(c) * c->dt_s / BR_MODEL_SUB_RH_MAX);
    return n < 1.0 ? 1 : (int)n;
}

static void test_sub_count(void **st)
{
    (void)st;
    br_model_t m;
    /* the reference at the PF's and the UKF's periods: one step, h = dt exactly */
    const float periods[] = {PF_H, BR_MACHINE_CTRL_PERIOD_S_F};
    for (unsigned i = 0; i < 2; i++) {
        br_model_cfg_t c = cfg_k(periods[i], 1.0f);
        assert_int_equal(br_model_init(&m, &c), BR_OK);
        assert_int_equal(m.n_sub, 1);
        assert_true(m.h_sub_s == c.dt_s);
        BR_ASSERT_NEAR(m.rho_h, rho_of(&c) * c.dt_s, 1e-5);
    }
    /* stiffer bristles (omega_n h 1.1-13.5), and an overdamped mode (sigma1 large:
     * the fast real eigenvalue) */
    const float ks[] = {4.5f, 16.0f, 100.0f, 700.0f};
    for (unsigned i = 0; i < 4; i++) {
        br_model_cfg_t c = cfg_k(PF_H, ks[i]);
        assert_int_equal(br_model_init(&m, &c), BR_OK);
        assert_int_equal(m.n_sub, n_of(&c));
        assert_true(m.n_sub > 1);
        BR_ASSERT_NEAR(m.h_sub_s, c.dt_s / m.n_sub, 1e-7 * c.dt_s);
    }
    br_model_cfg_t c = cfg_k(PF_H, 1.0f);
    c.lugre.sigma1_Nspm = 3.0e5f;
    assert_true(rho_of(&c) > 1.5 * sqrt(c.lugre.sigma0_Npm * c.lead_mprad * c.lead_mprad /
                                        (c.J_kgm2 + c.lead_mprad * c.lead_mprad * c.M_kg)));
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_int_equal(m.n_sub, n_of(&c));
    /* with elements the model keeps one step */
    br_est_cfg_t e = br_circle_pf_cfg_default(PF_H).est;
    br_circle_est_mslip(&e);
    e.model.lugre.sigma0_Npm *= 100.0f; /* omega_n h 5.1 with LuGre */
    assert_int_equal(br_model_init(&m, &e.model), BR_OK);
    assert_int_equal(m.n_sub, 1);
}

/* more than BR_MODEL_SUB_MAX sub-steps: refused, not stepped with fewer */
static void test_sub_guard(void **st)
{
    (void)st;
    br_model_t m;
    br_model_cfg_t c = cfg_k(PF_H, 1.0f);
    const double rho = rho_of(&c);
    c.dt_s = (float)((BR_MODEL_SUB_MAX - 0.5) / rho);
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_int_equal(m.n_sub, BR_MODEL_SUB_MAX);
    c.dt_s = (float)((BR_MODEL_SUB_MAX + 0.5) / rho);
    assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    assert_int_equal(m.ready, 0);
    /* a lead whose square rounds to 0 in float (the sub-step choice divides by it; the
     * host-debug build's sanitizer stops on that division: fuzz_replay found it) and an
     * inertia at the load that rounds to 0: refused */
    c = cfg_k(PF_H, 1.0f);
    c.lead_mprad = 1.0e-23f;
    assert_true(c.lead_mprad * c.lead_mprad == 0.0f);
    assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
    c = cfg_k(PF_H, 1.0f);
    c.lead_mprad = 1.8e19f;
    c.M_kg = 0.0f;
    c.J_kgm2 = 1.0e-23f;
    assert_int_equal(br_model_init(&m, &c), BR_E_PARAM);
}

/* Double-precision RK4 of eq. 6 over dt in n substeps: the accuracy reference */
static void fine_step(const br_model_cfg_t *c, const double p[4], double u, int n, double out[4])
{
    const double L = c->lead_mprad, J = (double)c->J_kgm2 + L * L * c->M_kg;
    const double s0 = c->lugre.sigma0_Npm, s1 = c->lugre.sigma1_Nspm, s2 = c->sigma2_Nspm;
    double x[4] = {p[0], p[1], p[2], p[3]};
    const double h = (double)c->dt_s / n;
    for (int s = 0; s < n; s++) {
        double k[4][4], xs[4];
        for (int st = 0; st < 4; st++) {
            const double a = st == 0 ? 0.0 : (st == 3 ? 1.0 : 0.5);
            for (int i = 0; i < 4; i++) xs[i] = x[i] + (st ? a * h * k[st - 1][i] : 0.0);
            const double v = L * xs[1], zd = v - s0 * fabs(v) * xs[2] / xs[3];
            k[st][0] = xs[1];
            k[st][1] = (u - L * (s2 * L * xs[1] + s0 * xs[2] + s1 * zd)) / J;
            k[st][2] = zd;
            k[st][3] = 0.0;
        }
        for (int i = 0; i < 4; i++) x[i] += h / 6.0 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
    }
    for (int i = 0; i < 4; i++) out[i] = x[i];
}

/* omega_n h = 5.1 (sigma0 x 100 at the PF's period): one step against 2000
 * fine substeps, from presliding states released or pushed */
static void test_sub_accuracy(void **st)
{
    (void)st;
    br_model_t m;
    const br_model_cfg_t c = cfg_k(PF_H, 100.0f);
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    assert_int_equal(m.n_sub, 6);
    const float zs = BR_MACHINE_FS_N_F / c.lugre.sigma0_Npm, L = c.lead_mprad;
    /* {theta, omega, z, g_p, u} */
    const float cases[][5] = {{0.0f, 0.0f, 0.8f * zs, BR_MACHINE_FS_N_F, 0.0f},
                              {0.0f, 0.0f, 0.0f, BR_MACHINE_FS_N_F, 0.5f * L * BR_MACHINE_FC_N_F},
                              {0.3f, 1.0e-3f, -0.5f * zs, 9.0f, -0.3f * L * BR_MACHINE_FC_N_F}};
    for (unsigned i = 0; i < 3; i++) {
        float x[BR_NX] = {cases[i][0], cases[i][1], cases[i][2], cases[i][3]}, xn[BR_NX];
        const double xd[4] = {x[0], x[1], x[2], x[3]};
        double ref[4];
        assert_int_equal(br_model_step(&m, x, cases[i][4], xn), BR_OK);
        fine_step(&c, xd, cases[i][4], 2000, ref);
        /* RK4 at rho h = 0.85 per sub-step: its phase error x^4 / 120 = 0.4 % of
         * the 5.1 rad the mode turns in the step, and its amplitude error
         * x^6 / 144 per sub-step: 2 % of the presliding zone (in z) and of the
         * speed that zone rings with (omega_n zs / L), theta to 2 % of its travel */
        const double wn = sqrt(c.lugre.sigma0_Npm * L * L / (c.J_kgm2 + L * L * c.M_kg));
        BR_ASSERT_NEAR(xn[BR_X_Z], ref[2], 0.02 * zs);
        BR_ASSERT_NEAR(xn[BR_X_OMEGA], ref[1], 0.02 * wn * zs / L);
        BR_ASSERT_NEAR(xn[BR_X_THETA], ref[0], 0.02 * zs / L + 2.4e-7 * fabs(xd[0]));
    }
}

/* the released bristles over 2000 steps: bounded by the presliding zone and
 * ringing down with the sub-steps; one step over the period (the model forced
 * to n = 1: RK4 leaves its limit, the bounded scheme takes over) locks into a
 * cycle that slams z from one edge of the zone to the other every two periods
 * and never rings down (what the fleet's axes showed, docs/fleet.md) */
static void test_sub_bounded(void **st)
{
    (void)st;
    br_model_t m, one;
    const br_model_cfg_t c = cfg_k(PF_H, 100.0f);
    assert_int_equal(br_model_init(&m, &c), BR_OK);
    one = m;
    one.n_sub = 1;
    one.h_sub_s = c.dt_s;
    const float zs = BR_MACHINE_FS_N_F / c.lugre.sigma0_Npm;
    float x[BR_NX] = {0.0f, 0.0f, 0.8f * zs, BR_MACHINE_FS_N_F}, xo[BR_NX] = {0.0f, 0.0f, 0.8f * zs, BR_MACHINE_FS_N_F};
    float zo_max = 0.0f;
    for (int k = 0; k < 2000; k++) {
        float xn[BR_NX];
        assert_int_equal(br_model_step(&m, x, 0.0f, xn), BR_OK);
        for (int j = 0; j < BR_NX; j++) x[j] = xn[j];
        assert_true(fabsf(x[BR_X_Z]) <= 0.8f * zs);
        assert_int_equal(br_model_step(&one, xo, 0.0f, xn), BR_OK);
        for (int j = 0; j < BR_NX; j++) xo[j] = xn[j];
        zo_max = (k >= 1990 && fabsf(xo[BR_X_Z]) > zo_max) ? fabsf(xo[BR_X_Z]) : zo_max;
    }
    /* rung down: the mode's damping (sigma1 + sigma2) and RK4's own */
    assert_true(fabsf(x[BR_X_Z]) < 0.01f * zs);
    assert_true(zo_max > 0.9f * zs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sub_count),    cmocka_unit_test(test_sub_guard),
        cmocka_unit_test(test_sub_accuracy), cmocka_unit_test(test_sub_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
