/* SPDX-License-Identifier: Apache-2.0 */
/* The reference queue (br_refq): its guards, the queue's fill and overflow,
 * a segment against its formula, and the underrun (hold, brake within the
 * machine's max_accel, fault). The limits are the machine file's
 * (BR_MACHINE_APP_MACHINE through br_app_motion_cfg). */
#include "br_test.h"

#include <math.h>
#include <string.h>

#include "bristle/br_machine_cfg.h"
#include "bristle/br_refq.h"

#define DT BR_MACHINE_CTRL_PERIOD_S_F
#define HOLD 5u

static br_refq_cfg_t machine_cfg(uint32_t queue_len)
{
    const br_app_machine_t m = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t mo = br_app_motion_cfg(&m);
    br_refq_cfg_t c = {queue_len, DT, BR_MACHINE_RAD_PER_COUNT_F, mo.counts_per_m, mo.max_speed_mps,
                       mo.max_accel_mps2, HOLD, 0u};
    /* the fault after the longest braking, plus 10 periods */
    c.fault_periods = HOLD + (uint32_t)ceilf(c.max_speed_mps / (c.max_accel_mps2 * DT)) + 10u;
    return c;
}

static br_refq_item_t setpoint(uint32_t tick, int32_t counts, float omega)
{
    br_refq_item_t it = {BR_REFQ_SETPOINT, 0u, tick, 1u, counts, 0.0f, omega, 0.0f, 0.0f};
    return it;
}

static void test_init_guards(void **st)
{
    (void)st;
    br_refq_t q;
    br_refq_cfg_t c = machine_cfg(8u);
    br_ref_t r;
    assert_int_equal(br_refq_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_refq_init(&q, NULL), BR_E_NULL);
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    c.queue_len = 0u;
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
    assert_int_equal(br_refq_step(&q, 0u, &r), BR_E_STATE);
    c.queue_len = BR_REFQ_MAX + 1u;
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
    c = machine_cfg(8u);
    c.max_accel_mps2 = NAN;
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
    c = machine_cfg(8u);
    c.dt_s = 0.0f;
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
    /* the fault must come after the braking from max_speed: one period short is refused */
    c = machine_cfg(8u);
    c.fault_periods = HOLD + (uint32_t)ceilf(c.max_speed_mps / (c.max_accel_mps2 * DT));
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
    c.fault_periods += 1u;
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    /* the smallest accepted value is the one the helper gives; none for limits that give none */
    assert_int_equal(br_refq_fault_periods_min(&c), c.fault_periods);
    c.max_speed_mps = INFINITY;
    assert_int_equal(br_refq_fault_periods_min(&c), 0u);
    c = machine_cfg(8u);
    c.hold_periods = 1000000001u;
    assert_int_equal(br_refq_fault_periods_min(&c), 0u);
    assert_int_equal(br_refq_init(&q, &c), BR_E_PARAM);
}

static void test_push_guards(void **st)
{
    (void)st;
    br_refq_t q;
    br_refq_cfg_t c = machine_cfg(8u);
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    br_refq_item_t it = setpoint(10u, 0, 0.0f);
    it.frac = 1.0f;
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    it.frac = NAN;
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    it = setpoint(10u, 0, INFINITY);
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    /* a setpoint's speed beyond 2^24 counts per period */
    it = setpoint(10u, 0, 2.0f * BR_REFQ_SEG_MAX_COUNTS * BR_MACHINE_RAD_PER_COUNT_F / DT);
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    it = setpoint(10u, 0, 0.0f);
    it.flags = 2u;
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    it.flags = 0u;
    it.kind = 2u;
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    br_refq_item_t seg = {BR_REFQ_SEGMENT, 0u, 10u, 0u, 0, 0.0f, 1.0f, 0.0f, 0.0f};
    assert_int_equal(br_refq_push(&q, &seg), BR_E_INPUT); /* 0 periods */
    seg.periods = 1000u;
    seg.j = 1.0e14f; /* j T^3 / 6 = 1.7e14 counts over 1 s */
    assert_int_equal(br_refq_push(&q, &seg), BR_E_INPUT);
    seg.j = NAN;
    assert_int_equal(br_refq_push(&q, &seg), BR_E_INPUT);
    assert_int_equal(q.cnt.rejected, 9u);
    assert_int_equal(q.n, 0u);
    /* order: an item must start at or after the end of the last one queued */
    it = setpoint(10u, 0, 0.0f);
    assert_int_equal(br_refq_push(&q, &it), BR_OK);
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    it.tick = 9u;
    assert_int_equal(br_refq_push(&q, &it), BR_E_INPUT);
    assert_int_equal(q.cnt.late, 2u);
    it.tick = 11u;
    assert_int_equal(br_refq_push(&q, &it), BR_OK);
    assert_int_equal(br_refq_push(NULL, &it), BR_E_NULL);
}

