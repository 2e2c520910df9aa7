/* SPDX-License-Identifier: Apache-2.0 */
/* The application module: configuration guards, the latched faults, the
 * estimator interface, and that each estimator kind runs the same period as
 * the filter and the controller stepped by hand. */
#include "br_test.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"

typedef struct {
    int32_t counts;
    float duty;
    br_status_t enc_st; /* what encoder_read returns (it writes counts on BR_OK only) */
    br_status_t pwm_st; /* what pwm_write returns */
    int on;             /* outputs enabled (pwm_enable / pwm_disable) */
    int disables;
} fake_t;

static br_status_t fake_enc(void *ctx, int32_t *c)
{
    fake_t *f = ctx;
    if (f->enc_st == BR_OK) {
        *c = f->counts;
    }
    return f->enc_st;
}
static br_status_t fake_pwm(void *ctx, float d)
{
    ((fake_t *)ctx)->duty = d;
    return ((fake_t *)ctx)->pwm_st;
}
static br_status_t fake_disable(void *ctx)
{
    fake_t *f = ctx;
    f->on = 0;
    f->disables++;
    return BR_OK;
}
static br_status_t fake_enable(void *ctx)
{
    ((fake_t *)ctx)->on = 1;
    return BR_OK;
}

/* guards of the tests: 100 counts per period, 3 held reads, lost lock at 3
 * outlier steps within 10 periods; drive protections out of the way */
#define GUARD {100u, 3u, 10u, 2u}
#define MOTION BR_TEST_WIDE_MOTION
static br_status_t fake_tick(void *ctx, uint32_t *t)
{
    (void)ctx;
    *t = 0;
    return BR_OK;
}

static br_ctrl_cfg_t ctrl_cfg(void)
{
    br_ctrl_cfg_t c = {{-0.5f, -0.01f, -10.0f}, 1e-3f, 0.64f, 0.64f, 6.0e-6f, 1.27e-3f};
    return c;
}

static br_status_t const_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    *F_hat_N = *(const float *)ctx;
    return BR_OK;
}

static void test_init_guards(void **st)
{
    (void)st;
    fake_t f = {0, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    br_ctrl_cfg_t k = ctrl_cfg();
    br_pf_cfg_t pfc = br_circle_pf_cfg_tuned(1e-3f);
    br_ukf_cfg_t ukfc = br_circle_ukf_cfg_tuned(1e-3f);
    br_pf_t *pf = calloc(1, sizeof *pf);
    br_ukf_t ukf;
    assert_non_null(pf);
    const br_app_mem_t mem = {pf, &ukf}, no_pf = {NULL, &ukf}, no_ukf = {pf, NULL};
    const br_ref_t r = {0, 0.0f, 0.0f};
    br_app_t app;
    br_est_t est;

    br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL, GUARD, MOTION};
    assert_int_equal(br_app_init(NULL, &c, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, NULL, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, &c, NULL, NULL), BR_E_NULL);
    /* every HAL function the period calls */
    br_hal_t h2 = hal;
    h2.encoder_read = NULL;
    assert_int_equal(br_app_init(&app, &c, &h2, NULL), BR_E_NULL);
    h2 = hal;
    h2.pwm_write = NULL;
    assert_int_equal(br_app_init(&app, &c, &h2, NULL), BR_E_NULL);
    h2 = hal;
    h2.tick_wait = NULL;
    assert_int_equal(br_app_init(&app, &c, &h2, NULL), BR_E_NULL);
    assert_int_equal(br_app_est_init(&c, NULL, NULL), BR_E_NULL);
    c.ctrl = NULL;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_NULL);
    c.ctrl = &k;
    c.est = (br_app_est_kind_t)7;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    assert_int_equal(br_app_step(&app, &r), BR_E_STATE);
    assert_int_equal(br_app_step(NULL, &r), BR_E_NULL);

    /* PF: its configuration and its storage are required */
    c.est = BR_APP_EST_PF;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_NULL);
    c.pf = &pfc;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, &c, &hal, &no_pf), BR_E_NULL);
    /* at the controller's period only */
    pfc.est.model.dt_s = 1.5e-3f;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    pfc.est.model.dt_s = NAN;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    pfc.est.model.dt_s = 1e-3f;
    /* the filter's own guards are passed up */
    pfc.n_particles = 0u;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    assert_int_equal(br_app_step(&app, &r), BR_E_STATE);
    pfc.n_particles = 100u;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_OK);
    assert_int_equal(br_app_est_init(&c, &mem, &est), BR_OK);
    assert_ptr_equal(est.ctx, pf);
    assert_ptr_equal(est.step, br_pf_est_step);
    assert_ptr_equal(est.predict, br_pf_est_predict);
    assert_ptr_equal(est.reset, br_pf_est_reset);

    /* UKF: likewise */
    c.est = BR_APP_EST_UKF;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_NULL);
    c.ukf = &ukfc;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, &c, &hal, &no_ukf), BR_E_NULL);
    ukfc.est.model.dt_s = 2e-3f;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    ukfc.est.model.dt_s = 1e-3f;
    const float r_var = ukfc.est.r_var_rad2;
    ukfc.est.r_var_rad2 = -1.0f;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_E_PARAM);
    ukfc.est.r_var_rad2 = r_var;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_OK);

    /* an external estimator: the interface and its step are required */
    const float F = 1.0f;
    br_est_t ext = {(void *)&F, NULL, NULL, NULL};
    c.est = BR_APP_EST_EXTERN;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_NULL);
    c.ext = &ext;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_NULL);
    ext.step = const_est_step;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);

    /* the controller's guards are passed up */
    k.dt_s = 0.0f;
    c.est = BR_APP_EST_NONE;
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_E_PARAM);
    assert_int_equal(br_app_step(&app, &r), BR_E_STATE);
    free(pf);
}

static void test_none_is_hinf_only(void **st)
{
    (void)st;
    fake_t f = {1000, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    const br_ctrl_cfg_t k = ctrl_cfg();
    const br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL, GUARD, MOTION};
    br_app_t app;
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&app), BR_OK);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    BR_ASSERT_NEAR(f.duty, -0.5 * 1000 * 6.0e-6 / 0.64, 1e-7);
    BR_ASSERT_NEAR(app.F_hat_N, 0.0, 0.0);
}

static void test_extern_drives_compensation(void **st)
{
    (void)st;
    fake_t f = {0, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    const br_ctrl_cfg_t k = ctrl_cfg();
    const float F = 10.0f;
    const br_est_t ext = {(void *)&F, const_est_step, NULL, NULL};
    const br_app_cfg_t c = {&k, BR_APP_EST_EXTERN, NULL, NULL, &ext, GUARD, MOTION};
    br_app_t app;
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&app), BR_OK);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    /* zero error: the duty is the compensation alone, L F / tau_per_duty */
    BR_ASSERT_NEAR(f.duty, 1.27e-3 * 10.0 / 0.64, 1e-7);
}

/* An estimator behind the interface (EXTERN with predict and reset): a failed
 * read reaches its predict with the last torque, an arm its reset, whose
 * error keeps the application latched; no kind is read after init. */
typedef struct {
    int steps, predicts, resets;
    float u;
    br_status_t reset_st;
    br_meas_t y;
} iface_t;

static br_status_t iface_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    iface_t *e = ctx;
    e->y = *y;
    e->steps++;
    e->u = u_prev_Nm;
    *F_hat_N = 1.0f;
    return BR_OK;
}
static br_status_t iface_predict(void *ctx, float u_prev_Nm, float *F_hat_N)
{
    iface_t *e = ctx;
    e->predicts++;
    e->u = u_prev_Nm;
    *F_hat_N = 3.0f;
    return BR_OK;
}
static br_status_t iface_reset(void *ctx)
{
    iface_t *e = ctx;
    e->resets++;
    return e->reset_st;
}

