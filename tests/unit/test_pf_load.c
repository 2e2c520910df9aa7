/* SPDX-License-Identifier: Apache-2.0 */
/* The PF's shared external force (cfg.load; docs/modules/pf.md, "External
 * force"): its configuration guards, a load step followed with one outlier
 * step (its first period held; without the state, the outliers it causes),
 * the compensation of friction + load within the bound, a counter jump no
 * load can explain still rejected, and encoder glitches no load. */
#include "br_test.h"
#include "br_test_push.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "circle/br_circle_est.h"
#include "bristle/br_pf.h"

#define DT_F BR_EST_PF_PERIOD_S_F

/* the filters are large: one, static to the test (not a mutable global of the firmware) */
static br_pf_t g_pf;

static br_pf_cfg_t load_cfg(void)
{
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(DT_F);
    c.load.q_N2 = 1.0e4f * DT_F; /* 1e4 N^2/s, the campaign's */
    c.load.max_N = BR_MACHINE_TORQUE_LIMIT_NM_F / c.est.model.lead_mprad;
    return c;
}

static int init_with(br_pf_cfg_t c) { return br_pf_init(&g_pf, &c); }

static void test_load_guards(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    assert_true(g_pf.load_g_radpN > 0.0f);
    assert_true(g_pf.load_P[5] == c.load.max_N * c.load.max_N);
    c = br_circle_pf_cfg_tuned(DT_F);
    assert_int_equal(init_with(c), BR_OK); /* all 0: off */
    /* off needs both 0 */
    c = br_circle_pf_cfg_tuned(DT_F); c.load.q_N2 = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    c = br_circle_pf_cfg_tuned(DT_F); c.load.max_N = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    const float bad[] = {NAN, INFINITY, -1.0f, 1.0e-40f, 2.0f * BR_EST_VAR_MAX, 0.0f};
    for (unsigned b = 0; b < sizeof bad / sizeof bad[0]; b++) {
        c = load_cfg(); c.load.q_N2 = bad[b]; assert_int_equal(init_with(c), BR_E_PARAM);
        c = load_cfg(); c.load.max_N = bad[b]; assert_int_equal(init_with(c), BR_E_PARAM);
    }
    c = load_cfg(); c.load.max_N = 1.0e19f; assert_int_equal(init_with(c), BR_E_PARAM); /* 4 max^2 overflows */
    /* the cloud is moved and weighed again with eq. 6 and the Gaussian likelihood:
     * the bootstrap proposal of the thesis model only */
    c = load_cfg(); c.proposal = BR_PF_PROPOSAL_OPT; assert_int_equal(init_with(c), BR_E_PARAM);
    c = load_cfg(); c.est.model.causes.offset_N = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
}

/* Counts of an axis held still for 0.1 s, then pushed by an external force
 * F_N (toward -x: a force against +x, as friction) with no torque: theta(t) =
 * -L F_N t^2 / (2 J_eff) from t0, frictionless. Runs n periods, returns the
 * number of outlier steps; *F_comp the last compensation. */
static int run_pushed(double F_N, int n, float *F_comp)
{
    const br_model_cfg_t *m = &g_pf.cfg.est.model;
    const double rpc = g_pf.cfg.est.rad_per_count;
    const br_est_t e = br_pf_est(&g_pf);
    return br_test_run_pushed(&e, m, rpc, F_N, n, F_comp);
}