/* fill, overflow (dropped and counted), then the items in order, one a period */
static void test_fill_overflow(void **st)
{
    (void)st;
    br_refq_t q;
    br_refq_cfg_t c = machine_cfg(8u);
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    for (uint32_t k = 0u; k < 11u; ++k) {
        const br_refq_item_t it = setpoint(k, (int32_t)(100u + k), 0.0f);
        assert_int_equal(br_refq_push(&q, &it), k < 8u ? BR_OK : BR_E_BUSY);
    }
    assert_int_equal(q.n, 8u);
    assert_int_equal(q.cnt.dropped, 3u);
    br_ref_t r;
    for (uint32_t k = 0u; k < 8u; ++k) {
        assert_int_equal(br_refq_step(&q, k, &r), BR_OK);
        assert_int_equal(r.ref_counts, (int32_t)(100u + k));
        assert_int_equal(q.state, BR_REFQ_STREAM);
    }
    assert_int_equal(q.n, 0u);
    /* a late item (over before its period) is dropped at the step and counted */
    br_refq_item_t it = setpoint(20u, 7, 0.0f);
    assert_int_equal(br_refq_push(&q, &it), BR_OK);
    it = setpoint(21u, 8, 0.0f);
    assert_int_equal(br_refq_push(&q, &it), BR_OK);
    assert_int_equal(br_refq_step(&q, 21u, &r), BR_OK);
    assert_int_equal(r.ref_counts, 8);
    assert_int_equal(q.cnt.late, 1u);
}

/* A cubic segment: each period's reference is the formula's, computed here in
 * double from the segment's fields: within 2 float32 ulps of the position (the
 * displacement is a float32 Horner form, one rounding per operation, below
 * 2^24 counts) and 1e-6 relative on the velocity. */
static void test_segment_formula(void **st)
{
    (void)st;
    br_refq_t q;
    br_refq_cfg_t c = machine_cfg(4u);
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    const br_refq_item_t seg = {BR_REFQ_SEGMENT, BR_REFQ_FLAG_LAST, 100u, 400u, -5000, 0.25f,
                                20000.0f, -3.0e4f, 2.5e5f};
    assert_int_equal(br_refq_push(&q, &seg), BR_OK);
    br_ref_t r;
    const double dt = (double)DT, rpc = (double)BR_MACHINE_RAD_PER_COUNT_F;
    for (uint32_t k = 100u; k < 500u; ++k) {
        assert_int_equal(br_refq_step(&q, k, &r), BR_OK);
        const double t = (double)(k - 100u) * dt;
        const double p = -5000.0 + 0.25 + 20000.0 * t - 0.5 * 3.0e4 * t * t + 2.5e5 * t * t * t / 6.0;
        const double w = (20000.0 - 3.0e4 * t + 0.5 * 2.5e5 * t * t) * rpc;
        const double got = (double)r.ref_counts + (double)r.ref_frac_counts;
        BR_ASSERT_NEAR(got, p, 2.0 * ldexp(1.0, -23) * fmax(1.0, fabs(p + 5000.0)));
        BR_ASSERT_NEAR(r.ref_omega_radps, w, 1e-6 * fmax(fabs(w), 20000.0 * rpc));
        assert_true(r.ref_frac_counts >= 0.0f && r.ref_frac_counts < 1.0f);
    }
    /* the last item: the reference holds its end, no underrun */
    const br_ref_t end = r;
    for (uint32_t k = 500u; k < 600u; ++k) {
        assert_int_equal(br_refq_step(&q, k, &r), BR_OK);
        assert_int_equal(r.ref_counts, end.ref_counts);
        assert_true(r.ref_frac_counts == end.ref_frac_counts);
        assert_true(r.ref_omega_radps == 0.0f);
    }
    assert_int_equal(q.state, BR_REFQ_IDLE);
    assert_int_equal(q.cnt.underruns, 0u);
}