static void test_estimator_interface(void **st)
{
    (void)st;
    fake_t f = {0, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, fake_disable, fake_enable};
    const br_ctrl_cfg_t k = ctrl_cfg();
    iface_t e = {0, 0, 0, 0.0f, BR_OK, {0, 0.0f}};
    const br_est_t ext = {&e, iface_step, iface_predict, iface_reset};
    const br_app_cfg_t c = {&k, BR_APP_EST_EXTERN, NULL, NULL, &ext, GUARD, MOTION};
    br_app_t app;
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_int_equal(e.resets, 0);
    assert_int_equal(br_app_arm(&app), BR_OK);
    assert_int_equal(e.resets, 1);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_int_equal(e.steps, 1);
    const float tau = app.last.tau_Nm;
    assert_true(tau != 0.0f);
    f.enc_st = BR_E_INPUT;
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_int_equal(e.predicts, 1);
    assert_true(e.u == tau);
    assert_true(app.F_hat_N == 3.0f);
    f.enc_st = BR_OK;
    const float tau2 = app.last.tau_Nm;
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_int_equal(e.steps, 2);
    assert_int_equal(e.predicts, 1);
    assert_true(e.u == tau2); /* the step sees the torque of the last period */
    assert_true(e.y.counts == 0 && e.y.frac == 0.5f); /* the count's centre */
    /* a reset that fails: the arm fails and the fault stays */
    assert_int_equal(br_app_fault(&app, BR_APP_FAULT_DEADLINE), BR_E_FAULT);
    e.reset_st = BR_E_PARAM;
    assert_int_equal(br_app_arm(&app), BR_E_PARAM);
    assert_int_equal(app.fault, BR_APP_FAULT_DEADLINE);
    assert_int_equal(br_app_step(&app, &r), BR_E_FAULT);
    e.reset_st = BR_OK;
    assert_int_equal(br_app_arm(&app), BR_OK);
    assert_int_equal(e.resets, 3);
}

/* The same periods through br_app (kind) and written out by hand (the
 * filter's step with the count's centre and the last torque, then the
 * controller with its estimate): bit-identical estimates and duties. */
static void run_against_hand(br_app_est_kind_t kind)
{
    fake_t fa = {0, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t ha = {&fa, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    const br_ctrl_cfg_t k = ctrl_cfg();
    br_pf_cfg_t pfc = br_circle_pf_cfg_tuned(1e-3f);
    pfc.n_particles = 200u;
    const br_ukf_cfg_t ukfc = br_circle_ukf_cfg_tuned(1e-3f);
    br_pf_t *pf = calloc(2, sizeof *pf);
    br_ukf_t *ukf = calloc(2, sizeof *ukf);
    assert_non_null(pf);
    assert_non_null(ukf);
    br_app_cfg_t c = {&k, kind, &pfc, &ukfc, NULL, GUARD, MOTION};
    /* the jumpy counts below make the filters reject measurements: the lock
     * monitor (not part of the period written out here) must not trip */
    c.guard.lock_max_outliers = c.guard.lock_window_periods - 1u;
    const br_app_mem_t mem = {&pf[0], &ukf[0]};
    br_app_t app;
    assert_int_equal(br_app_init(&app, &c, &ha, &mem), BR_OK);
    assert_int_equal(br_app_arm(&app), BR_OK); /* re-initialises the filter: the same as init */
    if (kind == BR_APP_EST_PF) {
        assert_int_equal(br_pf_init(&pf[1], &pfc), BR_OK);
    } else {
        assert_int_equal(br_ukf_init(&ukf[1], &ukfc), BR_OK);
    }
    br_ctrl_t ctrl;
    assert_int_equal(br_ctrl_init(&ctrl, &k), BR_OK);
    br_ctrl_out_t out = {0};
    float F = 0.0f;
    for (int i = 0; i < 50; i++) {
        const br_ref_t r = {i * 3, 0.25f, 0.5f};
        fa.counts = i * 3 + (i % 4) - 1;
        const br_status_t sa = br_app_step(&app, &r);
        const br_meas_t y = {fa.counts, 0.5f};
        const br_status_t sb = (kind == BR_APP_EST_PF) ? br_pf_est_step(&pf[1], &y, out.tau_Nm, &F)
                                                       : br_ukf_est_step(&ukf[1], &y, out.tau_Nm, &F);
        assert_int_equal(sa, sb);
        assert_false(BR_FAILED(sa));
        const br_ctrl_in_t in = {fa.counts, r.ref_counts, r.ref_frac_counts, r.ref_omega_radps, F};
        assert_int_equal(br_ctrl_step(&ctrl, &in, &out), BR_OK);
        assert_memory_equal(&app.F_hat_N, &F, sizeof(float));
        assert_memory_equal(&fa.duty, &out.duty, sizeof(float));
    }
    assert_true(app.F_hat_N != 0.0f);
    free(pf);
    free(ukf);
}

static void test_pf_as_wired_by_hand(void **st)
{
    (void)st;
    run_against_hand(BR_APP_EST_PF);
}

static void test_ukf_as_wired_by_hand(void **st)
{
    (void)st;
    run_against_hand(BR_APP_EST_UKF);
}

/* ---- fail-safe: latched faults (docs/reliability.md) ----------------------- */


typedef struct {
    fake_t f;
    br_hal_t hal;
    br_ctrl_cfg_t k;
    br_est_t ext;
    br_app_cfg_t c;
    br_app_t app;
} rig_t;

static br_status_t bad_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    *F_hat_N = 0.0f;
    return *(const br_status_t *)ctx;
}

static br_status_t est_status = BR_OK;

/* armed NONE application (or EXTERN with bad_est_step) at counts 0 */
static void rig_init(rig_t *g, int ext)
{
    memset(g, 0, sizeof *g);
    g->hal = (br_hal_t){&g->f, fake_enc, fake_pwm, fake_tick, fake_disable, fake_enable};
    g->k = ctrl_cfg();
    g->ext = (br_est_t){&est_status, bad_est_step, NULL, NULL};
    est_status = BR_OK;
    g->c = (br_app_cfg_t){&g->k, ext ? BR_APP_EST_EXTERN : BR_APP_EST_NONE, NULL, NULL, &g->ext, GUARD, MOTION};
    assert_int_equal(br_app_init(&g->app, &g->c, &g->hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&g->app), BR_OK);
    assert_true(g->f.on);
}

/* the latched state: every step writes 0, outputs off, BR_E_FAULT, cause kept */
static void assert_latched(rig_t *g, br_app_fault_t cause)
{
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(g->app.fault, cause);
    assert_false(g->f.on);
    assert_true(g->f.duty == 0.0f);
    for (int i = 0; i < 3; i++) {
        g->f.duty = 0.3f;
        g->f.enc_st = BR_OK;
        assert_int_equal(br_app_step(&g->app, &r), BR_E_FAULT);
        assert_true(g->f.duty == 0.0f);
        assert_false(g->f.on);
        assert_int_equal(g->app.fault, cause);
    }
}

/* a fault where the position is trusted: the braking ramp (outputs on, the
 * controller following it) for at most `periods` periods, then outputs off
 * and latched */
static void assert_brakes_then_off(rig_t *g, br_app_fault_t cause, int periods)
{
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(g->app.fault, cause);
    assert_int_equal(g->app.stop, BR_APP_STOP_BRAKING);
    assert_true(g->f.on);
    int n = 0;
    while (g->app.stop == BR_APP_STOP_BRAKING && n <= periods) {
        assert_true(g->f.on);
        assert_int_equal(br_app_step(&g->app, &r), BR_E_FAULT);
        n++;
    }
    assert_true(n <= periods);
    assert_latched(g, cause);
}

/* a fault where the position is not trusted but the last speed v (counts per
 * period) is: the open-loop brake (outputs on, a duty against v, no encoder
 * read) for the periods v takes to stop at max_accel, then outputs off and
 * latched; at v = 0 off at once */
static void assert_open_brakes_then_off(rig_t *g, br_app_fault_t cause, float v)
{
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(g->app.fault, cause);
    const int periods = (int)ceilf(fabsf(v) / g->app.lim_amax);
    /* a speed to brake: the brake runs (it took the period of the latch) */
    assert_int_equal(periods > 0, g->app.stop == BR_APP_STOP_OPEN);
    int n = 0;
    while (g->app.stop == BR_APP_STOP_OPEN && n <= periods) {
        assert_true(g->f.on);
        assert_true(v > 0.0f ? g->f.duty < 0.0f : g->f.duty > 0.0f);
        g->f.enc_st = BR_E_INPUT; /* never read */
        assert_int_equal(br_app_step(&g->app, &r), BR_E_FAULT);
        n++;
    }
    assert_true(n <= periods);
    assert_latched(g, cause);
}

static void test_outputs_off_until_armed(void **st)
{
    (void)st;
    rig_t g;
    memset(&g, 0, sizeof g);
    g.hal = (br_hal_t){&g.f, fake_enc, fake_pwm, fake_tick, fake_disable, fake_enable};
    g.k = ctrl_cfg();
    g.c = (br_app_cfg_t){&g.k, BR_APP_EST_NONE, NULL, NULL, NULL, GUARD, MOTION};
    const br_ref_t r = {0, 0.0f, 0.0f};
    g.f.counts = 1000;
    g.f.on = 1;
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
    assert_int_equal(g.app.fault, BR_APP_FAULT_DISARMED);
    assert_int_equal(g.f.disables, 1);
    assert_latched(&g, BR_APP_FAULT_DISARMED);
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    assert_true(g.f.on);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    assert_true(g.f.duty != 0.0f);
    assert_int_equal(br_app_arm(NULL), BR_E_NULL);
}

static void test_ctrl_input_latches_until_rearmed(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    g.f.counts = 1000;
    const br_ref_t r = {0, 0.0f, 0.0f}, bad = {0, NAN, 0.0f};
    for (int i = 0; i < 5; i++) {
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    }
    assert_true(g.app.ctrl.eps_rads != 0.0f);
    assert_int_equal(br_app_step(&g.app, &bad), BR_E_FAULT);
    /* the position is trusted: the braking ramp, from standstill only its settle */
    assert_brakes_then_off(&g, BR_APP_FAULT_CTRL_INPUT, (int)BR_APP_BRAKE_SETTLE_PERIODS);
    /* a good reference does not clear it; only the arm does, restarting the integral */
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    assert_int_equal(g.app.fault, BR_APP_FAULT_NONE);
    assert_true(g.app.ctrl.eps_rads == 0.0f);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    assert_true(g.f.duty < 0.0f && g.f.on);
}

static void test_ctrl_state_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    g.app.ctrl.eps_rads = INFINITY; /* a corrupted integrator */
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_latched(&g, BR_APP_FAULT_CTRL_STATE);
}

