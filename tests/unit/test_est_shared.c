/* SPDX-License-Identifier: Apache-2.0 */
/* What the PF and the UKF share (firmware/est/br_est.c): the actuator-delay
 * history's interpolation u_a = (1 - f) u[k-1-m] + f u[k-2-m] against the
 * commands pushed, and the configuration's g_p-range guard on its own
 * (gp_min < gp_max strictly, also when gp0 sits on both). */
#include "br_test.h"

#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_est.h"

/* a delay of 2.25 periods (m = 2, f = 1/4; exact in binary): the command
 * pushed at step k is u_k = k + 1, and the torque that reached the axis over
 * the last period is the mix of the commands m and m + 1 periods before the
 * newest, 0 before the first */
static void test_delay_interpolates(void **st)
{
    (void)st;
    br_est_cfg_t c;
    memset(&c, 0, sizeof c);
    c.model.dt_s = 0.5f;
    c.model.causes.delay_s = 1.125f;
    br_est_delay_t d;
    br_est_delay_init(&d, &c);
    assert_int_equal(d.m, 2u);
    BR_ASSERT_NEAR(d.f, 0.25, 0.0);
    for (int k = 0; k < 3 * (int)BR_EST_DELAY_HIST; k++) {
        const float got = br_est_delay_apply(&d, (float)(k + 1));
        const int a = k - 2, b = k - 3; /* the commands m and m + 1 periods before the newest */
        const double want = 0.75 * (a >= 0 ? a + 1 : 0) + 0.25 * (b >= 0 ? b + 1 : 0);
        BR_ASSERT_NEAR(got, want, 1e-6 * fabs(want));
    }
    /* no delay: the command itself */
    c.model.causes.delay_s = 0.0f;
    br_est_delay_init(&d, &c);
    BR_ASSERT_NEAR(br_est_delay_apply(&d, 3.5f), 3.5, 0.0);
}

static void test_gp_range_is_strict(void **st)
{
    (void)st;
    br_est_cfg_t c = br_circle_ukf_cfg_default(BR_MACHINE_CTRL_PERIOD_S_F).est;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c.gp_min_N = c.gp0_N;
    c.gp_max_N = 1.5f * c.gp0_N;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* an empty range with g_p0 on both ends */
    c.gp_max_N = c.gp0_N;
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_delay_interpolates),
        cmocka_unit_test(test_gp_range_is_strict),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
