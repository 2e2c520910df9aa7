/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's delayed guard plants (sim/tune/br_tune_delay.h): a setting that
 * stops the axis on one counts as a failure, never as a figure. */
#include "br_test.h"

#include "tune/br_tune_delay.h"

static br_tune_delay_t g; /* large: static */

/* the committed tunings run every delayed plant to the end, given as the
 * tuner gives them (the identification off): the guard turns the machine's
 * identification on, without which the same settings stop */
static void test_committed_runs(void **st)
{
    (void)st;
    static const br_circle_ctrl_t ests[] = {BR_CTRL_HINF_UKF, BR_CTRL_HINF_PF};
    for (int e = 0; e < 2; e++) {
        br_tune_delay_init(&g, ests[e]);
        for (int k = 0; k < BR_TUNE_DELAY_N; k++) assert_true(g.plant[k].plant.delay_s > 0.0);
        br_circle_cfg_t c = br_circle_cfg_thesis(ests[e]);
        br_circle_use_delay_id(&c, 0);
        assert_true(br_tune_delay_failed(&g, &c) == 0.0);
        /* the same settings without the identification on the first delayed plant */
        br_circle_cfg_t p = g.plant[0];
        p.pf = c.pf;
        p.ukf = c.ukf;
        br_circle_result_t r;
        assert_int_equal(br_circle_run(&p, NULL, NULL, &r), 1);
        assert_true(r.fault_status != 0);
    }
}

/* the UKF that `br_tune_est --mslip-target 0.136` returned without this guard
 * (branch tune-hw-ukf, docs/tuning.md: R 0.012 count^2, below the encoder's
 * quantisation) loses lock at 2 ms: a stop counts as 1 + the share of the run
 * lost, and the tuner's box (the identification off, as it tunes) does not
 * hide it: the guard turns the machine's identification on */
static void test_stop_is_failure(void **st)
{
    (void)st;
    br_tune_delay_init(&g, BR_CTRL_HINF_UKF);
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    br_circle_use_delay_id(&c, 0);
    static const float q[4] = {4.246927313e-14f, 3.775609457e-06f, 2.482526852e-14f, 3.231890034e-03f};
    for (int i = 0; i < 4; i++) c.ukf.est.q_var[i] = q[i];
    c.ukf.est.r_var_rad2 = 4.474242699e-13f;
    const double failed = br_tune_delay_failed(&g, &c);
    print_message("tune-hw-ukf's UKF on the delayed guard plants: failed %.4f\n", failed);
    assert_true(failed > 1.0 && failed <= 2.0 * BR_TUNE_DELAY_N);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_committed_runs),
        cmocka_unit_test(test_stop_is_failure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