static void test_estimator_error_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 1);
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    est_status = BR_W_OUTLIER; /* a warning: control goes on */
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_true(g.f.on);
    est_status = BR_E_NUMERIC;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    /* at rest: the ramp is the settle alone */
    assert_brakes_then_off(&g, BR_APP_FAULT_ESTIMATOR, (int)BR_APP_BRAKE_SETTLE_PERIODS);
}

/* The lock monitor: an estimator that keeps rejecting the measurement (the
 * UKF re-anchoring for ever on an axis with an unmodelled dead time) stops
 * the axis; outliers as sparse as the limit allows never do. */
static void test_lost_lock_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 1);
    const br_ref_t r = {0, 0.0f, 0.0f};
    /* 2 outliers in every 10 periods (the limit) for 200 periods: runs on */
    for (int k = 0; k < 200; k++) {
        est_status = (k % 5 == 0) ? BR_W_OUTLIER : BR_OK;
        assert_int_equal(br_app_step(&g.app, &r), est_status);
        assert_int_equal(g.app.fault, BR_APP_FAULT_NONE);
        assert_true(g.f.on);
    }
    /* the pattern's next outlier (period 200: 195 and 200 in the window), then
     * one more: the third of the last 10 periods */
    est_status = BR_W_OUTLIER;
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_brakes_then_off(&g, BR_APP_FAULT_LOST_LOCK, (int)BR_APP_BRAKE_SETTLE_PERIODS);
    /* a good estimate does not clear it; the arm does, with an empty window */
    est_status = BR_OK;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    est_status = BR_W_OUTLIER;
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    /* outliers for ever (re-anchoring at every step): the third faults */
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_brakes_then_off(&g, BR_APP_FAULT_LOST_LOCK, (int)BR_APP_BRAKE_SETTLE_PERIODS);
    /* predict-only periods (failed reads) leave the window as clean periods */
    rig_init(&g, 1);
    est_status = BR_W_OUTLIER;
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    est_status = BR_OK;
    for (int k = 0; k < 8; k++) {
        g.f.enc_st = (k % 2 == 0) ? BR_E_INPUT : BR_OK;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    }
    g.f.enc_st = BR_OK;
    est_status = BR_W_OUTLIER; /* the first two have left the window */
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_int_equal(br_app_step(&g.app, &r), BR_W_OUTLIER);
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_LOST_LOCK);
}

static void test_hal_error_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    const br_ref_t r = {0, 0.0f, 0.0f};
    g.f.pwm_st = BR_E_INPUT;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_HAL);
    assert_false(g.f.on);
    assert_true(g.f.duty == 0.0f);
}

static void test_encoder_jump_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    const br_ref_t r = {0, 0.0f, 0.0f};
    /* across zero both ways, at the limit: fine (the int32 wrap lies beyond
     * any stroke's soft limits: test_port, test_stm32h7 test the wrap) */
    g.f.counts = -40;
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    g.f.counts = 60; /* +100 */
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    g.f.counts = -40; /* -100 back */
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    /* one count above the axis's maximum speed: a glitch, not a count */
    g.f.counts -= 101;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    /* braked on open loop against the last good speed, -100 counts a period */
    assert_open_brakes_then_off(&g, BR_APP_FAULT_ENC_JUMP, -100.0f);
    /* INT32_MIN apart (|delta| 2^31) as well */
    rig_init(&g, 0);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    g.f.counts = INT32_MIN;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_JUMP);
}

/* k held reads, then a good one at delta: the step's status */
static br_status_t held_then(rig_t *g, uint32_t k, int32_t delta)
{
    const br_ref_t r = {0, 0.0f, 0.0f};
    rig_init(g, 0);
    assert_int_equal(br_app_step(&g->app, &r), BR_OK);
    g->f.enc_st = BR_E_INPUT;
    for (uint32_t i = 0u; i < k; i++) {
        assert_int_equal(br_app_step(&g->app, &r), BR_OK);
    }
    g->f.enc_st = BR_OK;
    g->f.counts += delta;
    return br_app_step(&g->app, &r);
}

/* After k held reads the first good one spans k + 1 periods: at the speed limit (100
 * counts a period) the axis moved 100 (k + 1) counts, which is no jump; one count more is.
 * (The limit of one period latched ENC_JUMP after a single held read at speed.) */
