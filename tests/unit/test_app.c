/* The application module: configuration guards, and that each estimator kind
 * runs the same loop as wiring the estimator into br_axis by hand. */
#include "br_test.h"

#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_app.h"

typedef struct {
    int32_t counts;
    float duty;
} fake_t;

static br_status_t fake_enc(void *ctx, int32_t *c)
{
    *c = ((fake_t *)ctx)->counts;
    return BR_OK;
}
static br_status_t fake_pwm(void *ctx, float d)
{
    ((fake_t *)ctx)->duty = d;
    return BR_OK;
}
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
    fake_t f = {0, 0.0f};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick};
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

    br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL};
    assert_int_equal(br_app_init(NULL, &c, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, NULL, &hal, NULL), BR_E_NULL);
    assert_int_equal(br_app_init(&app, &c, NULL, NULL), BR_E_NULL);
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
    br_est_t ext = {(void *)&F, NULL};
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
    fake_t f = {1000, 0.0f};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick};
    const br_ctrl_cfg_t k = ctrl_cfg();
    const br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL};
    br_app_t app;
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    BR_ASSERT_NEAR(f.duty, -0.5 * 1000 * 6.0e-6 / 0.64, 1e-7);
    BR_ASSERT_NEAR(app.axis.F_hat_N, 0.0, 0.0);
}

static void test_extern_drives_compensation(void **st)
{
    (void)st;
    fake_t f = {0, 0.0f};
    const br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick};
    const br_ctrl_cfg_t k = ctrl_cfg();
    const float F = 10.0f;
    const br_est_t ext = {(void *)&F, const_est_step};
    const br_app_cfg_t c = {&k, BR_APP_EST_EXTERN, NULL, NULL, &ext};
    br_app_t app;
    const br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_app_init(&app, &c, &hal, NULL), BR_OK);
    assert_int_equal(br_app_step(&app, &r), BR_OK);
    /* zero error: the duty is the compensation alone, L F / tau_per_duty */
    BR_ASSERT_NEAR(f.duty, 1.27e-3 * 10.0 / 0.64, 1e-7);
}

/* The same periods through br_app (kind) and through br_axis with the filter
 * wired by hand: bit-identical estimates and duties. */
static void run_against_axis(br_app_est_kind_t kind)
{
    fake_t fa = {0, 0.0f}, fb = {0, 0.0f};
    const br_hal_t ha = {&fa, fake_enc, fake_pwm, fake_tick}, hb = {&fb, fake_enc, fake_pwm, fake_tick};
    const br_ctrl_cfg_t k = ctrl_cfg();
    br_pf_cfg_t pfc = br_circle_pf_cfg_tuned(1e-3f);
    pfc.n_particles = 200u;
    const br_ukf_cfg_t ukfc = br_circle_ukf_cfg_tuned(1e-3f);
    br_pf_t *pf = calloc(2, sizeof *pf);
    br_ukf_t *ukf = calloc(2, sizeof *ukf);
    assert_non_null(pf);
    assert_non_null(ukf);
    const br_app_cfg_t c = {&k, kind, &pfc, &ukfc, NULL};
    const br_app_mem_t mem = {&pf[0], &ukf[0]};
    br_app_t app;
    assert_int_equal(br_app_init(&app, &c, &ha, &mem), BR_OK);
    br_est_t est;
    if (kind == BR_APP_EST_PF) {
        assert_int_equal(br_pf_init(&pf[1], &pfc), BR_OK);
        est = (br_est_t){&pf[1], br_pf_est_step};
    } else {
        assert_int_equal(br_ukf_init(&ukf[1], &ukfc), BR_OK);
        est = (br_est_t){&ukf[1], br_ukf_est_step};
    }
    br_axis_t axis;
    assert_int_equal(br_axis_init(&axis, &hb, &k, &est), BR_OK);
    for (int i = 0; i < 50; i++) {
        const br_ref_t r = {i * 3, 0.25f, 0.5f};
        fa.counts = fb.counts = i * 3 + (i % 4) - 1;
        const br_status_t sa = br_app_step(&app, &r), sb = br_axis_step(&axis, &r);
        assert_int_equal(sa, sb);
        assert_false(BR_FAILED(sa));
        assert_memory_equal(&app.axis.F_hat_N, &axis.F_hat_N, sizeof(float));
        assert_memory_equal(&fa.duty, &fb.duty, sizeof(float));
    }
    assert_true(app.axis.F_hat_N != 0.0f);
    free(pf);
    free(ukf);
}

static void test_pf_as_wired_by_hand(void **st)
{
    (void)st;
    run_against_axis(BR_APP_EST_PF);
}

static void test_ukf_as_wired_by_hand(void **st)
{
    (void)st;
    run_against_axis(BR_APP_EST_UKF);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_none_is_hinf_only),
        cmocka_unit_test(test_extern_drives_compensation),
        cmocka_unit_test(test_pf_as_wired_by_hand),
        cmocka_unit_test(test_ukf_as_wired_by_hand),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
