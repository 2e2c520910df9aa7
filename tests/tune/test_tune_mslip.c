/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's Maxwell-slip guard plants (sim/lib/tune_mslip/br_tune_mslip.h): a setting
 * that stops the axis on one counts as a failure, never as a figure. */
#include "br_test.h"

#include <math.h>

#include "tune_mslip/br_tune_mslip.h"

static br_tune_mslip_t g; /* large: static */

/* the shipped UKF runs every guard plant to the end, better than H-inf only */
static void test_shipped_runs(void **st)
{
    (void)st;
    assert_int_equal(br_tune_mslip_init(&g, BR_CTRL_HINF_UKF), 0);
    for (int k = 0; k < BR_TUNE_MSLIP_N; k++) assert_true(g.hinf_only_m[k] > 0.0 && isfinite(g.hinf_only_m[k]));
    const br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    double failed = -1.0;
    const double worst = br_tune_mslip_worst(&g, &c, &failed);
    assert_true(failed == 0.0);
    assert_true(worst > 0.0 && worst < 1.0);
}

/* a UKF whose outlier gate rejects every measurement (1e-3 sigma, no transient term) loses lock
 * on every guard plant, whatever the machine: each stop counts as 1 + the
 * share of the run lost, and adds nothing to the worst ratio (a UKF with 1e-3
 * of the tuned process noise stopped on the reference machine's plants but
 * not on machines/heavy.json's) */
static void test_stop_is_failure(void **st)
{
    (void)st;
    assert_int_equal(br_tune_mslip_init(&g, BR_CTRL_HINF_UKF), 0);
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    c.ukf.est.outlier_sigma = 1e-3f;
    c.ukf.est.outlier_transient_rad = 0.0f; /* and no transient term (eq. G1): the gate is 1e-3 sigma */
    double failed = 0.0;
    const double worst = br_tune_mslip_worst(&g, &c, &failed);
    assert_true(failed >= 1.0 && failed <= 2.0 * BR_TUNE_MSLIP_N);
    assert_true(worst >= 0.0 && worst < 1.0e3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shipped_runs),
        cmocka_unit_test(test_stop_is_failure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
