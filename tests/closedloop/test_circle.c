/* SPDX-License-Identifier: Apache-2.0 */
/* The thesis circle on the simulator with the H-inf-only controller
 * (section 5): outward quadrant glitches after the reversals, no saturation,
 * the same gains at the PF's period; the compensated loops against H-inf only.
 * Machine-generic: every bound is a ratio to the H-inf-only run or comes from
 * the machine's headers. On the thesis's machine (BR_TEST_THESIS_MACHINE,
 * set by CMake for machines/reference.json) also the published figures. */
#include "br_test.h"

#include "circle/br_circle.h"
#include "tool/br_run_report.h"
#include "bristle/br_app.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

#ifdef BR_TEST_THESIS_MACHINE
/* thesis section 5: H-inf only, contour RMS */
#define THESIS_HINF_ONLY_RMS_M 2.4e-6
/* What the code achieves on the reference machine (`make demo`, docs/demo.md:
 * contour RMS 2.667e-8 m (PF with its shared external force, tuned with it,
 * the guard plants' outliers and the Maxwell-slip guards, 2026-11-28), 1.547e-8 m (UKF with its
 * external-force state, tuned with it and the Maxwell-slip and delayed guard
 * plants, 2026-11-28) against 2.288e-6 m for H-inf only; compensation RMS
 * error 0.0754 N, 0.282 N: the UKF's F_d, in its compensation, carries a
 * period-to-period noise of mean 0, docs/modules/ukf.md). The bounds sit
 * MEASURED_MARGIN above them: a filter 20 % worse in either figure fails.
 * The run is deterministic (fixed noise table and seeds, -ffp-contract=off;
 * the firmware is bit-identical on the M7, docs/target.md): the margin only
 * has to cover the host libm's double exp/sin in the plant and the rounding of
 * the documented figures (0.049 may be 0.0495: 1.3 x 0.0495 = 0.064 > 1.2 x 0.049). A
 * retune (`make tune`) that changes the figures updates them here and in docs/demo.md. */
#define PF_RATIO_MEASURED (2.667e-8 / 2.288e-6)
#define PF_FERR_MEASURED_N 0.0754
#define UKF_RATIO_MEASURED (1.547e-8 / 2.288e-6)
#define UKF_FERR_MEASURED_N 0.282
#define MEASURED_MARGIN 1.2
#endif

/* Reversals of the circle x = A sin(2 pi t / 8), y = A cos(2 pi t / 8):
 * y at t = 4 s, x at t = 2 and 6 s (t = 0 is the start, excluded). */
static const double reversal_s[] = {2.0, 4.0, 6.0};
#define N_REV 3
#define WINDOW_S 0.8

typedef struct {
    double max_out[N_REV], max_in[N_REV];
} glitch_t;

static void glitch_sink(void *user, const br_circle_sample_t *s)
{
    glitch_t *g = user;
    for (int i = 0; i < N_REV; i++) {
        if (s->t_s >= reversal_s[i] && s->t_s < reversal_s[i] + WINDOW_S) {
            if (s->radial_err_m > g->max_out[i]) g->max_out[i] = s->radial_err_m;
            if (-s->radial_err_m > g->max_in[i]) g->max_in[i] = -s->radial_err_m;
        }
    }
}

static void test_hinf_only_quadrant_glitches(void **st)
{
    (void)st;
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    br_circle_result_t r;
    glitch_t g = {{0}, {0}};
    assert_int_equal(br_circle_run(&c, glitch_sink, &g, &r), 0);
    print_message("H-inf only: contour RMS %.3e m, max %.3e m\n", r.contour_rms_m, r.max_err_m);
    /* the experiment fits the machine: its diameter in the travel, its speed under the top speed */
    assert_true(2.0 * c.radius_m <= BR_MACHINE_TRAVEL_M);
    assert_true(2.0 * 3.14159265358979323846 * c.radius_m / c.period_s <= BR_MACHINE_MAX_SPEED_MPS);
    assert_int_equal(r.n_samples, (long)floor(c.duration_s / c.dt_s + 0.5) + 1);
    assert_int_equal(r.saturated_steps, 0);
#ifdef BR_TEST_THESIS_MACHINE
    /* the weights were chosen to give the published figure (docs/modules/hinf.md) */
    print_message("thesis: %.1e m\n", THESIS_HINF_ONLY_RMS_M);
    assert_true(fabs(r.contour_rms_m / THESIS_HINF_ONLY_RMS_M - 1.0) <= 0.30);
#endif
    for (int i = 0; i < N_REV; i++) {
        print_message("reversal at %.0f s: outward %.2f um, inward %.2f um\n", reversal_s[i], g.max_out[i] * 1e6,
                      g.max_in[i] * 1e6);
        /* an outward glitch after each reversal, larger than the run's RMS and
         * than any inward excursion there */
        assert_true(g.max_out[i] > r.contour_rms_m);
        assert_true(g.max_out[i] > 1.5 * g.max_in[i]);
#ifdef BR_TEST_THESIS_MACHINE
        assert_true(g.max_out[i] > 2e-6); /* "a few um", as the thesis shows */
#endif
    }
}