static void test_encoder_jump_after_held_reads(void **st)
{
    (void)st;
    rig_t g;
    for (uint32_t k = 1u; k <= 3u; k++) {
        assert_int_equal(held_then(&g, k, (int32_t)(100u * (k + 1u))), BR_OK);
        assert_int_equal(held_then(&g, k, -(int32_t)(100u * (k + 1u))), BR_OK);
        assert_int_equal(held_then(&g, k, (int32_t)(100u * (k + 1u) + 1u)), BR_E_FAULT);
        assert_latched(&g, BR_APP_FAULT_ENC_JUMP);
    }
    /* and a good read right after a good one is held to one period again */
    assert_int_equal(held_then(&g, 0u, 101), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_JUMP);
}

/* Held reads at speed: the controller sees the last count moved on at the
 * speed measured then, so with the reference moving on at that speed its
 * duty is the one of a good read (held at the count itself the controller
 * would see a following error grow by the speed each period and push). */
static void test_held_reads_extrapolate(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    const int32_t v = 1000; /* counts per period: the guard's limit raised to let it through */
    g.app.guard.enc_max_delta_counts = 4000u;
    br_ref_t r = {0, 0.5f, (float)v * g.k.rad_per_count / g.k.dt_s};
    for (int i = 0; i < 50; i++) {
        g.f.counts += v;
        r.ref_counts = g.f.counts;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    }
    const float d0 = g.f.duty;
    g.f.enc_st = BR_E_INPUT;
    for (int i = 0; i < 3; i++) {
        r.ref_counts += v;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
        /* the duty of a controller on the reference: as before the hold */
        assert_true(fabsf(g.f.duty - d0) <= 1e-3f);
    }
    /* the fourth failed read: ENC_STALE, braked on open loop against the
     * last good speed */
    r.ref_counts += v;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_open_brakes_then_off(&g, BR_APP_FAULT_ENC_STALE, (float)v);
}

static void test_encoder_stale_holds_then_latches(void **st)
{
    (void)st;
    fake_t f = {0, 0.0f, BR_OK, BR_OK, 0, 0};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, fake_disable, fake_enable};
    const br_ctrl_cfg_t k = ctrl_cfg();
    br_pf_cfg_t pfc = br_circle_pf_cfg_tuned(1e-3f);
    pfc.n_particles = 100u;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    const br_app_cfg_t c = {&k, BR_APP_EST_PF, &pfc, NULL, NULL, GUARD, MOTION};
    const br_app_mem_t mem = {pf, NULL};
    br_app_t app;
    assert_int_equal(br_app_init(&app, &c, &hal, &mem), BR_OK);
    assert_int_equal(br_app_arm(&app), BR_OK);
    const br_ref_t r = {0, 0.0f, 0.0f};
    f.counts = 50;
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    const float duty0 = f.duty;
    /* three failed reads: the last count is held, the PF predicts only */
    f.enc_st = BR_E_INPUT;
    for (uint32_t i = 1u; i <= 3u; i++) {
        assert_int_equal(br_app_step(&app, &r), BR_OK);
        assert_int_equal(pf->n_predicted, i);
        assert_true(f.on);
        assert_true(f.duty < 0.0f && duty0 < 0.0f); /* still pushing towards the reference */
    }
    /* a good read resets the count of failed reads */
    f.enc_st = BR_OK;
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_int_equal(pf->n_predicted, 0u);
    f.enc_st = BR_E_INPUT;
    for (int i = 0; i < 3; i++) {
        assert_int_equal(br_app_step(&app, &r), BR_OK);
    }
    /* the fourth in a row: timeout */
    assert_int_equal(br_app_step(&app, &r), BR_E_FAULT);
    assert_int_equal(app.fault, BR_APP_FAULT_ENC_STALE);
    assert_false(f.on);
    assert_true(f.duty == 0.0f);
    /* re-arm: the PF is primed again at the next measurement; a failed first
     * read writes duty 0 without turning the outputs off (nothing latched) */
    assert_int_equal(br_app_arm(&app), BR_OK);
    f.duty = 0.3f;
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_true(f.duty == 0.0f);
    assert_true(f.on);
    f.enc_st = BR_OK;
    assert_int_equal(pf->primed, 0);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    assert_int_equal(pf->primed, 1);
    free(pf);
}

/* the rig with the machine's drive protections (machine file) */
static void rig_machine(rig_t *g)
{
    rig_init(g, 0);
    g->c.motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE);
    g->c.guard = br_app_guard_cfg(1e-3f, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F);
    assert_int_equal(br_app_init(&g->app, &g->c, &g->hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&g->app), BR_OK);
}

/* The stuck encoder, from the model: a counter that stops while the axis
 * moves latches at the first still period; a still counter under a steady
 * force (a load held) never does; a force that grows beyond what stiction
 * holds without a count does, before the following error. */
static void test_encoder_frozen_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_machine(&g);
    br_ref_t r = {0, 0.5f, 0.0f};
    /* moving at 200 counts a period, the reference on the count */
    for (int i = 0; i < 20; i++) {
        g.f.counts += 200;
        r.ref_counts = g.f.counts;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    }
    /* the counter stops, the reference goes on: the model predicts 200 counts */
    r.ref_counts += 200;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    /* braked on open loop against the model's speed (+: 200 counts a period
     * less what friction and the drive take in the still period) */
    assert_true(g.app.v_pred > 0.0f);
    assert_open_brakes_then_off(&g, BR_APP_FAULT_ENC_FROZEN, g.app.v_pred);
    /* still, reference on the count, 2000 periods: never */
    rig_machine(&g);
    const br_ref_t still = {0, 0.5f, 0.0f};
    for (int i = 0; i < 2000; i++) {
        assert_int_equal(br_app_step(&g.app, &still), BR_OK);
    }
    /* a reference the axis should follow, a counter that never moves: the
     * drive's force grows past the stiction band: ENC_FROZEN, not FOLLOWING */
    rig_machine(&g);
    const br_ref_t far = {100000, 0.0f, 0.0f};
    br_status_t s = BR_OK;
    for (int i = 0; i < 1000 && s == BR_OK; i++) {
        s = br_app_step(&g.app, &far);
    }
    assert_int_equal(s, BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_FROZEN);
    if (g.app.stop == BR_APP_STOP_OPEN) {
        assert_open_brakes_then_off(&g, BR_APP_FAULT_ENC_FROZEN, g.app.v_pred);
    }
    assert_latched(&g, BR_APP_FAULT_ENC_FROZEN);
}

/* the rig with the machine's drive protections on an encoder so coarse for
 * its period that the friction band plus the quantization allowance (2 k,
 * k = mass / (counts_per_m dt^2) the force of one count per period^2) is
 * COARSE_SHARE of the actuator's force, as on the fleet's axis 3 (0.096 um
 * counts at 0.27 ms: k = 140 N, 36 + 280 N of 659 N); the controller on the
 * same counts */
#define COARSE_SHARE 0.5f
static void rig_coarse(rig_t *g)
{
    rig_init(g, 0);
    br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t fine = br_app_motion_cfg(&mm);
    const float dt = g->k.dt_s, F_max = g->k.tau_max_Nm / g->k.lead_mprad;
    const float k_N = (COARSE_SHARE * F_max - fine.stuck_band_N) / BR_APP_STUCK_QUANT_ACCEL;
    /* counts_per_m = mass / (k dt^2) */
    const float cpm = fine.mass_kg / (k_N * dt * dt);
    mm.rad_per_count = 1.0f / (mm.lead_mprad * cpm);
    g->k.rad_per_count = mm.rad_per_count;
    g->c.motion = br_app_motion_cfg(&mm);
    g->c.guard = br_app_guard_cfg(dt, mm.max_speed_mps * cpm);
    assert_int_equal(br_app_init(&g->app, &g->c, &g->hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&g->app), BR_OK);
    assert_float_equal(g->app.mot_k_m, k_N, 1e-3f * k_N);
    /* one count per period^2 is more than the band: the edge below matters */
    assert_true(k_N > g->app.motion.stuck_band_N);
}