static void test_load_step_followed(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    const double F = 0.5 * (double)c.load.max_N; /* half the actuator's force */
    float comp = 0.0f;
    /* pushed from rest until the axis reaches the machine's top speed: 0.1 s still,
     * then v_max J_eff / (L^2 F) */
    const br_model_cfg_t *m = &c.est.model;
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const int n = (int)ceil(0.1 / m->dt_s) + (int)ceil((double)BR_MACHINE_MAX_SPEED_MPS_F * Jeff / (L * L * F) / m->dt_s);
    assert_int_equal(init_with(c), BR_OK);
    /* one outlier step: the push's first period, held as the candidate its second confirms */
    assert_int_equal(run_pushed(F, n, &comp), 1);
    assert_int_equal(g_pf.load_gate.n_held, 1u);
    assert_true(g_pf.n_load_acq >= 1u);
    printf("  load %.1f N: compensation %.2f N, F_d %.2f N, %u re-acquisitions\n", F, (double)comp,
           (double)g_pf.load_N, g_pf.n_load_acq);
    /* the compensation carries the load: of its size within half of it (without
     * cfg.load it is the friction's, about 0.06 F). Measured at the top speed: 1.14 F
     * on the reference machine, 0.74 F on machines/heavy.json (machine_heavy), still
     * rising there; the pushed axis of this test is frictionless while the filter's
     * model brakes it by sigma2 v, so the estimate also takes up that mismatch and
     * goes on growing with the speed (1.4 F at twice the push's time on both) */
    assert_true(comp > 0.5 * F && comp < 1.5 * F);
    /* without it the same push is a run of outliers (the lock monitor's trip) */
    br_pf_cfg_t off = br_circle_pf_cfg_tuned(DT_F);
    assert_int_equal(init_with(off), BR_OK);
    assert_true(run_pushed(F, 250, &comp) > 10);
}

static void test_load_bounded(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    c.load.max_N = 100.0f; /* a bound below the push: F_d and the compensation stay within it */
    float comp = 0.0f;
    assert_int_equal(init_with(c), BR_OK);
    (void)run_pushed(250.0, 250, &comp);
    assert_true(fabsf(g_pf.load_N) <= 100.0f);
    assert_true(fabsf(comp) <= 100.0f);
}

static void test_jump_not_a_load(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    const br_meas_t y = {100, 0.5f};
    for (int k = 0; k < 200; k++) {
        assert_int_equal(br_pf_step(&g_pf, &y, 0.0f), BR_OK);
    }
    const uint32_t acq = g_pf.n_load_acq;
    /* 2e4 counts in one period: a force of ~5e3 N, beyond 2 max_N: still an outlier, no re-acquisition */
    const br_meas_t j = {100 + 20000, 0.5f};
    assert_int_equal(br_pf_step(&g_pf, &j, 0.0f), BR_W_OUTLIER);
    assert_int_equal(g_pf.n_load_acq, acq);
}

/* docs/modules/pf.md, "Glitch or load": a 500-count spike and a 1000-count
 * slip at rest are forces of 116 and 233 N over one period, within 2 max_N;
 * taken for loads (the single-innovation rule) F_d swung +-450 N for 90
 * periods. Held as candidates, neither is confirmed (the spike comes back,
 * the slip stays: its error does not grow as a force's): no re-acquisition,
 * the compensation stays the friction's (< 2 % of the actuator's force), the
 * spike costs one outlier step and the slip the re-anchoring's
 * reanchor_after. */
static void test_glitch_not_a_load(void **st)
{
    (void)st;
    static const int32_t off[2] = {500, 1000};
    for (int slip = 0; slip < 2; slip++) {
        br_pf_cfg_t c = load_cfg();
        assert_int_equal(init_with(c), BR_OK);
        float F_max;
        const br_est_t e = br_pf_est(&g_pf);
        const int n_out = br_test_run_glitch(&e, off[slip], slip, 600, &F_max);
        br_test_assert_glitch(slip, n_out, F_max, g_pf.n_load_acq, g_pf.load_gate.n_held, c.load.max_N, c.est.reanchor_after);
    }
}

/* A spike 1, 2 and 3 periods after a load's re-acquisition (the window of
 * docs/modules/est.md, "Glitch or load") */
static void test_glitch_in_window(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    const double F = 0.5 * (double)c.load.max_N;
    const int n = br_test_push_periods(&c.est.model, F, (double)BR_MACHINE_MAX_SPEED_MPS_F);
    float F_end[4];
    int acq[4];
    for (int after = 0; after < 4; after++) {
        assert_int_equal(init_with(c), BR_OK);
        const br_est_t e = br_pf_est(&g_pf);
        acq[after] = br_test_run_push_spike(&e, &g_pf.n_load_acq, &c.est.model, c.est.rad_per_count, F, after, n,
                                            &F_end[after]);
    }
    br_test_assert_window(acq, F_end, F);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_guards),
        cmocka_unit_test(test_load_step_followed),
        cmocka_unit_test(test_load_bounded),
        cmocka_unit_test(test_jump_not_a_load),
        cmocka_unit_test(test_glitch_not_a_load),
        cmocka_unit_test(test_glitch_in_window),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