/* A motionless axis is never a perfect result: with zero gains the table
 * stays at the circle's start, on the circle, with no radial error at all
 * (br_demo_circle --gains 0,0,0 once rated it at contour RMS 0). The run is
 * no result: the fault BR_RUN_NOT_FOLLOWED, rc 1. The thesis run followed,
 * its table within a small part of the radius. */
static void test_motionless_axis_is_no_result(void **st)
{
    (void)st;
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    br_circle_result_t r;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 0);
    assert_int_equal(r.fault_status, 0);
    print_message("H-inf only: the table at most %.3e m from the reference point (radius %.1e m)\n", r.track_max_m,
                  c.radius_m);
    assert_true(r.track_max_m < 0.2 * c.radius_m);
    c.K[0] = c.K[1] = c.K[2] = 0.0f;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 1);
    assert_int_equal(r.fault_status, BR_RUN_NOT_FOLLOWED);
    assert_int_equal(r.fault_cause, BR_RUN_CAUSE_NOT_FOLLOWED);
    assert_true(r.track_max_m > c.radius_m);
    /* the reference is a radius away after a sixth of the revolution */
    assert_true(r.fault_t_s > 0.0 && r.fault_t_s < c.period_s / 5.0);
}

static void test_same_gains_at_pf_period(void **st)
{
    (void)st;
    /* the PF runs at its own period (1.5 ms on the reference): the H-inf loop must
     * stay stable there and within twice its RMS at the control period */
    br_circle_cfg_t c0 = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY), c = c0;
    c.dt_s = BR_EST_PF_PERIOD_S;
    br_circle_result_t r0, r;
    assert_int_equal(br_circle_run(&c0, NULL, NULL, &r0), 0);
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 0);
    print_message("H-inf only at %.2g ms: contour RMS %.3e m (%.3e m at %.2g ms)\n", c.dt_s * 1e3, r.contour_rms_m,
                  r0.contour_rms_m, c0.dt_s * 1e3);
    assert_true(r.contour_rms_m < 2.0 * r0.contour_rms_m);
    assert_int_equal(r.saturated_steps, 0);
}

/* Thesis section 5 ratios to H-inf only: UKF 1.3/2.4, PF 0.4/2.4. The compensated
 * loops must do at least as well as the thesis's, without saturating and
 * without the estimator losing lock. */
static double run_ratio(br_circle_ctrl_t ctrl, br_circle_result_t *r)
{
    br_circle_cfg_t c0 = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY), c = br_circle_cfg_thesis(ctrl);
    br_circle_result_t r0;
    assert_int_equal(br_circle_run(&c0, NULL, NULL, &r0), 0);
    assert_int_equal(br_circle_run(&c, NULL, NULL, r), 0);
    print_message("%s: contour RMS %.3e m = %.4f of H-inf only, friction estimate RMS error %.4f N, %d outliers\n",
                  br_circle_ctrl_name(ctrl), r->contour_rms_m, r->contour_rms_m / r0.contour_rms_m,
                  r->fhat_rms_err_N, r->outlier_steps);
    assert_int_equal(r->saturated_steps, 0);
    assert_int_equal(r->outlier_steps, 0);
    return r->contour_rms_m / r0.contour_rms_m;
}

static void test_ukf_beats_thesis_ratio(void **st)
{
    (void)st;
    br_circle_result_t r;
    const double ratio = run_ratio(BR_CTRL_HINF_UKF, &r);
    assert_true(ratio <= 1.3 / 2.4);
#ifdef BR_TEST_THESIS_MACHINE
    assert_true(ratio <= MEASURED_MARGIN * UKF_RATIO_MEASURED);
    assert_true(r.fhat_rms_err_N <= MEASURED_MARGIN * UKF_FERR_MEASURED_N);
#endif
}

