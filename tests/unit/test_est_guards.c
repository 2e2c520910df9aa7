/* SPDX-License-Identifier: Apache-2.0 */
/* The estimators' fail-safe guards (docs/reliability.md): noise variances
 * that would break a filter are rejected at init; a residual so large that
 * its log-weight overflows does not turn a valid particle invalid; the UKF
 * recovers from a covariance that fails instead of failing forever; a
 * predict-only step serves a period without a measurement, and the spread it
 * adds is taken back by the measurements that follow. */
#include "br_test.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_est.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"

/* the estimator periods of the circle experiment (thesis section 5) */
#define PF_DT_S 1.5e-3f
#define UKF_DT_S 1.0e-3f
/* an encoder silent for 1 s (docs/reliability.md), in periods */
#define PF_GAP 667
#define UKF_GAP 1000

static void test_variance_bounds(void **st)
{
    (void)st;
    const br_est_cfg_t ok = br_circle_ukf_cfg_tuned(UKF_DT_S).est;
    const float rpc2 = ok.rad_per_count * ok.rad_per_count;
    br_est_cfg_t c = ok;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* R: subnormal (1 / 2R overflows), below a millionth of a count^2, absurd, NaN */
    c = ok; c.r_var_rad2 = 1e-40f;                      assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.r_var_rad2 = 0.5f * BR_EST_R_MIN_COUNTS2 * rpc2; assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.r_var_rad2 = BR_EST_R_MIN_COUNTS2 * rpc2; assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c = ok; c.r_var_rad2 = 2.0f * BR_EST_VAR_MAX;       assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.r_var_rad2 = NAN;                         assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    /* Q: zero is allowed, a subnormal or absurd entry is not */
    for (int i = 0; i < BR_NX; i++) {
        c = ok; c.q_var[i] = 0.0f;                 assert_int_equal(br_est_cfg_check(&c), BR_OK);
        c = ok; c.q_var[i] = 1e-40f;               assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
        c = ok; c.q_var[i] = 2.0f * BR_EST_VAR_MAX; assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
        c = ok; c.q_var[i] = -1.0f;                assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    }
    /* the outlier gate: its square must stay a float (found by fuzz_replay:
     * a gate of 1e30 sigma made the PF's threshold -inf and the ESS 0/0) */
    c = ok; c.outlier_sigma = 2.0f * BR_EST_GATE_MAX_SIGMA; assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.outlier_sigma = BR_EST_GATE_MAX_SIGMA;        assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* the gate's transient term (rad): 0 (off) up to BR_EST_GATE_MAX_TRANSIENT_COUNTS counts, finite */
    const float d_max = BR_EST_GATE_MAX_TRANSIENT_COUNTS * ok.rad_per_count;
    c = ok; c.outlier_transient_rad = 0.0f;          assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c = ok; c.outlier_transient_rad = d_max;         assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c = ok; c.outlier_transient_rad = 2.0f * d_max;  assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.outlier_transient_rad = -ok.rad_per_count; assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.outlier_transient_rad = NAN;           assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c = ok; c.outlier_transient_rad = INFINITY;      assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    assert_true(br_est_var_ok(BR_EST_VAR_MAX, 0));
    assert_false(br_est_var_ok(0.0f, 0));
    assert_true(br_est_var_ok(0.0f, 1));
    assert_false(br_est_var_ok(INFINITY, 1));
}

/* the gate's transient factor (eq. G1) at no spread: the thesis gate, finite, never a 0/0
 * (fuzz_replay found the division by zero through a replay's header) */
static void test_gate_factor_zero_spread(void **st)
{
    (void)st;
    br_est_cfg_t c;
    memset(&c, 0, sizeof c);
    c.outlier_sigma = 8.0f;
    c.outlier_transient_rad = 1e-3f;
    assert_true(br_est_gate_f2(&c, 0.0f) == 1.0f);
    c.outlier_sigma = 0.0f;
    assert_true(br_est_gate_f2(&c, 1.0f) == 1.0f);
    c.outlier_sigma = 8.0f;
    assert_true(br_est_gate_f2(&c, 1.0f) > 1.0f); /* the term where there is spread */
}

static void test_pf_needs_gp_noise(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(PF_DT_S);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    /* without g_p noise the resampled cloud collapses onto one g_p for good */
    c.est.q_var[BR_X_GP] = 0.0f;
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = br_circle_pf_cfg_tuned(PF_DT_S);
    c.x0_std[BR_X_OMEGA] = 2.0e6f; /* variance 4e12 > BR_EST_VAR_MAX */
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    free(pf);
}

/* an element set in the model: the PF and the UKF take it, but not with a
 * look-ahead of the compensation (comp_ahead_periods steps the LuGre state) */
