/* SPDX-License-Identifier: Apache-2.0 */
/* Compensating ahead (br_est_comp_N, docs/modules/est.md): the lead is
 * checked at init; a lead of 0 is the filtered estimate itself, bit for bit;
 * a lead carries the estimate by the model with the torque that reaches the
 * axis in each period (the delayed commands from the history, the newest
 * standing in for those not yet computed), interpolated in the last period;
 * a carry that fails gives the filtered estimate, never a NaN. The expected
 * values here step br_model themselves with the commands the test sent. */
#include "br_test.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_est.h"
#include "bristle/br_model.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"

#define UKF_DT_S 1.0e-3f
#define PF_DT_S 1.5e-3f
#define N_STEPS 60

/* a moving axis, 2 mm from the encoder's zero (where the extended model's
 * position terms differ from theirs at 0): 20 counts a period, and commands
 * that alternate in sign so that a wrong command in the carry changes the force */
#define COUNTS_0 260000
static int32_t counts_at(int k) { return COUNTS_0 + 20 * k; }
static float cmd_at(int k) { return ((k % 2) != 0 ? 0.3f : -0.2f) + 0.001f * (float)k; }

/* position terms of the extended model: a ripple and a friction gradient */
static void with_position_causes(br_model_cfg_t *mc)
{
    mc->causes.ripple_amp_N = 1.0f;
    mc->causes.ripple_period_m = 4.0e-3f;
    mc->causes.ripple_phase_rad = 0.5f;
    mc->causes.grad_per_m = 4.0f;
}

static void test_ahead_bounds(void **st)
{
    (void)st;
    const br_est_cfg_t ok = br_circle_ukf_cfg_tuned(UKF_DT_S).est;
    br_est_cfg_t c = ok;
    c.comp_ahead_periods = 0.0f;                     assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c.comp_ahead_periods = BR_EST_AHEAD_MAX_PERIODS; assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c.comp_ahead_periods = nextafterf(BR_EST_AHEAD_MAX_PERIODS, INFINITY);
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.comp_ahead_periods = -1.0e-6f;                 assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.comp_ahead_periods = NAN;                      assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.comp_ahead_periods = INFINITY;                 assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    /* both filters refuse it at init */
    br_ukf_t u;
    br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    cu.est.comp_ahead_periods = NAN;
    assert_int_equal(br_ukf_init(&u, &cu), BR_E_PARAM);
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t cp = br_circle_pf_cfg_tuned(PF_DT_S);
    cp.est.comp_ahead_periods = -0.5f;
    assert_int_equal(br_pf_init(pf, &cp), BR_E_PARAM);
    free(pf);
}

/* a PF of 200 particles with the lead given, on the extended model with
 * position terms when extended (the caller frees it) */
static br_pf_t *pf_with_lead(float lead, int extended, br_pf_cfg_t *cp)
{
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    *cp = br_circle_pf_cfg_tuned(PF_DT_S);
    cp->n_particles = 200u;
    cp->est.delay_id.n_cand = 0u; /* the test's made-up motion is no axis: no delay to identify */
    cp->est.comp_ahead_periods = lead;
    if (extended) {
        with_position_causes(&cp->est.model);
        cp->load = (br_pf_load_t){0.0f, 0.0f}; /* the shared external force needs the thesis model */
    }
    assert_int_equal(br_pf_init(pf, cp), BR_OK);
    return pf;
}

/* lead 0: what the step returns is the filtered F_hat, bit for bit */
static void test_no_lead_is_the_estimate(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    cu.est.comp_ahead_periods = 0.0f;
    cu.est.delay_id.n_cand = 0u; /* as the PF's */
    assert_int_equal(br_ukf_init(&u, &cu), BR_OK);
    br_pf_cfg_t cp;
    br_pf_t *pf = pf_with_lead(0.0f, 0, &cp);
    for (int k = 0; k < N_STEPS; k++) {
        const br_meas_t y = {counts_at(k), 0.5f};
        float Fu = NAN, Fp = NAN;
        assert_false(BR_FAILED(br_ukf_est_step(&u, &y, cmd_at(k), &Fu)));
        assert_false(BR_FAILED(br_pf_est_step(pf, &y, cmd_at(k), &Fp)));
        assert_memory_equal(&Fu, &br_ukf_estimate(&u)->F_hat_N, sizeof Fu);
        assert_memory_equal(&Fp, &br_pf_estimate(pf)->F_hat_N, sizeof Fp);
    }
    free(pf);
}

/* the torque reaching the axis over the j-th period after step k, with the
 * delay dm + df periods: sent[i] was held over the period that ended at step
 * i, so the command of the period starting at step k + j is sent[k + 1 + j]
 * (sent[k] is the newest; those not yet computed take its value) */