static void test_pf_beats_thesis_ratio(void **st)
{
    (void)st;
    br_circle_result_t r;
    const double ratio = run_ratio(BR_CTRL_HINF_PF, &r);
    assert_true(ratio <= 0.4 / 2.4);
#ifdef BR_TEST_THESIS_MACHINE
    assert_true(ratio <= MEASURED_MARGIN * PF_RATIO_MEASURED);
    assert_true(r.fhat_rms_err_N <= MEASURED_MARGIN * PF_FERR_MEASURED_N);
#endif
}

static void assert_refused_at_init(const br_circle_cfg_t *c)
{
    br_circle_result_t r;
    assert_int_equal(br_circle_run(c, NULL, NULL, &r), -1);
    assert_int_equal(r.fault_status, BR_E_PARAM);
    assert_int_equal(r.fault_cause, BR_RUN_CAUSE_REFUSED_AT_INIT);
    assert_true(r.fault_t_s == 0.0 && r.n_samples == 0);
}

static void test_rejects_bad_experiment(void **st)
{
    (void)st;
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    br_circle_result_t r;
    c.dt_s = 0.0;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), -1);
    c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    c.plant.sigma0_Npm = -1.0;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), -1);
    assert_int_equal(r.fault_cause, 0); /* the harness's plant, not the firmware, refused it */
    /* what the firmware refuses at init (br_app_init: the controller's gains, an estimator
     * whose period is not the loop's, an estimator's setting): -1, the result saying so
     * (br_run_report.h) */
    c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    c.K[0] = NAN;
    assert_refused_at_init(&c);
    c = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    c.dt_s = 2.0 * c.dt_s;
    assert_refused_at_init(&c);
    c = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    c.ukf.est.r_var_rad2 = -1.0f;
    assert_refused_at_init(&c);
    /* a direction other than +1 (clockwise) or -1 */
    c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    c.dir = 0.5;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), -1);
}

/* The tools' circle (br_circle_use_path, docs/circle-test.md): nothing given
 * keeps the thesis's bit for bit; a radius alone keeps the feed; a feed sets
 * the revolution; counter-clockwise mirrors x from the same start (0, A). */
#define assert_near(a, b, tol) assert_true(fabs((a) - (b)) <= (tol))

typedef struct {
    double t_s[3], ref_m[3][2];
} refs_t;

static void refs_sink(void *user, const br_circle_sample_t *s)
{
    refs_t *g = user;
    for (int i = 0; i < 3; i++)
        if (fabs(s->t_s - g->t_s[i]) < 1e-9) {
            g->ref_m[i][0] = s->ref_m[0];
            g->ref_m[i][1] = s->ref_m[1];
        }
}

static void test_circle_path(void **st)
{
    (void)st;
    const br_circle_cfg_t th = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    br_circle_cfg_t c = th;
    br_circle_use_path(&c, 0.0, 0.0, 0);
    assert_true(c.radius_m == th.radius_m && c.period_s == th.period_s && c.duration_s == th.duration_s);
    assert_true(c.dir == 1.0);
    br_circle_use_path(&c, 2.0 * th.radius_m, 0.0, 1); /* the thesis's feed on twice the radius */
    assert_true(c.radius_m == 2.0 * th.radius_m && c.period_s == 2.0 * th.period_s && c.duration_s == c.period_s);
    assert_true(c.dir == -1.0);
    assert_near(br_circle_feed_mps(&c), br_circle_feed_mps(&th), 1e-18);
    c = th;
    br_circle_use_path(&c, 0.0, 0.005, 0); /* 300 mm/min on the thesis's radius */
    assert_near(c.period_s, 2.0 * 3.14159265358979323846 * th.radius_m / 0.005, 1e-15);
    assert_near(br_circle_feed_mps(&c), 0.005, 1e-15);
    assert_true(c.duration_s == c.period_s && c.radius_m == th.radius_m);
    /* both directions on a short circle: the same y, x mirrored, a similar contour error */
    br_circle_result_t r[2];
    refs_t g[2] = {{{0.01, 0.03, 0.05}, {{0}}}, {{0.01, 0.03, 0.05}, {{0}}}};
    for (int d = 0; d < 2; d++) {
        c = th;
        br_circle_use_path(&c, 0.0, 0.005, d);
        assert_int_equal(br_circle_run(&c, refs_sink, &g[d], &r[d]), 0);
    }
    for (int i = 0; i < 3; i++) {
        assert_true(g[0].ref_m[i][0] > 0.0); /* clockwise from (0, A): x > 0 in the first half turn (T = 0.126 s) */
        assert_near(g[1].ref_m[i][0], -g[0].ref_m[i][0], 1e-15);
        assert_near(g[1].ref_m[i][1], g[0].ref_m[i][1], 1e-15);
    }
    print_message("300 mm/min: contour RMS %.3e m clockwise, %.3e m counter-clockwise\n", r[0].contour_rms_m,
                  r[1].contour_rms_m);
    assert_true(fabs(r[1].contour_rms_m / r[0].contour_rms_m - 1.0) < 0.2);
}