/* The stuck-encoder model on a coarse count (rig_coarse): an axis held on a
 * count's edge reads the count and its neighbour by turns without moving
 * (the fleet's axis 3 latched ENC_FROZEN 1.4 ms into every run that way:
 * -1, +1, then still, F_hold taken 280 N off); the quantization allowance
 * keeps it running. A counter that never moves under a reference far away
 * still latches ENC_FROZEN, and one that stops while the axis moves at the
 * first still period. */
static void test_encoder_frozen_coarse_count(void **st)
{
    (void)st;
    rig_t g;
    rig_coarse(&g);
    /* on the edge of count 0: the count reads 0 or -1, the reference on it */
    static const int32_t edge[] = {0, -1, 0, 0, 0, -1, -1, 0, -1, 0, 0, 0, 0, -1};
    const br_ref_t on_edge = {0, 0.0f, 0.0f};
    for (int i = 0; i < 2000; i++) {
        g.f.counts = edge[i % (int)(sizeof edge / sizeof edge[0])];
        assert_int_equal(br_app_step(&g.app, &on_edge), BR_OK);
    }
    /* a counter that never moves, a reference far away: ENC_FROZEN once the
     * drive pushes past the band and the allowance */
    rig_coarse(&g);
    const br_ref_t far = {100000, 0.0f, 0.0f};
    br_status_t s = BR_OK;
    int n = 0;
    for (; n < 1000 && s == BR_OK; n++) {
        s = br_app_step(&g.app, &far);
    }
    assert_int_equal(s, BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_FROZEN);
    print_message("coarse count: far reference, ENC_FROZEN after %d periods\n", n);
    /* a run-up within the limiter's acceleration to 20 counts a period, the
     * reference on the axis; the counter stops: at the first still period
     * (the model: 20 counts less the band and the allowance) */
    rig_coarse(&g);
    double pos = 0.5, v = 0.0;
    for (int i = 0; i < 100; i++) {
        v = fmin(v + 0.9 * (double)g.app.lim_amax, 20.0);
        pos += v;
        g.f.counts = (int32_t)floor(pos);
        const br_ref_t mv = {g.f.counts, (float)(pos - floor(pos)), (float)(v * (double)g.k.rad_per_count / (double)g.k.dt_s)};
        assert_int_equal(br_app_step(&g.app, &mv), BR_OK);
    }
    pos += v;
    const br_ref_t ahead = {(int32_t)floor(pos), (float)(pos - floor(pos)), 0.0f};
    assert_int_equal(br_app_step(&g.app, &ahead), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_FROZEN);
}

/* The start the delay test runs, in periods (its frictionless axis is no
 * plant the rig's gains are made for: on the heavy machine it leaves the
 * following limit after about 100). */
#define DELAY_RUN_PERIODS 50

/* One period of an axis without friction whose force is the command `late`
 * periods late (u: the commands, u[j] issued at the start of period j, 0
 * before the first): x, v in counts, counts per period, a = F / k_m (the
 * model's own mass per count/period^2), exact for the force constant over
 * each part. */
static void delayed_axis_period(const float *u, int k, float late, float k_m, double *x, double *v)
{
    const int m = (int)late;
    const double f = (double)(late - (float)m);
    /* over [k, k + f) the command of period k - m - 1, then that of k - m */
    const double part[2] = {f, 1.0 - f};
    for (int h = 0; h < 2; h++) {
        const int j = k - m - 1 + h;
        const double a = (j >= 0) ? (double)u[j] / (double)k_m : 0.0;
        *x += *v * part[h] + 0.5 * a * part[h] * part[h];
        *v += a * part[h];
    }
}

/* A start from rest on an axis whose force comes `late` periods after the
 * command, the model told the delay model_delay_s: the reference leaves at
 * half the limiter's speed at once (the fleet's drawn circles start at their
 * feed). The periods run before a fault (DELAY_RUN_PERIODS: none), the count
 * reached in *moved. */