static float reaching(const float *sent, int k, int j, uint32_t dm, float df)
{
    const int a = k + 1 + j - (int)dm; /* sent[a] and sent[a - 1] */
    const float ua = (a > k) ? sent[k] : ((a >= 0) ? sent[a] : 0.0f);
    const float ub = (a - 1 > k) ? sent[k] : ((a - 1 >= 0) ? sent[a - 1] : 0.0f);
    return (1.0f - df) * ua + df * ub;
}

/* the UKF with a delay of delay_periods and a lead (on the extended model
 * with position terms when extended): the compensation is F_hat plus the
 * change of f_c over delay + lead periods of the model, driven by the
 * commands that reach the axis in them */
static void run_carry_case(float delay_periods, float lead, int extended)
{
    br_ukf_t u;
    br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    cu.est.model.causes.delay_s = delay_periods * UKF_DT_S;
    cu.est.delay_id.n_cand = 0u; /* the delay is the test's, not identified */
    if (cu.load.max_N == 0.0f) {
        /* the external-force state on whatever the machine file says (its carry is under test) */
        const float F_act = 10.0f * cu.est.gp_max_N;
        cu.load = (br_ukf_load_t){1.0e3f * UKF_DT_S, F_act * F_act, F_act};
    }
    if (extended) {
        with_position_causes(&cu.est.model);
    }
    cu.est.comp_ahead_periods = lead;
    assert_int_equal(br_ukf_init(&u, &cu), BR_OK);
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cu.est.model), BR_OK);
    /* the delay's own history, fed the same commands: the anchor of reaching() */
    br_est_delay_t dd;
    br_est_delay_init(&dd, &cu.est);
    float sent[N_STEPS];
    float worst = 0.0f, moved = 0.0f, fd_max = 0.0f;
    for (int k = 0; k < N_STEPS; k++) {
        const br_meas_t y = {counts_at(k), 0.5f};
        sent[k] = cmd_at(k);
        float F = NAN;
        assert_false(BR_FAILED(br_ukf_est_step(&u, &y, sent[k], &F)));
        const float F_hat = br_ukf_estimate(&u)->F_hat_N;
        const float p0 = (float)u.origin_counts * u.m_per_count;
        const uint32_t dm = u.delay.on ? u.delay.m : 0u;
        const float df = u.delay.on ? u.delay.f : 0.0f;
        /* reaching() for the period that ended at step k is what the estimator's
         * delay took (br_est_delay_apply); with a delay of a period or more,
         * where no stand-in enters it */
        const float ua = br_est_delay_apply(&dd, sent[k]);
        if (k >= 1 && dm >= 1u) {
            BR_ASSERT_NEAR(ua, reaching(sent, k - 1, 0, dm, df), 1e-7);
        }
        const float h = (float)dm + df + lead;
        const int n = (int)floorf(h);
        float cur[BR_NX], nxt[BR_NX];
        memcpy(cur, u.x, sizeof cur);
        const float f0 = br_model_fcomp_N(&m, u.x, p0);
        /* the external force F_d the UKF carries, held over the carry (0 with the state off) */
        const float u_ext = cu.est.model.lead_mprad * br_ukf_estimate(&u)->load_N;
        fd_max = fmaxf(fd_max, fabsf(br_ukf_estimate(&u)->load_N));
        for (int j = 0; j < n; j++) {
            assert_int_equal(br_model_step_at(&m, cur, p0, reaching(sent, k, j, dm, df) - u_ext, nxt), BR_OK);
            memcpy(cur, nxt, sizeof cur);
        }
        assert_int_equal(br_model_step_at(&m, cur, p0, reaching(sent, k, n, dm, df) - u_ext, nxt), BR_OK);
        const float fa = br_model_fcomp_N(&m, cur, p0), fb = br_model_fcomp_N(&m, nxt, p0);
        const float want = F_hat + (fa + (h - (float)n) * (fb - fa) - f0);
        assert_true(isfinite(F));
        worst = fmaxf(worst, fabsf(F - want));
        moved = fmaxf(moved, fabsf(want - F_hat));
    }
    /* float rounding of the same sums only; the lead itself moves F by far more */
    assert_true(worst <= 1.0e-5f);
    assert_true(moved > 1.0e-2f);
    /* with the external-force state on, F_d moved: the carry's L F_d was exercised */
    if (cu.load.max_N > 0.0f) {
        assert_true(fd_max > 0.1f);
    }
}

static void test_lead_without_delay(void **st)
{
    (void)st;
    run_carry_case(0.0f, 0.5f, 0);
    run_carry_case(0.0f, 1.0f, 0);
}

static void test_lead_over_a_delay(void **st)
{
    (void)st;
    run_carry_case(2.5f, 0.75f, 0);
    run_carry_case(3.0f, 0.5f, 0);
}

/* the extended model carries theta relative to the estimator's origin: its
 * ripple and gradient see the position p0 + L theta */
static void test_lead_on_the_extended_model(void **st)
{
    (void)st;
    run_carry_case(0.0f, 0.5f, 1);
    run_carry_case(2.5f, 0.75f, 1);
}

/* the PF's lead starts from the particle mean (br_pf_stats' mean), theta
 * relative to its origin */