/* A fault stops the run safe: the UKF on the nominal model of a plant with a
 * 3 ms actuator dead time and the delay identification off loses lock (at a
 * 50-sigma gate its estimate left what the actuator can exert; at 8 sigma it
 * re-anchored for ever), or, with the machine's external-force state, a
 * guard latches, and the firmware zeroes the drive instead of compensating
 * with it (it once ran on with an 11064-outlier, 0.17 mm contour error). */
static void test_diverged_estimate_stops_safe(void **st)
{
    (void)st;
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    c.plant.delay_s = 3.0e-3;
    /* the estimator as it was before the delay identification, which finds the dead time
     * (test_delay_identified below) */
    br_circle_use_delay_id(&c, 0);
    br_circle_result_t r;
#ifdef BR_TEST_THESIS_MACHINE
    /* measured on the thesis's machine (docs/diagnose-control.md) */
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 1);
    assert_true(r.fault_status < 0);
    assert_true(r.fault_t_s > 0.0 && r.fault_t_s < c.duration_s);
    print_message("UKF on the nominal model, 3 ms plant delay: fault %d (cause %d) at %.3f s, contour RMS before it %.3g m\n",
                  r.fault_status, r.fault_cause, r.fault_t_s, r.contour_rms_m);
    if (c.ukf.load.max_N > 0.0f) {
        /* with the machine's external-force state the delay's misfit is re-acquired as a
         * load and the lock monitor sees too few outliers: a motion guard or the estimator's
         * own failure latches (measured: ENC_FROZEN at 0.123 s; docs/modules/ukf.md, "On in
         * the reference machine"). Still a latched stop, within 0.25 s */
        assert_true(r.fault_cause == BR_APP_FAULT_LOST_LOCK || r.fault_cause == BR_APP_FAULT_ENC_FROZEN ||
                    r.fault_cause == BR_APP_FAULT_ESTIMATOR || r.fault_cause == BR_APP_FAULT_SPEED ||
                    r.fault_cause == BR_APP_FAULT_FOLLOWING);
        assert_true(r.fault_t_s < 0.25);
    } else {
        /* LOST_LOCK: the position is trusted, the axis brakes on the ramp (test_app:
         * test_lost_lock_latches), so the fault period's duty is the ramp's */
        assert_int_equal(r.fault_cause, BR_APP_FAULT_LOST_LOCK);
    }
    /* the shipped UKF gate rejects a 10-sigma jump (test_ukf: test_outlier) */
    assert_true(BR_EST_UKF_OUTLIER_SIGMA < 10.0);
    /* a gate tight enough to reject a 10-sigma jump: the filter no longer runs
     * away, it re-anchors at most steps (once 2.3e-5 m of contour error for
     * the whole circle, 8201 outlier steps); the lock monitor stops it. The
     * thesis filter (its external-force state off): the gate's own effect */
    br_circle_cfg_t t = c;
    br_circle_use_ukf_load(&t, 0.0);
    t.ukf.est.outlier_sigma = 8.0f;
    assert_int_equal(br_circle_run(&t, NULL, NULL, &r), 1);
    print_message("  at an 8-sigma gate: fault cause %d at %.3f s after %d outlier steps, duty %g\n", r.fault_cause,
                  r.fault_t_s, r.outlier_steps, r.fault_duty);
    assert_int_equal(r.fault_status, BR_E_FAULT);
    /* the fault period's duty is the braking ramp's (stopping: study_faults) */
    assert_int_equal(r.fault_cause, BR_APP_FAULT_LOST_LOCK);
    assert_true(r.fault_t_s < 0.5);
    /* the same gate without the dead time runs the whole circle, no outlier */
    t.plant.delay_s = 0.0;
    assert_int_equal(br_circle_run(&t, NULL, NULL, &r), 0);
    assert_int_equal(r.outlier_steps, 0);
    /* so does the PF without its shared external force, which at its 30-sigma
     * gate re-anchored for ever on this plant (6393 outlier steps, 3.5e-6 m) */
    br_circle_cfg_t p = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    p.plant.delay_s = 3.0e-3;
    br_circle_use_delay_id(&p, 0);
    br_circle_cfg_t pl = p;
    p.pf.load = (br_pf_load_t){0.0f, 0.0f};
    assert_int_equal(br_circle_run(&p, NULL, NULL, &r), 1);
    print_message("PF on the nominal model, 3 ms plant delay: fault cause %d at %.3f s after %d outlier steps\n",
                  r.fault_cause, r.fault_t_s, r.outlier_steps);
    /* the fault period's duty is the braking ramp's (stopping: study_faults) */
    assert_int_equal(r.fault_cause, BR_APP_FAULT_LOST_LOCK);
    /* with it (the machine's), the delay's misfit is re-acquired as a load and the lock
     * monitor sees too few outliers: the loop runs away until a motion guard latches
     * (measured: FAULT SPEED at 1.128 s; docs/modules/pf.md, "On in
     * the reference machine"). Still a latched stop, never a run to the end */
    if (pl.pf.load.max_N > 0.0f) {
        assert_int_equal(br_circle_run(&pl, NULL, NULL, &r), 1);
        print_message("  with its shared external force: fault cause %d at %.3f s, contour RMS before it %.3g m\n",
                      r.fault_cause, r.fault_t_s, r.contour_rms_m);
        assert_int_equal(r.fault_status, BR_E_FAULT);
        assert_true(r.fault_cause == BR_APP_FAULT_LOST_LOCK || r.fault_cause == BR_APP_FAULT_SPEED ||
                    r.fault_cause == BR_APP_FAULT_FOLLOWING);
    }