static int delayed_start_periods(float late, float model_delay_s, int32_t *moved)
{
    rig_t g;
    rig_init(&g, 0);
    br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    mm.delay_s = model_delay_s;
    g.c.motion = br_app_motion_cfg(&mm);
    g.c.guard = br_app_guard_cfg(g.k.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    const double vr = 0.5 * (double)g.app.lim_vmax;
    float u[DELAY_RUN_PERIODS];
    double x = 0.5, v = 0.0;
    int k = 0;
    for (; k < DELAY_RUN_PERIODS; k++) {
        g.f.counts = (int32_t)floor(x);
        const double pr = vr * (double)(k + 1);
        const br_ref_t r = {(int32_t)floor(pr), (float)(pr - floor(pr)),
                            (float)(vr * (double)g.k.rad_per_count / (double)g.k.dt_s)};
        if (br_app_step(&g.app, &r) != BR_OK) {
            assert_int_equal(g.app.fault, BR_APP_FAULT_ENC_FROZEN);
            break;
        }
        u[k] = g.app.last.tau_Nm / g.k.lead_mprad;
        delayed_axis_period(u, k, late, g.app.mot_k_m, &x, &v);
    }
    *moved = g.f.counts;
    return k;
}

/* The actuator delay in the stuck-encoder model (the fleet's drawn circles
 * latched ENC_FROZEN 0.4-3.2 ms in on healthy axes whose drive is 0.9-2.8
 * periods late). The count held still, the model without a delay latches
 * after n periods (the rig's force passing the band and the allowance); an
 * axis whose force comes n + 0.5 periods late keeps its count still that
 * long: the model told that delay runs the start and the axis moves, the
 * model without it (as before the fix) latches ENC_FROZEN. */
static void test_encoder_frozen_actuator_delay(void **st)
{
    (void)st;
    const float dt = ctrl_cfg().dt_s;
    int32_t moved = 0;
    /* a force later than the run: the count never moves */
    const int n = delayed_start_periods((float)DELAY_RUN_PERIODS, 0.0f, &moved);
    assert_true(n < DELAY_RUN_PERIODS - 10);
    const float late = (float)n + 0.5f;
    const int n_fix = delayed_start_periods(late, late * dt, &moved);
    print_message("still count: ENC_FROZEN after %d periods; force %.1f periods late, the delay in the model: "
                  "%d periods run, the axis at %d counts\n", n, (double)late, n_fix, (int)moved);
    assert_int_equal(n_fix, DELAY_RUN_PERIODS);
    assert_true(moved > 100);
    /* the model without the delay: ENC_FROZEN in the still start */
    assert_true(delayed_start_periods(late, 0.0f, &moved) < DELAY_RUN_PERIODS);
    assert_int_equal(moved, 0);
    /* a delay beyond the command history is refused */
    rig_t g;
    rig_init(&g, 0);
    br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    mm.delay_s = (float)BR_EST_DELAY_HIST * dt;
    g.c.motion = br_app_motion_cfg(&mm);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    /* a negative or non-finite delay: br_app_motion_cfg's all zero, and
     * refused by br_app_init when set in the configuration itself */
    mm.delay_s = -dt;
    assert_true(br_app_motion_cfg(&mm).counts_per_m == 0.0f);
    mm.delay_s = INFINITY;
    assert_true(br_app_motion_cfg(&mm).counts_per_m == 0.0f);
    mm.delay_s = 0.0f;
    g.c.motion = br_app_motion_cfg(&mm);
    g.c.motion.delay_s = -dt;
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    g.c.motion.delay_s = 0.0f;
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
}

/* The reference limiter: within the limits the reference passes bit for
 * bit; a step is limited (flagged) to the machine's speed and acceleration,
 * lands on the target and passes again; a target beyond the soft travel
 * limit is held at it. */
static void test_reference_limiter(void **st)
{
    (void)st;
    rig_t g;
    rig_machine(&g);
    /* the fake axis jumps to the reference without a force: no stuck model */
    g.app.motion.stuck_band_N = 1e9f;
    const br_app_t *a = &g.app;
    const float vmax = a->lim_vmax, amax = a->lim_amax;
    assert_true(vmax > 0.0f && amax > 0.0f);
    br_ref_t r = {0, 0.5f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    assert_false(a->ref_limited);
    /* a 10 mm step */
    const int32_t step = (int32_t)(0.01f * a->motion.counts_per_m);
    r.ref_counts = step;
    float prev_v = 0.0f, prev_p = 0.5f;
    int n = 0;
    while (n < 10000) {
        /* the axis follows the limited reference exactly */
        g.f.counts = a->lim_counts;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
        if (!a->ref_limited) break;
        const float p = (float)a->lim_counts + a->lim_frac;
        const float v = p - prev_p;
        assert_true(fabsf(v) <= vmax * 1.0001f);
        assert_true(fabsf(v - prev_v) <= amax * 1.0001f + 1.0f);
        /* never past the target by more than one period's change of speed
         * (the braking curve's float rounding) */
        assert_true(p <= (float)step + amax);
        prev_v = v;
        prev_p = p;
        n++;
    }
    assert_true(n > 1 && n < 10000);
    assert_true(a->n_ref_limited >= (uint32_t)n);
    print_message("10 mm step: limited for %d periods\n", n);
    /* a reference at half the speed limit from standstill: within the speed,
     * beyond the acceleration: limited */
    rig_machine(&g);
    g.app.motion.stuck_band_N = 1e9f;
    br_ref_t mv = {0, 0.5f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &mv), BR_OK);
    assert_false(a->ref_limited);
    mv.ref_counts += (int32_t)(0.5f * vmax);
    mv.ref_omega_radps = 0.5f * vmax * g.k.rad_per_count / g.k.dt_s;
    assert_int_equal(br_app_step(&g.app, &mv), BR_OK);
    assert_true(a->ref_limited);
    /* a target beyond the soft limit: held at it, flagged */
    rig_machine(&g);
    g.app.motion.stuck_band_N = 1e9f;
    const br_ref_t beyond = {(int32_t)(1.1f * a->lim_hi), 0.0f, 0.0f};
    for (int i = 0; i < 100000 && g.app.fault == BR_APP_FAULT_NONE; i++) {
        g.f.counts = a->lim_counts;
        assert_int_equal(br_app_step(&g.app, &beyond), BR_OK);
        assert_true(a->ref_limited);
        /* at most one period's change of speed past it (the braking curve's
         * float rounding at 1.6e7 counts: 28 counts, 0.2 um, measured) */
        assert_true((float)a->lim_counts + a->lim_frac <= a->lim_hi + amax);
    }
}

/* br_app_ref_speed_cap_mps is what the limiter passes (docs/modules/app.md,
 * "Drive protections"): the speed limit mid-stroke, 0 at a soft limit, and,
 * 3 mm and 20 mm from each soft limit (the braking curve and the coast
 * envelope binding), a reference cruising toward the end at 0.999 of the cap
 * passes untouched while one at 1.01 of it is limited. NULL, an application
 * not initialised and a NaN position give 0. */
static void test_speed_cap_is_what_passes(void **st)
{
    (void)st;
    rig_t g;
    rig_machine(&g);
    const br_app_t *a = &g.app;
    const float vmax = a->motion.max_speed_mps;
    assert_true(br_app_ref_speed_cap_mps(NULL, 0.0f, 1) == 0.0f);
    assert_true(br_app_ref_speed_cap_mps(a, NAN, 1) == 0.0f);
    const float mid = 0.5f * (a->motion.soft_min_m + a->motion.soft_max_m);
    assert_true(fabsf(br_app_ref_speed_cap_mps(a, mid, 1) / vmax - 1.0f) <= 1.0e-5f);
    assert_true(fabsf(br_app_ref_speed_cap_mps(a, mid, 0) / vmax - 1.0f) <= 1.0e-5f);
    assert_true(br_app_ref_speed_cap_mps(a, a->motion.soft_max_m, 1) == 0.0f);
    assert_true(br_app_ref_speed_cap_mps(a, a->motion.soft_min_m, 0) == 0.0f);
    static const float from_end_m[2] = {0.003f, 0.020f}, share[2] = {0.999f, 1.01f};
    for (int hi = 0; hi < 2; hi++) {
        for (int d = 0; d < 2; d++) {
            for (int s = 0; s < 2; s++) {
                rig_machine(&g);
                g.app.motion.stuck_band_N = 1e9f; /* the fake axis moves without a force */
                const float cpm = a->motion.counts_per_m, dt = a->ctrl.cfg.dt_s;
                const float pos_m = hi ? a->motion.soft_max_m - from_end_m[d] : a->motion.soft_min_m + from_end_m[d];
                const float cap = br_app_ref_speed_cap_mps(a, pos_m, hi);
                assert_true(cap > 0.0f && cap < vmax);
                /* the limiter cruising toward the end at that position, the axis on it */
                const float p = pos_m * cpm, step = (hi ? 1.0f : -1.0f) * share[s] * cap * cpm * dt;
                g.app.lim_primed = 1;
                g.app.lim_active = 0;
                g.app.lim_counts = (int32_t)floorf(p);
                g.app.lim_frac = p - floorf(p);
                g.app.lim_v = step;
                g.f.counts = g.app.lim_counts;
                const float t = p + step;
                const br_ref_t r = {(int32_t)floorf(t), t - floorf(t), step * g.k.rad_per_count / dt};
                assert_int_equal(br_app_step(&g.app, &r), BR_OK);
                print_message("%s end, %.0f mm from it: cap %.4f m/s, at %.3f of it limited %d\n", hi ? "high" : "low",
                              (double)from_end_m[d] * 1e3, (double)cap, (double)share[s], a->ref_limited);
                assert_int_equal(a->ref_limited, s);
            }
        }
    }
}

/* A reference at max speed toward the stroke's end and beyond it (the axis
 * follows the limited reference exactly): held on the braking curve that
 * stops at the soft limit (without it the reference passed the soft limit at
 * full speed: TRAVEL on the closed loop, br_faults ref_to_end) and, with the
 * machine's coast envelope (limits.coast_stop stroke), never so fast that a
 * coast with the outputs off, from the speed fault's margin above it, runs
 * past the stroke's end; it still reaches the soft limit. The reference
 * ramps within the limiter's acceleration, so it passes through until one
 * of these acts. With the envelope
 * off (external) the speed near the end is the limiter's. */
/* r moved by dv counts, its fraction kept in [0, 1) */
static void pos_add_test(br_ref_t *r, float dv)
{
    const float total = r->ref_frac_counts + dv, whole = floorf(total);
    r->ref_counts += (int32_t)whole;
    r->ref_frac_counts = total - whole;
}

static void run_to_end(int coast_in_stroke, float *v_near_end)
{
    rig_t g;
    rig_init(&g, 0);
    br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    mm.coast_in_stroke = coast_in_stroke;
    g.c.motion = br_app_motion_cfg(&mm);
    g.c.guard = br_app_guard_cfg(1e-3f, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
    assert_int_equal(br_app_arm(&g.app), BR_OK);
    g.app.motion.stuck_band_N = 1e9f;
    const br_app_t *a = &g.app;
    const float vmax = a->lim_vmax, amax = a->lim_amax, k = 1.0f + BR_APP_SPEED_MARGIN, ac = a->lim_acoast;
    assert_true(coast_in_stroke ? ac > 0.0f : ac == 0.0f);
    /* from twice the coast's length before the soft limit, at standstill */
    const float coast_counts = (float)BR_MACHINE_COAST_M * a->motion.counts_per_m;
    float p = floorf(a->lim_hi - 2.0f * coast_counts);
    g.f.counts = (int32_t)p;
    br_ref_t r = {(int32_t)p, 0.5f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    p = (float)a->lim_counts + a->lim_frac;
    *v_near_end = 0.0f;
    int i = 0;
    /* the reference ramps at half the limiter's acceleration: passed
     * through until a limit acts */
    float vr = 0.0f;
    for (; i < 20000; i++) {
        vr = fminf(vr + 0.5f * amax, vmax);
        pos_add_test(&r, vr);
        r.ref_omega_radps = vr * g.k.rad_per_count / g.k.dt_s;
        g.f.counts = a->lim_counts;
        assert_int_equal(br_app_step(&g.app, &r), BR_OK);
        /* the step: the limiter's own (positions near 2^24 counts are whole
         * counts in float; the coast's length grows 700 counts per count of it) */
        const float v = a->lim_v;
        p = (float)a->lim_counts + a->lim_frac;
        assert_true(v <= vmax * 1.0001f && v >= -amax);
        /* the braking curve: at most one period's change of speed past the soft limit */
        assert_true(p <= a->lim_hi + amax);
        if (coast_in_stroke) {
            /* a coast from k v, seen a period late, stops inside the stroke
             * less the following limit (positions in float near 2^24 counts
             * are whole counts: the limiter's position before the step, after
             * it and the room each round by up to a count; 2.8 measured) */
            assert_true((k * v) * (k * v) / (2.0f * ac) + 2.0f * k * v <= a->lim_end_hi - p + 4.0f);
        }
        if (a->lim_end_hi - p < 0.25f * coast_counts) *v_near_end = fmaxf(*v_near_end, v);
        if (v == 0.0f && p >= a->lim_hi - 1.0f) break;
    }
    assert_true(i < 20000); /* stood at the soft limit */
}

static void test_reference_to_the_end(void **st)
{
    (void)st;
    float v_in = 0.0f, v_ext = 0.0f;
    run_to_end(1, &v_in);
    run_to_end(0, &v_ext);
    print_message("largest step within a quarter of the coast from the end: %.0f counts (envelope), %.0f (external)\n",
                  (double)v_in, (double)v_ext);
    assert_true(v_ext > 1.5f * v_in);
    /* limits.coast_stop is 0 or 1 */
    br_app_machine_t bad = BR_MACHINE_APP_MACHINE;
    bad.coast_in_stroke = 2;
    rig_t g;
    rig_init(&g, 0);
    g.c.motion = br_app_motion_cfg(&bad);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
}

/* Speed, following error and travel: latched, the axis brakes (controller
 * on a ramp at the machine's acceleration), then outputs off. */
static void test_motion_faults_brake(void **st)
{
    (void)st;
    rig_t g;
    const br_ref_t r = {0, 0.5f, 0.0f};
    /* speed: a delta above speed_fault (below the jump limit) */
    rig_machine(&g);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    const int32_t fast = (int32_t)(g.app.motion.speed_fault_mps * g.app.motion.counts_per_m * 1e-3f) + 2;
    g.c.guard.enc_max_delta_counts = 100000u;
    g.app.guard.enc_max_delta_counts = 100000u;
    g.f.counts += fast;
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_SPEED);
    /* the ramp starts from the last speed below the fault's (here the axis
     * stood), never from the delta that tripped it (a lying count) */
    assert_true(g.app.brk_v == 0.0f);
    /* from that speed the ramp is at most speed / accel + the settle long */
    const int ramp = (int)ceilf((float)fast / g.app.lim_amax) + (int)BR_APP_BRAKE_SETTLE_PERIODS;
    assert_int_equal(g.app.stop, BR_APP_STOP_BRAKING);
    assert_true(g.f.on);
    /* the axis follows the ramp */
    while (g.app.stop == BR_APP_STOP_BRAKING) {
        g.f.counts = g.app.brk_counts;
        assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
        assert_true(g.app.brk_left <= (uint32_t)ramp);
    }
    assert_latched(&g, BR_APP_FAULT_SPEED);
    /* following error: the count 1.5 following limits from the reference */
    rig_machine(&g);
    assert_int_equal(br_app_step(&g.app, &r), BR_OK);
    g.app.guard.enc_max_delta_counts = 1u << 30;
    g.app.motion.speed_fault_mps = 1e6f;
    g.f.counts += (int32_t)(1.5f * g.app.motion.max_following_m * g.app.motion.counts_per_m);
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_FOLLOWING);
    assert_int_equal(g.app.stop, BR_APP_STOP_BRAKING);
    /* beyond the soft limit: travel (the reference there too) */
    rig_machine(&g);
    g.f.counts = (int32_t)(g.app.lim_hi + 2.0f * g.app.motion.max_following_m * g.app.motion.counts_per_m);
    const br_ref_t there = {g.f.counts, 0.5f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &there), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_TRAVEL);
    assert_brakes_then_off(&g, BR_APP_FAULT_TRAVEL, (int)BR_APP_BRAKE_SETTLE_PERIODS);
    /* a failed read while braking: outputs off at once */
    rig_machine(&g);
    assert_int_equal(br_app_fault(&g.app, BR_APP_FAULT_DEADLINE), BR_E_FAULT);
    assert_latched(&g, BR_APP_FAULT_DEADLINE);
}