static void run_pf_case(int extended)
{
    br_pf_cfg_t cp;
    br_pf_t *pf = pf_with_lead(1.0f, extended, &cp);
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cp.est.model), BR_OK);
    float moved = 0.0f, fd_max = 0.0f;
    for (int k = 0; k < N_STEPS; k++) {
        const br_meas_t y = {counts_at(k), 0.5f};
        float F = NAN;
        assert_false(BR_FAILED(br_pf_est_step(pf, &y, cmd_at(k), &F)));
        br_pf_stats_t s;
        assert_int_equal(br_pf_stats(pf, &s), BR_OK);
        const float p0 = (float)br_pf_estimate(pf)->origin_counts * pf->m_per_count;
        float nxt[BR_NX];
        /* less the shared external force's torque (0 with it off) */
        const float u_ext = cp.est.model.lead_mprad * pf->load_N;
        fd_max = fmaxf(fd_max, fabsf(pf->load_N));
        assert_int_equal(br_model_step_at(&m, s.mean, p0, cmd_at(k) - u_ext, nxt), BR_OK);
        const float want = br_pf_estimate(pf)->F_hat_N +
                           (br_model_fcomp_N(&m, nxt, p0) - br_model_fcomp_N(&m, s.mean, p0));
        BR_ASSERT_NEAR(F, want, 1.0e-5);
        moved = fmaxf(moved, fabsf(F - br_pf_estimate(pf)->F_hat_N));
    }
    assert_true(moved > 1.0e-2f);
    /* with the shared external force on, F_d moved: the carry's L F_d was exercised */
    if (cp.load.max_N > 0.0f) {
        assert_true(fd_max > 0.1f);
    }
    free(pf);
}

static void test_pf_lead_from_the_mean(void **st)
{
    (void)st;
    run_pf_case(0);
    run_pf_case(1);
}

/* a carry the model refuses (a state out of its range), a force beyond float
 * range, or a lead or delay no check has seen give F_hat itself */
static void test_failed_carry_gives_the_estimate(void **st)
{
    (void)st;
    br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    cu.est.comp_ahead_periods = 0.5f;
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cu.est.model), BR_OK);
    br_est_delay_t d;
    br_est_delay_init(&d, &cu.est);
    const float F_hat = 3.25f;
    const float bad_gp[BR_NX] = {0.0f, 1.0f, 0.0f, 0.0f}; /* g_p = 0: outside the model */
    assert_true(br_est_comp_N(&cu.est, &m, &d, bad_gp, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    const float nan_x[BR_NX] = {0.0f, NAN, 0.0f, 5.0f};
    assert_true(br_est_comp_N(&cu.est, &m, &d, nan_x, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    /* a speed the model's step refuses */
    const float faster[BR_NX] = {0.0f, 3.0e38f, 0.0f, 5.0f};
    assert_true(br_est_comp_N(&cu.est, &m, &d, faster, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    /* finite steps whose force is not (1e36 rad/s: f_c is infinite or NaN) */
    const float fast[BR_NX] = {0.0f, 1.0e36f, 0.0f, 5.0f};
    float x1[BR_NX];
    assert_int_equal(br_model_step_at(&m, fast, 0.0f, 0.1f, x1), BR_OK);
    assert_true(br_est_comp_N(&cu.est, &m, &d, fast, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    /* a sane state moves it */
    const float ok[BR_NX] = {0.0f, 1.0f, 0.0f, 5.0f};
    const float lead = br_est_comp_N(&cu.est, &m, &d, ok, 0.0f, 0.1f, 0.0f, 0.0f);
    assert_true(isfinite(lead) && lead != 0.0f);
    /* a lead no check has seen: none at all, not a loop of 2^32 steps */
    br_est_cfg_t wild = cu.est;
    wild.comp_ahead_periods = INFINITY;
    assert_true(br_est_comp_N(&wild, &m, &d, ok, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    wild.comp_ahead_periods = 2.5f;
    assert_true(br_est_comp_N(&wild, &m, &d, ok, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    /* nor a delay longer than the history */
    br_est_delay_t far = d;
    far.on = 1;
    far.m = BR_EST_DELAY_HIST - 1u;
    far.f = 0.0f;
    assert_true(br_est_comp_N(&cu.est, &m, &far, ok, 0.0f, 0.1f, 0.0f, F_hat) == F_hat);
    far.m = BR_EST_DELAY_HIST - 2u; /* the longest one: carried */
    assert_true(br_est_comp_N(&cu.est, &m, &far, ok, 0.0f, 0.1f, 0.0f, F_hat) != F_hat);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ahead_bounds),
        cmocka_unit_test(test_no_lead_is_the_estimate),
        cmocka_unit_test(test_lead_without_delay),
        cmocka_unit_test(test_lead_on_the_extended_model),
        cmocka_unit_test(test_lead_over_a_delay),
        cmocka_unit_test(test_pf_lead_from_the_mean),
        cmocka_unit_test(test_failed_carry_gives_the_estimate),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
