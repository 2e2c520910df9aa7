/* SPDX-License-Identifier: Apache-2.0 */
/* Axis loop over the HAL, with a fake port. */
#include "br_test.h"

#include "bristle/br_axis.h"
#include "bristle_gen/machine/br_machine.h"

typedef struct {
    int32_t counts;
    br_status_t enc_status;
    float duty;
    int writes;
} fake_t;

static br_status_t fake_enc(void *ctx, int32_t *c)
{
    fake_t *f = ctx;
    *c = f->counts;
    return f->enc_status;
}
static br_status_t fake_pwm(void *ctx, float d)
{
    fake_t *f = ctx;
    f->duty = d;
    f->writes++;
    return BR_OK;
}
static br_status_t fake_tick(void *ctx, uint32_t *t)
{
    (void)ctx;
    *t = 0;
    return BR_OK;
}

/* the machine's period, torque limit, amplifier, encoder and lead */
#define DT BR_MACHINE_CTRL_PERIOD_S_F
#define TAU_MAX BR_MACHINE_TORQUE_LIMIT_NM_F
#define TAU_DUTY BR_MACHINE_TAU_PER_DUTY_NM_F
#define RPC BR_MACHINE_RAD_PER_COUNT_F
#define LEAD BR_MACHINE_LEAD_MPRAD_F

/* the test's gains (round numbers, not the H-inf design) on the machine */
static br_ctrl_cfg_t cfg(void)
{
    br_ctrl_cfg_t c = {{-0.5f, -0.01f, -10.0f}, DT, TAU_MAX, TAU_DUTY, RPC, LEAD};
    return c;
}

static void test_init_guards(void **st)
{
    (void)st;
    fake_t f = {0};
    br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    br_axis_t a;
    br_ctrl_cfg_t k = cfg();
    assert_int_equal(br_axis_init(&a, NULL, &k, NULL), BR_E_NULL);
    br_hal_t h2 = hal; h2.pwm_write = NULL;
    assert_int_equal(br_axis_init(&a, &h2, &k, NULL), BR_E_NULL);
    h2 = hal; h2.encoder_read = NULL;
    assert_int_equal(br_axis_init(&a, &h2, &k, NULL), BR_E_NULL);
    k.dt_s = 0.0f;
    assert_int_equal(br_axis_init(&a, &hal, &k, NULL), BR_E_PARAM);
    br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_axis_step(&a, &r), BR_E_STATE);
}

static void test_step_writes_duty(void **st)
{
    (void)st;
    fake_t f = {1000, BR_OK, 0.0f, 0};
    br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    br_axis_t a;
    br_ctrl_cfg_t k = cfg();
    assert_int_equal(br_axis_init(&a, &hal, &k, NULL), BR_OK);
    br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_axis_step(&a, &r), BR_OK);
    assert_int_equal(f.writes, 1);
    BR_ASSERT_NEAR(f.duty, -0.5 * 1000 * RPC / TAU_DUTY, 1e-7);
}

static void test_encoder_fault_zeroes_pwm(void **st)
{
    (void)st;
    fake_t f = {1000, BR_OK, 0.0f, 0};
    br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    br_axis_t a;
    br_ctrl_cfg_t k = cfg();
    assert_int_equal(br_axis_init(&a, &hal, &k, NULL), BR_OK);
    br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_axis_step(&a, &r), BR_OK);
    assert_true(f.duty != 0.0f);
    f.enc_status = BR_E_INPUT;
    assert_int_equal(br_axis_step(&a, &r), BR_E_INPUT);
    assert_true(f.duty == 0.0f);
}

typedef struct {
    float F;
    br_status_t st;
    br_meas_t y;
    float u_prev;
    int calls;
} fake_est_t;

static br_status_t fake_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    fake_est_t *e = ctx;
    e->y = *y;
    e->u_prev = u_prev_Nm;
    e->calls++;
    *F_hat_N = e->F;
    return e->st;
}

static void test_estimator_drives_compensation(void **st)
{
    (void)st;
    fake_t f = {0, BR_OK, 0.0f, 0};
    br_hal_t hal = {&f, fake_enc, fake_pwm, fake_tick, NULL, NULL};
    fake_est_t e = {10.0f, BR_OK, {0, 0.0f}, 0.0f, 0};
    br_est_t est = {&e, fake_est_step, NULL, NULL};
    br_axis_t a;
    br_ctrl_cfg_t k = cfg();
    br_est_t bad = {&e, NULL, NULL, NULL};
    assert_int_equal(br_axis_init(&a, &hal, &k, &bad), BR_E_NULL);
    assert_int_equal(br_axis_init(&a, &hal, &k, &est), BR_OK);
    br_ref_t r = {0, 0.0f, 0.0f};
    assert_int_equal(br_axis_step(&a, &r), BR_OK);
    /* zero error: the duty is the compensation alone, L F / tau_per_duty */
    BR_ASSERT_NEAR(f.duty, LEAD * 10.0 / TAU_DUTY, 1e-7);
    assert_int_equal(e.y.counts, 0);
    BR_ASSERT_NEAR(e.y.frac, 0.5, 0.0);
    BR_ASSERT_NEAR(e.u_prev, 0.0, 0.0);
    /* the next call sees the torque applied over the last period */
    assert_int_equal(br_axis_step(&a, &r), BR_OK);
    BR_ASSERT_NEAR(e.u_prev, LEAD * 10.0, 1e-9);
    /* an estimator failure: zero duty, status passed up, and the torque it will
     * see next time is the zero that was really applied */
    e.st = BR_E_NUMERIC;
    assert_int_equal(br_axis_step(&a, &r), BR_E_NUMERIC);
    assert_true(f.duty == 0.0f);
    e.st = BR_OK;
    assert_int_equal(br_axis_step(&a, &r), BR_OK);
    BR_ASSERT_NEAR(e.u_prev, 0.0, 0.0);
    /* a non-finite estimate is refused by the controller: zero duty */
    e.F = NAN;
    assert_int_equal(br_axis_step(&a, &r), BR_E_INPUT);
    assert_true(f.duty == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_init_guards), cmocka_unit_test(test_step_writes_duty),
                                       cmocka_unit_test(test_encoder_fault_zeroes_pwm),
                                       cmocka_unit_test(test_estimator_drives_compensation)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
