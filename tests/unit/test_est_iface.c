/* SPDX-License-Identifier: Apache-2.0 */
/* The estimator interface (br_est.h, docs/modules/est.md "The interface"):
 * br_est_period routes a period with a measurement to step and one without
 * to predict (or holds the estimate), br_est_restart calls reset; the PF's
 * and the UKF's bindings are their own step, predict and init, bit for bit. */
#include "br_test.h"

#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_est.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"

typedef struct {
    int steps, predicts, resets;
    float u;         /* the last torque passed */
    br_status_t st;  /* what every call returns */
} fake_t;

static br_status_t fake_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    fake_t *f = ctx;
    (void)y;
    f->steps++;
    f->u = u_prev_Nm;
    *F_hat_N = 1.0f;
    return f->st;
}
static br_status_t fake_predict(void *ctx, float u_prev_Nm, float *F_hat_N)
{
    fake_t *f = ctx;
    f->predicts++;
    f->u = u_prev_Nm;
    *F_hat_N = 2.0f;
    return f->st;
}
static br_status_t fake_reset(void *ctx)
{
    fake_t *f = ctx;
    f->resets++;
    return f->st;
}

static void test_period_routes(void **st)
{
    (void)st;
    fake_t f = {0, 0, 0, 0.0f, BR_OK};
    const br_meas_t y = {3, 0.5f};
    float F = 0.0f;
    br_est_t e = {&f, fake_step, fake_predict, fake_reset};
    /* guards */
    assert_int_equal(br_est_period(NULL, &y, 0.0f, &F), BR_E_NULL);
    assert_int_equal(br_est_period(&e, &y, 0.0f, NULL), BR_E_NULL);
    assert_int_equal(br_est_restart(NULL), BR_E_NULL);
    br_est_t no_step = e;
    no_step.step = NULL;
    assert_int_equal(br_est_period(&no_step, &y, 0.0f, &F), BR_E_NULL);
    assert_int_equal(f.steps + f.predicts + f.resets, 0);
    /* a measurement: step; none: predict; the status is passed up */
    assert_int_equal(br_est_period(&e, &y, 0.25f, &F), BR_OK);
    assert_true(F == 1.0f && f.steps == 1 && f.u == 0.25f);
    f.st = BR_W_OUTLIER;
    assert_int_equal(br_est_period(&e, NULL, 0.5f, &F), BR_W_OUTLIER);
    assert_true(F == 2.0f && f.predicts == 1 && f.u == 0.5f);
    f.st = BR_E_NUMERIC;
    assert_int_equal(br_est_restart(&e), BR_E_NUMERIC);
    assert_int_equal(f.resets, 1);
    /* without predict the estimate is held; without reset nothing happens */
    e.predict = NULL;
    e.reset = NULL;
    F = 7.0f;
    assert_int_equal(br_est_period(&e, NULL, 0.5f, &F), BR_OK);
    assert_true(F == 7.0f);
    assert_int_equal(br_est_restart(&e), BR_OK);
    assert_int_equal(f.predicts + f.resets, 2);
}

/* n periods on two filters of the same configuration: a through the binding
 * (its step, and its predict at every third period), b by hand; estimates
 * equal bit for bit. */
static void check_binding(br_est_t a, const br_est_t *want, br_status_t (*predict)(void *, float), const float *b_F,
                          void *b)
{
    /* the binding is the filter's three functions over its context */
    assert_ptr_equal(a.ctx, want->ctx);
    assert_ptr_equal(a.step, want->step);
    assert_ptr_equal(a.predict, want->predict);
    assert_ptr_equal(a.reset, want->reset);
    br_est_step_fn step = want->step;
    float Fa = 0.0f, Fb = 0.0f;
    for (int k = 0; k < 30; k++) {
        const br_meas_t y = {k / 2, 0.5f};
        const float u = 0.01f * (float)(k % 5);
        br_status_t sa, sb;
        if (k > 0 && k % 3 == 0) {
            sa = br_est_period(&a, NULL, u, &Fa);
            sb = predict(b, u);
            Fb = *b_F;
        } else {
            sa = br_est_period(&a, &y, u, &Fa);
            sb = step(b, &y, u, &Fb);
        }
        assert_int_equal(sa, sb);
        assert_false(BR_FAILED(sa));
        assert_memory_equal(&Fa, &Fb, sizeof(float));
    }
    /* reset: the filter starts again (unprimed: nothing to predict from) */
    assert_int_equal(br_est_restart(&a), BR_OK);
    assert_int_equal(br_est_period(&a, NULL, 0.0f, &Fa), BR_E_STATE);
    /* guards */
    assert_int_equal(a.predict(a.ctx, 0.0f, NULL), BR_E_NULL);
    assert_int_equal(a.reset(NULL), BR_E_NULL);
}

/* after a's reset and b's init: three steps of both, equal bit for bit */
static void check_fresh(const br_est_t *a, br_status_t (*step)(void *, const br_meas_t *, float, float *), void *b)
{
    float Fa = 0.0f, Fb = 0.0f;
    const br_meas_t y = {5, 0.5f};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(br_est_period(a, &y, 0.0f, &Fa), step(b, &y, 0.0f, &Fb));
        assert_memory_equal(&Fa, &Fb, sizeof(float));
    }
}

static br_status_t pf_predict(void *ctx, float u) { return br_pf_predict(ctx, u); }
static br_status_t ukf_predict(void *ctx, float u) { return br_ukf_predict(ctx, u); }

static void test_pf_binding(void **st)
{
    (void)st;
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(1e-3f);
    c.n_particles = 200u;
    br_pf_t *pf = calloc(2, sizeof *pf);
    assert_non_null(pf);
    assert_int_equal(br_pf_init(&pf[0], &c), BR_OK);
    assert_int_equal(br_pf_init(&pf[1], &c), BR_OK);
    const br_est_t e = br_pf_est(&pf[0]), want = {&pf[0], br_pf_est_step, br_pf_est_predict, br_pf_est_reset};
    check_binding(e, &want, pf_predict, &pf[1].est.F_hat_N, &pf[1]);
    /* the reset is init: the next steps are a fresh filter's */
    assert_int_equal(br_pf_init(&pf[1], &c), BR_OK);
    check_fresh(&e, br_pf_est_step, &pf[1]);
    free(pf);
}

static void test_ukf_binding(void **st)
{
    (void)st;
    const br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(1e-3f);
    br_ukf_t u[2];
    assert_int_equal(br_ukf_init(&u[0], &c), BR_OK);
    assert_int_equal(br_ukf_init(&u[1], &c), BR_OK);
    const br_est_t e = br_ukf_est(&u[0]), want = {&u[0], br_ukf_est_step, br_ukf_est_predict, br_ukf_est_reset};
    check_binding(e, &want, ukf_predict, &u[1].est.F_hat_N, &u[1]);
    assert_int_equal(br_ukf_init(&u[1], &c), BR_OK);
    check_fresh(&e, br_ukf_est_step, &u[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_period_routes),
        cmocka_unit_test(test_pf_binding),
        cmocka_unit_test(test_ukf_binding),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