/* The drive protections of the machine file: br_app_motion_cfg's float32
 * stop bound and soft limits are machine.stop_bound_m's (the generated
 * header); a stroke that leaves no travel inside them, a non-finite stroke
 * start, and soft limits beyond the int32 count are refused at init; a count
 * across the int32 wrap lies beyond every stroke: TRAVEL, never a small
 * delta read as motion inside it. */
static void test_motion_cfg_machine(void **st)
{
    (void)st;
    const br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t c = br_app_motion_cfg(&mm);
    assert_true(fabs((double)c.stop_bound_m - BR_MACHINE_STOP_BOUND_M) <= 1e-6 * BR_MACHINE_STOP_BOUND_M);
    assert_true(fabs((double)c.soft_min_m - (BR_MACHINE_TRAVEL_MIN_M + BR_MACHINE_STOP_BOUND_M)) <= 1e-6);
    assert_true(fabs((double)c.soft_max_m - (BR_MACHINE_TRAVEL_MIN_M + BR_MACHINE_TRAVEL_M - BR_MACHINE_STOP_BOUND_M)) <=
                1e-6);
    rig_t g;
    rig_init(&g, 0);
    g.c.motion = c;
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
    br_app_machine_t bad = mm;
    bad.travel_m = 1.5f * c.stop_bound_m; /* the stop bound at each end: nothing left */
    g.c.motion = br_app_motion_cfg(&bad);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    bad = mm;
    bad.travel_min_m = NAN;
    g.c.motion = br_app_motion_cfg(&bad);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    bad = mm;
    bad.travel_min_m = 2147483648.0f / c.counts_per_m; /* starts beyond the int32 count */
    g.c.motion = br_app_motion_cfg(&bad);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    /* across the wrap */
    rig_machine(&g);
    g.app.motion.stuck_band_N = 1e9f;
    g.f.counts = INT32_MAX - 40;
    const br_ref_t r = {INT32_MAX - 40, 0.5f, 0.0f};
    assert_int_equal(br_app_step(&g.app, &r), BR_E_FAULT);
    assert_int_equal(g.app.fault, BR_APP_FAULT_TRAVEL);
}

