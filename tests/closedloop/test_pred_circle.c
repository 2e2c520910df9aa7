/* SPDX-License-Identifier: Apache-2.0 */
/* The compensation that predicts in closed loop (docs/modules/ff-pred.md), on
 * the thesis circle of the hardware-like plant, with the oracle (the plant's
 * true friction) as the estimate, so that what is checked is the prediction
 * and not a filter: the true friction one period late is worse than at t_k
 * (the bar an estimate at t_k meets), the true friction at t_k plus the
 * plant's own elements' change over half a period is better than at t_k
 * (measured 1.66e-8 against 1.91e-8 m), every run goes round, and the
 * prediction's switch off (pred = 0, the default) is the run without it bit
 * for bit. */
#include "br_test.h"

#include "circle/br_circle.h"

static br_circle_result_t run(const br_circle_cfg_t *c)
{
    br_circle_result_t r;
    assert_int_equal(br_circle_run(c, NULL, NULL, &r), 0);
    assert_int_equal(r.fault_status, 0);
    return r;
}

static void test_pred_beats_oracle_at_tk(void **state)
{
    (void)state;
    const br_circle_cfg_t now = br_circle_cfg_hardware_like(BR_CTRL_HINF_TRUE);
    br_circle_cfg_t late = now, pred = now, off = now;
    late.oracle_late = 1;
    br_circle_use_ff_el(&pred, BR_CIRCLE_FF_EL_OWN);
    br_circle_use_pred(&pred, 0.5 * pred.dt_s, 1);
    assert_int_equal(pred.pred, 1);
    br_circle_use_ff_el(&off, BR_CIRCLE_FF_EL_OWN); /* elements, but no horizon: nothing added */
    const br_circle_result_t rn = run(&now), rl = run(&late), rp = run(&pred), ro = run(&off);
    print_message("true friction at t_k %.4e m, one period late %.4e m, at t_k + prediction %.4e m\n",
                  rn.contour_rms_m, rl.contour_rms_m, rp.contour_rms_m);
    assert_true(rl.contour_rms_m > rn.contour_rms_m);
    assert_true(rp.contour_rms_m < rn.contour_rms_m);
    assert_true(ro.contour_rms_m == rn.contour_rms_m && ro.fhat_rms_err_N == rn.fhat_rms_err_N);
}

/* a horizon without the feedforward's elements is refused: no run, no figure */
static void test_pred_needs_elements(void **state)
{
    (void)state;
    br_circle_cfg_t c = br_circle_cfg_hardware_like(BR_CTRL_HINF_TRUE);
    br_circle_use_pred(&c, 1e-3, 1);
    br_circle_result_t r;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pred_beats_oracle_at_tk),
        cmocka_unit_test(test_pred_needs_elements),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