static void test_mslip_refused(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    br_ukf_t *ukf = calloc(1, sizeof *ukf);
    assert_non_null(pf);
    assert_non_null(ukf);
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(PF_DT_S);
    br_ukf_cfg_t u = br_circle_ukf_cfg_tuned(UKF_DT_S);
    c.load = (br_pf_load_t){0.0f, 0.0f}; /* the PF's shared external force is LuGre-only */
    const br_mslip_cfg_t ms = {.n = 1, .k_Npm = {1.0e6f}, .share = {1.0f}};
    c.est.model.mslip = ms;
    u.est.model.mslip = ms;
    c.est.comp_ahead_periods = 0.0f;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c.est.comp_ahead_periods = 1.0f;
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    u.est.comp_ahead_periods = 0.0f;
    assert_int_equal(br_ukf_init(ukf, &u), BR_OK);
    u.est.comp_ahead_periods = 1.0f;
    assert_int_equal(br_ukf_init(ukf, &u), BR_E_PARAM);
    free(pf);
    free(ukf);
}

static void test_ukf_p0_bounds(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(UKF_DT_S);
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    c.p0_var[BR_X_Z] = 1e-40f;
    assert_int_equal(br_ukf_init(&u, &c), BR_E_PARAM);
    c = br_circle_ukf_cfg_tuned(UKF_DT_S);
    c.p0_var[BR_X_OMEGA] = 2.0f * BR_EST_VAR_MAX;
    assert_int_equal(br_ukf_init(&u, &c), BR_E_PARAM);
}

/* Every particle so far from y that -(e^2)/(2R) overflows to -inf: the weights
 * must still be those of valid particles (an outlier step with equal weights),
 * never the all-zero weights of an all-invalid set (an ESS of 0/0). */
static void test_pf_log_weight_overflow(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(PF_DT_S);
    c.load = (br_pf_load_t){0.0f, 0.0f}; /* the thesis filter's weights (the load re-acquires the jump) */
    c.n_particles = 64u;
    c.est.reanchor_after = 1000u;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    const br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    for (uint32_t j = 0; j < c.n_particles; j++) {
        pf->x[BR_X_THETA][j] = 1.0e18f; /* e^2 / 2R ~ 1e36 / 4e-11 */
        pf->x[BR_X_OMEGA][j] = 0.0f;
    }
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    const br_pf_est_t *e = br_pf_estimate(pf);
    br_pf_stats_t s;
    assert_int_equal(br_pf_stats(pf, &s), BR_OK);
    assert_true(isfinite(s.ess));
    BR_ASSERT_NEAR(s.ess, (double)c.n_particles, 1e-3);
    assert_true(isfinite(e->F_hat_N));
    /* the same with the threshold itself at -inf (init keeps the gate's square a
     * float; the step does not rely on it): still an outlier step, not 0/0 */
    for (uint32_t j = 0; j < c.n_particles; j++) {
        pf->x[BR_X_THETA][j] = 1.0e18f;
    }
    pf->outlier_l = -INFINITY;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    assert_int_equal(br_pf_stats(pf, &s), BR_OK);
    assert_true(isfinite(s.ess));
    free(pf);
}

/* A covariance so large that the prediction overflows: the step fails once,
 * P is reset to P0, and the filter works again from the next step on. */
static void test_ukf_recovers_from_huge_covariance(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(UKF_DT_S);
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    const br_meas_t y = {100, 0.5f};
    for (int k = 0; k < 5; k++) {
        assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_OK);
    }
    for (int i = 0; i < BR_NX; i++) {
        u.P[i][i] = 1.0e36f; /* finite, and positive definite */
    }
    const uint32_t resets = u.n_recover;
    assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_E_NUMERIC);
    assert_int_equal(u.n_recover, resets + 1u);
    for (int k = 0; k < 10; k++) {
        assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_OK);
    }
    assert_true(isfinite(br_ukf_estimate(&u)->F_hat_N));
}

/* theta spread of the particle cloud (standard deviation, rad) */
static double pf_theta_std(const br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    double s = 0.0, s2 = 0.0;
    for (uint32_t j = 0; j < m; j++) {
        s += pf->x[BR_X_THETA][j];
    }
    const double mean = s / m;
    for (uint32_t j = 0; j < m; j++) {
        const double d = pf->x[BR_X_THETA][j] - mean;
        s2 += d * d;
    }
    return sqrt(s2 / m);
}