#endif
    /* with the delay in its own model the same estimator runs the whole circle */
    c.ukf.est.model.causes.delay_s = 3.0e-3f;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 0);
    assert_int_equal(r.fault_status, 0);
}

/* The delay identification (docs/modules/dlyid.md): on the plants above, with
 * the machine's identification, both estimators find the dead time and run
 * the whole circle: no fault, outliers on fewer than 1 % of the axis-periods
 * and a contour error below H-inf only's (the robustness study's lock rule),
 * within the thesis's own PF ratio (measured 0.017 to 0.109 on the reference
 * machine, docs/modules/dlyid.md). */
static void test_delay_identified(void **st)
{
    (void)st;
    static const double delays_s[] = {1.0e-3, 2.0e-3, 3.0e-3};
    static const br_circle_ctrl_t ests[] = {BR_CTRL_HINF_UKF, BR_CTRL_HINF_PF};
    for (size_t i = 0; i < sizeof delays_s / sizeof delays_s[0]; i++) {
        br_circle_cfg_t h = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
        h.plant.delay_s = delays_s[i];
        br_circle_result_t rh, r;
        assert_int_equal(br_circle_run(&h, NULL, NULL, &rh), 0);
        for (size_t e = 0; e < 2; e++) {
            br_circle_cfg_t c = br_circle_cfg_thesis(ests[e]);
            assert_true(c.ukf.est.delay_id.n_cand >= 2u && c.pf.est.delay_id.n_cand >= 2u);
            c.plant.delay_s = delays_s[i];
            assert_int_equal(br_circle_run(&c, NULL, NULL, &r), 0);
            print_message("%s, %.0f ms plant delay, identified: contour RMS %.3g m = %.3f of H-inf only, "
                          "%d outlier steps of %ld\n", e == 0 ? "UKF" : "PF", delays_s[i] * 1e3, r.contour_rms_m,
                          r.contour_rms_m / rh.contour_rms_m, r.outlier_steps, 2 * r.n_samples);
            assert_int_equal(r.fault_status, 0);
            assert_true((double)r.outlier_steps < 0.01 * 2.0 * (double)r.n_samples);
            assert_true(r.contour_rms_m < rh.contour_rms_m);
            /* and the thesis's own H-inf + PF ratio on its hardware (4.0e-7 / 2.4e-6 m,
             * test_pf_beats_thesis_ratio) without the dead time in the model */
            assert_true(r.contour_rms_m / rh.contour_rms_m <= 0.4 / 2.4);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_diverged_estimate_stops_safe),
                                       cmocka_unit_test(test_hinf_only_quadrant_glitches),
                                       cmocka_unit_test(test_motionless_axis_is_no_result),
                                       cmocka_unit_test(test_same_gains_at_pf_period),
                                       cmocka_unit_test(test_ukf_beats_thesis_ratio),
                                       cmocka_unit_test(test_pf_beats_thesis_ratio),
                                       cmocka_unit_test(test_rejects_bad_experiment),
                                       cmocka_unit_test(test_circle_path),
                                       cmocka_unit_test(test_delay_identified)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