/* Underrun: the last setpoint at speed v goes on for HOLD periods, then the
 * reference brakes, its speed falling by at most max_accel dt a period (the
 * machine's), to 0; fault_periods after the last setpoint, BR_E_FAULT. */
static void test_underrun(void **st)
{
    (void)st;
    br_refq_t q;
    br_refq_cfg_t c = machine_cfg(8u);
    assert_int_equal(br_refq_init(&q, &c), BR_OK);
    const float v_cpp = 0.5f * c.max_speed_mps * c.counts_per_m * DT; /* half the machine's speed */
    const float omega = v_cpp / DT * c.rad_per_count;
    const br_refq_item_t it = setpoint(0u, 1000, omega);
    assert_int_equal(br_refq_push(&q, &it), BR_OK);
    br_ref_t r;
    assert_int_equal(br_refq_step(&q, 0u, &r), BR_OK);
    double prev = 1000.0, prev_v = (double)v_cpp;
    const double a_max = (double)c.max_accel_mps2 * (double)c.counts_per_m * (double)DT * (double)DT;
    uint32_t k = 1u;
    for (; k <= HOLD; ++k) {
        assert_int_equal(br_refq_step(&q, k, &r), BR_OK);
        assert_int_equal(q.state, BR_REFQ_HOLD);
        const double p = (double)r.ref_counts + (double)r.ref_frac_counts;
        BR_ASSERT_NEAR(p - prev, (double)v_cpp, 1e-3);
        prev = p;
    }
    assert_int_equal(q.cnt.underruns, 1u);
    int stopped = 0;
    for (; k <= c.fault_periods; ++k) {
        assert_int_equal(br_refq_step(&q, k, &r), BR_OK);
        assert_int_equal(q.state, BR_REFQ_BRAKE);
        const double p = (double)r.ref_counts + (double)r.ref_frac_counts;
        const double v = p - prev;
        /* within max_accel (float32 rounding of a position near 1e4..1e6 counts) */
        assert_true(v >= -1e-3);
        assert_true(prev_v - v <= a_max * (1.0 + 1e-3) + 1e-3);
        BR_ASSERT_NEAR(r.ref_omega_radps, v / (double)DT * (double)c.rad_per_count, 1e-3 * (double)omega + 1e-9);
        stopped = (v == 0.0);
        prev = p;
        prev_v = v;
    }
    assert_true(stopped);
    /* one period more: the fault, and every period after it */
    assert_int_equal(br_refq_step(&q, k, &r), BR_E_FAULT);
    assert_int_equal(q.state, BR_REFQ_FAULT);
    assert_int_equal(br_refq_step(&q, k + 1u, &r), BR_E_FAULT);
    /* a new item ends the underrun */
    const br_refq_item_t again = setpoint(k + 2u, 5, 0.0f);
    assert_int_equal(br_refq_push(&q, &again), BR_OK);
    assert_int_equal(br_refq_step(&q, k + 2u, &r), BR_OK);
    assert_int_equal(r.ref_counts, 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_push_guards),
        cmocka_unit_test(test_fill_overflow),
        cmocka_unit_test(test_segment_formula),
        cmocka_unit_test(test_underrun),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