static void test_pf_predict_only(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(PF_DT_S);
    assert_int_equal(br_pf_predict(pf, 0.0f), BR_E_STATE); /* not initialised */
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    assert_int_equal(br_pf_predict(pf, 0.0f), BR_E_STATE); /* nothing to predict from yet */
    const br_meas_t y = {500, 0.5f};
    for (int k = 0; k < 50; k++) {
        assert_false(BR_FAILED(br_pf_step(pf, &y, 0.0f)));
    }
    const double locked = pf_theta_std(pf);
    assert_int_equal(br_pf_predict(pf, NAN), BR_E_INPUT);
    /* 1 s without a measurement: the cloud spreads, the estimate stays finite */
    for (int k = 0; k < PF_GAP; k++) {
        assert_int_equal(br_pf_predict(pf, 0.0f), BR_OK);
        assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
        assert_int_equal(br_pf_estimate(pf)->origin_counts, 500);
    }
    const double gap = pf_theta_std(pf);
    print_message("PF theta spread: locked %.3g rad, after %d predict-only periods %.3g rad\n", locked, PF_GAP, gap);
    assert_true(gap > 3.0 * locked);
    assert_int_equal(pf->n_predicted, (uint32_t)PF_GAP);
    /* measurements again: the spread comes back to the locked level */
    for (int k = 0; k < 50; k++) {
        assert_false(BR_FAILED(br_pf_step(pf, &y, 0.0f)));
    }
    assert_int_equal(pf->n_predicted, 0u);
    const double back = pf_theta_std(pf);
    print_message("PF theta spread after 50 measured periods %.3g rad\n", back);
    assert_true(back < 2.0 * locked);
    free(pf);
}

static void test_ukf_predict_only(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(UKF_DT_S);
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    assert_int_equal(br_ukf_predict(&u, 0.0f), BR_E_STATE);
    const br_meas_t y = {-300, 0.5f};
    for (int k = 0; k < 50; k++) {
        assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_OK);
    }
    const double locked = u.P[BR_X_THETA][BR_X_THETA];
    assert_int_equal(br_ukf_predict(&u, INFINITY), BR_E_INPUT);
    double prev = locked;
    for (int k = 0; k < UKF_GAP; k++) {
        assert_int_equal(br_ukf_predict(&u, 0.0f), BR_OK);
        /* the theta variance grows every period without a measurement */
        assert_true(u.P[BR_X_THETA][BR_X_THETA] > prev);
        prev = u.P[BR_X_THETA][BR_X_THETA];
        assert_int_equal(br_ukf_estimate(&u)->origin_counts, -300);
    }
    print_message("UKF theta variance: locked %.3g rad^2, after %d predict-only periods %.3g rad^2\n", locked, UKF_GAP,
                  prev);
    assert_true(prev > 10.0 * locked);
    for (int k = 0; k < 50; k++) {
        assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_OK);
    }
    assert_int_equal(u.n_predicted, 0u);
    BR_ASSERT_NEAR(u.P[BR_X_THETA][BR_X_THETA], locked, 0.1 * locked);
}

/* Many resamplings in a row at rest (3 s): the cloud keeps its spread in g_p
 * (the process noise the init insists on), it does not collapse onto a few
 * ancestors. */
static void test_pf_spread_survives_resampling(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    const br_pf_cfg_t c = br_circle_pf_cfg_tuned(PF_DT_S);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    const br_meas_t y = {0, 0.5f};
    for (int k = 0; k < 2000; k++) {
        assert_false(BR_FAILED(br_pf_step(pf, &y, 0.0f)));
    }
    const uint32_t m = c.n_particles;
    double s = 0.0, s2 = 0.0;
    for (uint32_t j = 0; j < m; j++) s += pf->x[BR_X_GP][j];
    const double mean = s / m;
    uint32_t distinct = 0;
    for (uint32_t j = 0; j < m; j++) {
        const double d = pf->x[BR_X_GP][j] - mean;
        s2 += d * d;
        int seen = 0;
        for (uint32_t i = 0; i < j && !seen; i++) seen = pf->x[BR_X_GP][i] == pf->x[BR_X_GP][j];
        distinct += !seen;
    }
    const double sd = sqrt(s2 / m), q = sqrt((double)c.est.q_var[BR_X_GP]);
    print_message("after 2000 resamplings: g_p spread %.3g N (process noise %.3g N per step), %u of %u distinct\n",
                  sd, q, distinct, m);
    assert_true(sd > 0.3 * q);
    assert_true(distinct > m / 4u);
    free(pf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_variance_bounds),
        cmocka_unit_test(test_gate_factor_zero_spread),
        cmocka_unit_test(test_pf_needs_gp_noise),
        cmocka_unit_test(test_mslip_refused),
        cmocka_unit_test(test_ukf_p0_bounds),
        cmocka_unit_test(test_pf_log_weight_overflow),
        cmocka_unit_test(test_ukf_recovers_from_huge_covariance),
        cmocka_unit_test(test_pf_predict_only),
        cmocka_unit_test(test_ukf_predict_only),
        cmocka_unit_test(test_pf_spread_survives_resampling),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
