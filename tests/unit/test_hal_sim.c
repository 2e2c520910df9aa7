/* SPDX-License-Identifier: Apache-2.0 */
/* Host HAL port bound to the plant. */
#include "br_test.h"

#include "hal_sim/br_hal_sim.h"

static void test_port(void **st)
{
    (void)st;
    br_plant_t p;
    br_plant_cfg_t c = br_plant_cfg_reference();
    br_plant_state_t x0 = {0.0, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &x0), 0);
    br_hal_sim_t port;
    br_hal_t hal;
    assert_int_equal(br_hal_sim_init(&port, &p, 0.0, &hal), BR_E_PARAM);
    assert_int_equal(br_hal_sim_init(&port, NULL, 1e-3, &hal), BR_E_NULL);
    assert_int_equal(br_hal_sim_init(&port, &p, 1e-3, &hal), BR_OK);
    uint32_t tick = 99;
    int32_t counts = 5;
    /* the first tick starts the clock without moving the plant */
    assert_int_equal(hal.tick_wait(hal.ctx, &tick), BR_OK);
    assert_int_equal((int)tick, 0);
    assert_int_equal(hal.pwm_write(hal.ctx, 0.5f), BR_OK);
    assert_int_equal(hal.encoder_read(hal.ctx, &counts), BR_OK);
    assert_int_equal(counts, 0);
    /* the next tick applies the duty over one period */
    assert_int_equal(hal.tick_wait(hal.ctx, &tick), BR_OK);
    assert_int_equal((int)tick, 1);
    BR_ASSERT_NEAR(p.tau_Nm, 0.5 * c.tau_per_duty_Nm, 1e-12);
    assert_int_equal(hal.encoder_read(hal.ctx, &counts), BR_OK);
    assert_true(counts > 0);
    /* clamp and reject */
    assert_int_equal(hal.pwm_write(hal.ctx, 3.0f), BR_OK);
    BR_ASSERT_NEAR(port.duty, 1.0, 0.0);
    assert_int_equal(hal.pwm_write(hal.ctx, NAN), BR_E_INPUT);
    BR_ASSERT_NEAR(port.duty, 0.0, 0.0);
    assert_int_equal(hal.encoder_read(hal.ctx, NULL), BR_E_NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_port)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