static void test_external_fault_latches(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    assert_int_equal(br_app_fault(&g.app, BR_APP_FAULT_NONE), BR_E_PARAM);
    assert_int_equal(br_app_fault(&g.app, (br_app_fault_t)99), BR_E_PARAM);
    assert_int_equal(g.app.fault, BR_APP_FAULT_NONE);
    assert_int_equal(br_app_fault(&g.app, BR_APP_FAULT_DEADLINE), BR_E_FAULT);
    assert_latched(&g, BR_APP_FAULT_DEADLINE);
}

static void test_guard_config(void **st)
{
    (void)st;
    rig_t g;
    rig_init(&g, 0);
    const br_app_guard_cfg_t ok = GUARD;
    br_app_guard_cfg_t bad[10] = {ok, ok, ok, ok, ok, ok, ok, ok, ok, ok};
    bad[0].enc_max_delta_counts = 0u;
    bad[1].enc_max_delta_counts = (1u << 30) + 1u;
    bad[2].enc_stale_periods = 1001u;
    bad[3].lock_max_outliers = 10u;
    bad[4].lock_window_periods = 2u; /* 2 of 2 */
    bad[5].enc_max_delta_counts = 0xFFFFFFFFu;
    bad[6].lock_window_periods = 0u;
    bad[7].lock_window_periods = BR_APP_LOCK_WINDOW_MAX + 1u;
    bad[8].lock_max_outliers = ok.lock_window_periods; /* could never trip */
    bad[9].lock_window_periods = 1u;                   /* likewise: 2 of 1 */
    for (int i = 0; i < 10; i++) {
        g.c.guard = bad[i];
        assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
        assert_int_equal(br_app_arm(&g.app), BR_E_STATE);
    }
    /* the machine's: 1 ms at 0.1 m/s = 13107.2 counts, times BR_APP_JUMP_SPEEDS
     * (2 x 1.2 = 2.4) = 31457.28 -> 31458 */
    const br_app_guard_cfg_t m = br_app_guard_cfg(1e-3f, 13107200.0f);
    assert_int_equal(m.enc_max_delta_counts, 31458u);
    /* the lock window: 100 ms of periods, a quarter of them */
    assert_true((float)m.lock_window_periods * 1e-3f >= BR_APP_GUARD_LOCK_S);
    assert_true((float)(m.lock_window_periods - 1u) * 1e-3f < BR_APP_GUARD_LOCK_S);
    assert_true((float)m.lock_max_outliers >= BR_APP_GUARD_LOCK_FRACTION * (float)m.lock_window_periods);
    assert_true((float)(m.lock_max_outliers - 1u) < BR_APP_GUARD_LOCK_FRACTION * (float)m.lock_window_periods);
    print_message("lock monitor at 1 ms: %u outliers in %u periods\n", (unsigned)m.lock_max_outliers,
                  (unsigned)m.lock_window_periods);
    g.c.guard = br_app_guard_cfg(1e-3f, 13107200.0f);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_OK);
    g.c.guard = br_app_guard_cfg(1e-6f, 13107200.0f); /* a window of 1e5 periods: too long */
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    g.c.guard = br_app_guard_cfg(NAN, 1.0f);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
    g.c.guard = br_app_guard_cfg(1e-3f, -1.0f);
    assert_int_equal(br_app_init(&g.app, &g.c, &g.hal, NULL), BR_E_PARAM);
}

/* One home: the image's const PF configuration (compile-time initialiser, in
 * flash) is the simulator's run-time one, value for value. */
static const br_pf_cfg_t k_image_pf = BR_MACHINE_PF_CFG_TUNED(BR_EST_PF_PERIOD_S_F);

static void test_machine_cfg_one_home(void **st)
{
    (void)st;
    const br_pf_cfg_t c = br_circle_pf_cfg_tuned((float)BR_EST_PF_PERIOD_S);
    assert_memory_equal(&c.est.model, &k_image_pf.est.model, sizeof c.est.model);
    assert_memory_equal(c.est.q_var, k_image_pf.est.q_var, sizeof c.est.q_var);
    assert_memory_equal(&c.est.r_var_rad2, &k_image_pf.est.r_var_rad2, sizeof(float));
    assert_memory_equal(c.x0_std, k_image_pf.x0_std, sizeof c.x0_std);
    assert_true(c.est.gp0_N == k_image_pf.est.gp0_N && c.est.gp_min_N == k_image_pf.est.gp_min_N &&
                c.est.gp_max_N == k_image_pf.est.gp_max_N &&
                c.est.outlier_sigma == k_image_pf.est.outlier_sigma &&
                c.est.rad_per_count == k_image_pf.est.rad_per_count);
    assert_int_equal(c.est.reanchor_after, k_image_pf.est.reanchor_after);
    assert_int_equal(c.n_particles, k_image_pf.n_particles);
    assert_int_equal(k_image_pf.n_particles, BR_EST_PF_N_PARTICLES);
    assert_ptr_equal(c.noise, k_image_pf.noise);
    assert_int_equal(c.noise_len, k_image_pf.noise_len);
    assert_int_equal(c.noise_skip, k_image_pf.noise_skip);
    assert_memory_equal(&c.adapt, &k_image_pf.adapt, sizeof c.adapt);
    /* and it is a configuration the PF accepts, at the image's period */
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    assert_int_equal(br_pf_init(pf, &k_image_pf), BR_OK);
    free(pf);
    /* the image's tick in whole ns is the period */
    assert_true(fabs((double)BR_EST_PF_PERIOD_NS * 1e-9 - BR_EST_PF_PERIOD_S) < 0.5e-9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_none_is_hinf_only),
        cmocka_unit_test(test_extern_drives_compensation),
        cmocka_unit_test(test_estimator_interface),
        cmocka_unit_test(test_pf_as_wired_by_hand),
        cmocka_unit_test(test_ukf_as_wired_by_hand),
        cmocka_unit_test(test_outputs_off_until_armed),
        cmocka_unit_test(test_ctrl_input_latches_until_rearmed),
        cmocka_unit_test(test_ctrl_state_latches),
        cmocka_unit_test(test_estimator_error_latches),
        cmocka_unit_test(test_lost_lock_latches),
        cmocka_unit_test(test_hal_error_latches),
        cmocka_unit_test(test_encoder_jump_latches),
        cmocka_unit_test(test_encoder_stale_holds_then_latches),
        cmocka_unit_test(test_held_reads_extrapolate),
        cmocka_unit_test(test_encoder_jump_after_held_reads),
        cmocka_unit_test(test_encoder_frozen_latches),
        cmocka_unit_test(test_encoder_frozen_coarse_count),
        cmocka_unit_test(test_encoder_frozen_actuator_delay),
        cmocka_unit_test(test_reference_limiter),
        cmocka_unit_test(test_speed_cap_is_what_passes),
        cmocka_unit_test(test_reference_to_the_end),
        cmocka_unit_test(test_motion_faults_brake),
        cmocka_unit_test(test_motion_cfg_machine),
        cmocka_unit_test(test_external_fault_latches),
        cmocka_unit_test(test_guard_config),
        cmocka_unit_test(test_machine_cfg_one_home),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
