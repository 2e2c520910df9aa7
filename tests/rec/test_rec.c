/* SPDX-License-Identifier: Apache-2.0 */
/* The recorder and telemetry (bristle/br_rec.h, bristle/br_tlm.h;
 * docs/link.md, "Telemetry" and "The recorder"): configuration checks, the
 * ring's wrap, the trigger positions, the fault trigger on a running
 * application, the condition, the bounded and complete dump, telemetry's
 * decimation and its drops on a full link. */
#include "br_test.h"

#include <math.h>
#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_tlm.h"
#include "rec_support.h"

#define CAP_MAX 64u
static br_rec_slot_t slots[CAP_MAX];

static br_rec_cfg_t cfg_of(uint32_t cap, uint32_t pre)
{
    const br_rec_cfg_t c = {slots, cap, pre, 0.0f, 2u};
    return c;
}

/* pushes samples of ticks t0 .. t1 - 1 */
static void push_range(br_rec_t *r, uint32_t t0, uint32_t t1)
{
    for (uint32_t t = t0; t < t1; ++t) {
        const br_rec_sample_t s = rec_sample_of(t);
        assert_int_equal(br_rec_push(r, &s), BR_OK);
    }
}

/* the ticks the ring holds are first, first + 1, ... (n of them) */
static void assert_ticks(const br_rec_t *r, uint32_t first, uint32_t n)
{
    assert_int_equal(r->n, n);
    for (uint32_t i = 0; i < n; ++i) {
        br_rec_sample_t s;
        assert_int_equal(br_rec_get(r, i, &s), BR_OK);
        assert_int_equal(s.tick, first + i);
    }
}

static void test_rec_init_guards(void **st)
{
    (void)st;
    br_rec_t r;
    br_rec_cfg_t c = cfg_of(8u, 3u);
    assert_int_equal(br_rec_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_rec_init(&r, NULL), BR_E_NULL);
    c.slots = NULL;
    assert_int_equal(br_rec_init(&r, &c), BR_E_NULL);
    /* each range check on its own; after a failure the recorder is not usable */
    const struct {
        uint32_t cap, pre, frames;
        float thr;
        br_status_t want;
    } cases[] = {
        {0u, 0u, 2u, 0.0f, BR_E_PARAM},                       /* zero capacity (no room for the trigger) */
        {BR_REC_CAPACITY_MAX + 1u, 0u, 2u, 0.0f, BR_E_PARAM}, /* index beyond the u16 */
        {8u, 8u, 2u, 0.0f, BR_E_PARAM},                       /* pre-trigger = capacity: no room for the trigger */
        {8u, 9u, 2u, 0.0f, BR_E_PARAM},                       /* pre-trigger > capacity */
        {8u, 7u, 0u, 0.0f, BR_E_PARAM},                       /* no dump frame per period */
        {8u, 7u, BR_REC_DUMP_FRAMES_MAX + 1u, 0.0f, BR_E_PARAM},
        {8u, 7u, 2u, -1.0f, BR_E_PARAM},                      /* negative threshold */
        {8u, 7u, 2u, NAN, BR_E_PARAM},
        {8u, 7u, 2u, INFINITY, BR_E_PARAM},
        {8u, 7u, BR_REC_DUMP_FRAMES_MAX, 3.0f, BR_OK},        /* the edges accepted */
        {1u, 0u, 1u, 0.0f, BR_OK},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        const br_rec_cfg_t ci = {slots, cases[i].cap, cases[i].pre, cases[i].thr, cases[i].frames};
        assert_int_equal(br_rec_init(&r, &ci), cases[i].want);
        const br_rec_sample_t s = rec_sample_of(1u);
        assert_int_equal(br_rec_push(&r, &s), cases[i].want == BR_OK ? BR_OK : BR_E_STATE);
    }
    c = cfg_of(8u, 3u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    assert_int_equal(br_rec_push(&r, NULL), BR_E_NULL);
    br_rec_sample_t s;
    assert_int_equal(br_rec_get(&r, 1u, &s), BR_E_PARAM); /* one sample held */
}

static void test_tlm_init_guards(void **st)
{
    (void)st;
    br_tlm_t t;
    br_tlm_cfg_t c = {0u};
    assert_int_equal(br_tlm_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_tlm_init(&t, NULL), BR_E_NULL);
    assert_int_equal(br_tlm_init(&t, &c), BR_E_PARAM); /* N = 0 */
    br_link_t l;
    static golden_sink_t sink;
    assert_int_equal(rec_link_init(&l, &sink, 4096u), BR_OK);
    const br_rec_sample_t s = rec_sample_of(0u);
    assert_int_equal(br_tlm_step(&t, &l, &s), BR_E_STATE);
    c.every_n_periods = 1u;
    assert_int_equal(br_tlm_init(&t, &c), BR_OK);
    assert_int_equal(br_tlm_step(&t, NULL, &s), BR_E_NULL);
}

/* the ring keeps the newest capacity samples, oldest first */
static void test_ring_wrap(void **st)
{
    (void)st;
    br_rec_t r;
    const br_rec_cfg_t c = cfg_of(5u, 2u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    push_range(&r, 0u, 3u);
    assert_ticks(&r, 0u, 3u);
    push_range(&r, 3u, 12u); /* two and a bit turns */
    assert_ticks(&r, 7u, 5u);
    assert_int_equal(r.state, BR_REC_ARMED);
    assert_int_equal(br_rec_count(&r), 0u); /* no capture yet */
}

/* capacity 10, pre 3: the trigger sample, 3 before it, 6 after it */
static void test_trigger_positions(void **st)
{
    (void)st;
    br_rec_t r;
    br_rec_cfg_t c = cfg_of(10u, 3u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    push_range(&r, 0u, 12u);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_range(&r, 12u, 18u); /* the trigger (12) and 5 after it */
    assert_int_equal(r.state, BR_REC_COLLECTING);
    push_range(&r, 18u, 19u); /* the 6th after it */
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(br_rec_count(&r), 10u);
    assert_int_equal(br_rec_trigger_index(&r), 3u);
    assert_int_equal(r.trig_tick, 12u);
    assert_int_equal(r.cause, BR_REC_TRIG_COMMAND);
    assert_ticks(&r, 9u, 10u);
    /* held: later samples change nothing, a trigger is refused */
    push_range(&r, 19u, 40u);
    assert_ticks(&r, 9u, 10u);
    assert_int_equal(br_rec_trigger(&r), BR_E_STATE);

    /* a trigger soon after the arm: the pre-trigger share holds what there is */
    assert_int_equal(br_rec_arm(&r), BR_OK);
    push_range(&r, 100u, 101u);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_range(&r, 101u, 108u);
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(br_rec_count(&r), 8u);
    assert_int_equal(br_rec_trigger_index(&r), 1u);
    assert_ticks(&r, 100u, 8u);

    /* pre 0: the trigger is the oldest; pre capacity - 1: the newest, done at once */
    c = cfg_of(4u, 0u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    push_range(&r, 0u, 9u);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_range(&r, 9u, 13u);
    assert_int_equal(br_rec_trigger_index(&r), 0u);
    assert_ticks(&r, 9u, 4u);
    c = cfg_of(4u, 3u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    push_range(&r, 0u, 9u);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_range(&r, 9u, 10u);
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(br_rec_trigger_index(&r), 3u);
    assert_ticks(&r, 6u, 4u);
}

static void push_fault(br_rec_t *r, uint32_t t, br_app_fault_t f)
{
    br_rec_sample_t s = rec_sample_of(t);
    s.fault = (uint8_t)f;
    assert_int_equal(br_rec_push(r, &s), BR_OK);
}

/* a fault latching triggers; the disarmed state does not; a fault after a
 * command trigger takes the capture over; one while a capture is held is counted */
static void test_fault_trigger(void **st)
{
    (void)st;
    br_rec_t r;
    const br_rec_cfg_t c = cfg_of(8u, 5u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    for (uint32_t t = 0; t < 10u; ++t) push_fault(&r, t, BR_APP_FAULT_DISARMED);
    for (uint32_t t = 10; t < 20u; ++t) push_fault(&r, t, BR_APP_FAULT_NONE);
    assert_int_equal(r.state, BR_REC_ARMED);
    push_fault(&r, 20u, BR_APP_FAULT_FOLLOWING);
    assert_int_equal(r.state, BR_REC_COLLECTING);
    for (uint32_t t = 21; t < 30u; ++t) push_fault(&r, t, BR_APP_FAULT_FOLLOWING);
    assert_int_equal(r.cause, BR_REC_TRIG_FAULT);
    assert_int_equal(br_rec_trigger_index(&r), 5u);
    assert_ticks(&r, 15u, 8u); /* 15..19 before, 20, 21..22 after */
    /* held: re-armed axis faulting again is counted, not captured */
    push_fault(&r, 30u, BR_APP_FAULT_NONE);
    push_fault(&r, 31u, BR_APP_FAULT_SPEED);
    assert_int_equal(r.missed_faults, 1u);
    assert_ticks(&r, 15u, 8u);

    /* a command trigger, then a fault within its post-trigger samples */
    assert_int_equal(br_rec_arm(&r), BR_OK);
    for (uint32_t t = 40; t < 50u; ++t) push_fault(&r, t, BR_APP_FAULT_NONE);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_fault(&r, 50u, BR_APP_FAULT_NONE);
    push_fault(&r, 51u, BR_APP_FAULT_NONE);
    push_fault(&r, 52u, BR_APP_FAULT_ENC_JUMP);
    for (uint32_t t = 53; t < 60u; ++t) push_fault(&r, t, BR_APP_FAULT_ENC_JUMP);
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(r.cause, BR_REC_TRIG_FAULT);
    assert_int_equal(r.trig_tick, 52u);
    assert_int_equal(br_rec_trigger_index(&r), 5u);
    assert_ticks(&r, 47u, 8u);
}

typedef struct {
    int32_t counts;
} enc_t;
static br_status_t enc_read(void *ctx, int32_t *c)
{
    *c = ((enc_t *)ctx)->counts;
    return BR_OK;
}
static br_status_t pwm_write(void *ctx, float d)
{
    (void)ctx;
    (void)d;
    return BR_OK;
}
static br_status_t tick_wait(void *ctx, uint32_t *t)
{
    (void)ctx;
    *t = 0u;
    return BR_OK;
}

/* the production application faulting (an encoder jump): the capture holds
 * the pre-trigger periods before the one the fault latched in, that period
 * and the post-trigger ones, taken from br_app_t by br_rec_sample_take */
static void test_fault_trigger_app(void **st)
{
    (void)st;
    enc_t e = {1000};
    const br_hal_t hal = {&e, enc_read, pwm_write, tick_wait, NULL, NULL};
    const br_ctrl_cfg_t cc = {{-0.5f, -0.01f, -10.0f}, 1e-3f, 0.64f, 0.64f, 6.0e-6f, 1.27e-3f};
    br_app_cfg_t ac;
    memset(&ac, 0, sizeof ac);
    ac.ctrl = &cc;
    ac.est = BR_APP_EST_NONE;
    ac.guard = (br_app_guard_cfg_t){100u, 3u, 10u, 2u};
    ac.motion = BR_TEST_WIDE_MOTION;
    br_app_t app;
    assert_int_equal(br_app_init(&app, &ac, &hal, NULL), BR_OK);
    br_rec_t r;
    const br_rec_cfg_t c = cfg_of(32u, 20u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    const br_ref_t ref = {1000, 0.5f, 0.0f};
    uint32_t fault_tick = 0u;
    for (uint32_t t = 0; t < 200u; ++t) {
        if (t == 5u) assert_int_equal(br_app_arm(&app), BR_OK);
        if (t == 150u) e.counts += 100000; /* far above enc_max_delta_counts */
        const br_status_t s = br_app_step(&app, &ref);
        if (t > 5u && s == BR_E_FAULT && fault_tick == 0u) fault_tick = t;
        br_rec_sample_t smp;
        assert_int_equal(br_rec_sample_take(&smp, &app, t, s), BR_OK);
        assert_int_equal(br_rec_push(&r, &smp), BR_OK);
    }
    assert_int_equal(fault_tick, 150u);
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(r.cause, BR_REC_TRIG_FAULT);
    assert_int_equal(r.trig_tick, 150u);
    assert_int_equal(br_rec_trigger_index(&r), 20u);
    assert_ticks(&r, 130u, 32u);
    br_rec_sample_t s;
    assert_int_equal(br_rec_get(&r, 19u, &s), BR_OK);
    assert_int_equal(s.fault, BR_APP_FAULT_NONE);
    assert_int_equal(s.counts, 1000);
    assert_int_equal(br_rec_get(&r, 20u, &s), BR_OK);
    assert_int_equal(s.fault, BR_APP_FAULT_ENC_JUMP);
    assert_int_equal(s.status, BR_E_FAULT);
    assert_int_equal(s.duty, 0.0f);
}

/* br_rec_sample_take reads each field from its place in br_app_t */
static void test_sample_take(void **st)
{
    (void)st;
    br_app_t app;
    memset(&app, 0, sizeof app);
    app.last_counts = -123456;
    app.lim_counts = 987654;
    app.lim_frac = 0.25f;
    app.last.duty = -0.375f;
    app.last.saturated = 1;
    app.F_hat_N = 6.5f;
    app.n_lock = 7u;
    app.fault = BR_APP_FAULT_TRAVEL;
    app.stop = BR_APP_STOP_OPEN;
    app.ref_limited = 1;
    app.n_stale = 2u;
    br_rec_sample_t s;
    assert_int_equal(br_rec_sample_take(NULL, &app, 0u, BR_OK), BR_E_NULL);
    assert_int_equal(br_rec_sample_take(&s, NULL, 0u, BR_OK), BR_E_NULL);
    assert_int_equal(br_rec_sample_take(&s, &app, 0xFFFFFFF0u, BR_W_OUTLIER), BR_OK);
    assert_int_equal(s.tick, 0xFFFFFFF0u);
    assert_int_equal(s.counts, -123456);
    assert_int_equal(s.ref_counts, 987654);
    assert_true(s.ref_frac == 0.25f && s.duty == -0.375f && s.F_hat_N == 6.5f);
    assert_int_equal(s.n_outliers, 7u);
    assert_int_equal(s.status, BR_W_OUTLIER);
    assert_int_equal(s.fault, BR_APP_FAULT_TRAVEL);
    assert_int_equal(s.flags, BR_REC_FLAG_REF_LIMITED | BR_REC_FLAG_SATURATED | BR_REC_FLAG_HELD |
                                  ((unsigned)BR_APP_STOP_OPEN << BR_REC_FLAG_STOP_SHIFT));
    /* packed and back, every field */
    uint8_t b[BR_REC_SAMPLE_BYTES];
    br_rec_sample_pack(&s, b);
    br_rec_sample_t u;
    memset(&u, 0xA5, sizeof u);
    br_rec_sample_unpack(b, &u);
    assert_true(u.tick == s.tick && u.counts == s.counts && u.ref_counts == s.ref_counts &&
                u.ref_frac == s.ref_frac && u.duty == s.duty && u.F_hat_N == s.F_hat_N &&
                u.n_outliers == s.n_outliers && u.status == s.status && u.fault == s.fault && u.flags == s.flags);
    assert_int_equal(b[BR_LINK_MSG_TLM_SAMPLE_OFF_TICK], 0xF0u); /* little-endian */
}

/* |following| above the threshold on a running axis triggers; at the
 * threshold, or with a fault, it does not; the count difference wraps */
static void test_condition_trigger(void **st)
{
    (void)st;
    br_rec_t r;
    br_rec_cfg_t c = cfg_of(8u, 2u);
    c.trig_following_counts = 100.0f;
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    br_rec_sample_t s = rec_sample_of(1u);
    s.ref_counts = s.counts + 100; /* following 100 + 0.5 - 0.5 = 100: not above */
    assert_int_equal(br_rec_push(&r, &s), BR_OK);
    assert_int_equal(r.state, BR_REC_ARMED);
    s.ref_frac = 0.75f; /* 100.25, but the axis is faulted */
    s.fault = (uint8_t)BR_APP_FAULT_DISARMED;
    assert_int_equal(br_rec_push(&r, &s), BR_OK);
    assert_int_equal(r.state, BR_REC_ARMED);
    /* across the count's wrap: INT32_MIN - INT32_MAX is 1 modulo 2^32 */
    s.fault = (uint8_t)BR_APP_FAULT_NONE;
    s.counts = INT32_MAX;
    s.ref_counts = INT32_MIN;
    assert_true(fabsf(br_rec_following_counts(&s) - 1.25f) < 1e-6f);
    assert_int_equal(br_rec_push(&r, &s), BR_OK);
    assert_int_equal(r.state, BR_REC_ARMED);
    s.counts = 5;
    s.ref_counts = 5 - 100; /* -100.25: above in magnitude */
    s.ref_frac = 0.25f;
    assert_int_equal(br_rec_push(&r, &s), BR_OK);
    assert_int_equal(r.state, BR_REC_COLLECTING);
    assert_int_equal(r.cause, BR_REC_TRIG_CONDITION);
    /* threshold 0: no condition */
    c.trig_following_counts = 0.0f;
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    s.ref_counts = s.counts + 1000000;
    assert_int_equal(br_rec_push(&r, &s), BR_OK);
    assert_int_equal(r.state, BR_REC_ARMED);
}

/* decodes the sink: the frames in order */
static size_t decode_sink(const golden_sink_t *k, br_link_frame_t *f, size_t max)
{
    br_link_dec_t d;
    br_link_dec_init(&d);
    size_t n = 0;
    br_link_frame_t one;
    for (size_t i = 0; i < k->len; ++i) {
        if (br_link_dec_push(&d, k->buf[i], &one)) {
            assert_true(n < max);
            f[n++] = one;
        }
    }
    assert_int_equal(d.cnt.rx_frames, n); /* nothing dropped */
    return n;
}

static br_link_frame_t frames[256];

/* a dump over a slow channel: at most dump_frames_per_period frames queued
 * per period, every index once and in order, then rec_end */
static void test_dump_bounded_complete(void **st)
{
    (void)st;
    br_rec_t r;
    br_rec_cfg_t c = cfg_of(40u, 10u);
    c.dump_frames_per_period = 3u;
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    push_range(&r, 0u, 50u);
    assert_int_equal(br_rec_trigger(&r), BR_OK);
    push_range(&r, 50u, 80u); /* the trigger and 29 after it */
    assert_int_equal(r.state, BR_REC_DONE);
    static golden_sink_t sink;
    br_link_t l;
    assert_int_equal(rec_link_init(&l, &sink, 16u), BR_OK); /* 16 bytes a period: the queue fills */
    assert_int_equal(br_rec_dump_request(&r, 0u), BR_OK);
    uint32_t periods = 0u;
    while (r.dump_active || l.tx_len > 0u) {
        const uint32_t before = l.dec.cnt.tx_frames;
        assert_int_equal(br_rec_dump_step(&r, &l), BR_OK);
        assert_true(l.dec.cnt.tx_frames - before <= 3u);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        assert_true(++periods < 1000u);
    }
    assert_true(l.dec.cnt.tx_busy > 0u); /* the channel was the bottleneck */
    const size_t n = decode_sink(&sink, frames, 256);
    assert_int_equal(n, 41u);
    for (uint32_t i = 0; i < 40u; ++i) {
        assert_int_equal(frames[i].id, BR_LINK_MSG_REC_SAMPLE);
        assert_int_equal(frames[i].payload[0] | (frames[i].payload[1] << 8), i);
        br_rec_sample_t s;
        br_rec_sample_unpack(&frames[i].payload[BR_LINK_MSG_REC_SAMPLE_OFF_TICK], &s);
        assert_int_equal(s.tick, 40u + i);
    }
    const uint8_t *e = frames[40].payload;
    assert_int_equal(frames[40].id, BR_LINK_MSG_REC_END);
    assert_int_equal(e[BR_LINK_MSG_REC_END_OFF_COUNT], 40u);
    assert_int_equal(e[BR_LINK_MSG_REC_END_OFF_TRIGGER_INDEX], 10u);
    assert_int_equal(e[BR_LINK_MSG_REC_END_OFF_TRIGGER_TICK], 50u);
    assert_int_equal(e[BR_LINK_MSG_REC_END_OFF_CAUSE], BR_REC_TRIG_COMMAND);
    assert_int_equal(e[BR_LINK_MSG_REC_END_OFF_STATE], BR_REC_DONE);

    /* again from index 37: 37, 38, 39 and the end; the capture is still held */
    assert_int_equal(rec_link_init(&l, &sink, 4096u), BR_OK);
    assert_int_equal(br_rec_dump_request(&r, 37u), BR_OK);
    for (int p = 0; p < 3; ++p) {
        assert_int_equal(br_rec_dump_step(&r, &l), BR_OK);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
    }
    assert_false(r.dump_active);
    assert_int_equal(decode_sink(&sink, frames, 256), 4u);
    assert_int_equal(frames[0].payload[0], 37u);
    assert_int_equal(frames[3].id, BR_LINK_MSG_REC_END);

    /* before a capture is complete: rec_end alone, count 0, the state */
    assert_int_equal(br_rec_arm(&r), BR_OK);
    push_range(&r, 0u, 5u);
    assert_int_equal(rec_link_init(&l, &sink, 4096u), BR_OK);
    assert_int_equal(br_rec_dump_request(&r, 0u), BR_OK);
    assert_int_equal(br_rec_dump_step(&r, &l), BR_OK);
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(&l, &cmd), BR_OK);
    assert_int_equal(decode_sink(&sink, frames, 256), 1u);
    assert_int_equal(frames[0].id, BR_LINK_MSG_REC_END);
    assert_int_equal(frames[0].payload[BR_LINK_MSG_REC_END_OFF_COUNT], 0u);
    assert_int_equal(frames[0].payload[BR_LINK_MSG_REC_END_OFF_STATE], BR_REC_ARMED);
    assert_int_equal(br_rec_dump_step(NULL, &l), BR_E_NULL);
}

/* the host's requests reach the recorder through the link's commands */
static void test_commands(void **st)
{
    (void)st;
    br_rec_t r;
    const br_rec_cfg_t c = cfg_of(4u, 1u);
    assert_int_equal(br_rec_init(&r, &c), BR_OK);
    br_link_cmd_t cmd;
    memset(&cmd, 0, sizeof cmd);
    cmd.kind = BR_LINK_CMD_ARM; /* the application's, not the recorder's */
    assert_int_equal(br_rec_command(&r, &cmd), 0);
    cmd.kind = BR_LINK_CMD_REC_TRIGGER;
    assert_int_equal(br_rec_command(&r, &cmd), 1);
    push_range(&r, 0u, 3u);
    assert_int_equal(r.state, BR_REC_DONE);
    assert_int_equal(r.trig_tick, 0u);
    cmd.kind = BR_LINK_CMD_REC_DUMP;
    cmd.first = 2u;
    assert_int_equal(br_rec_command(&r, &cmd), 1);
    assert_true(r.dump_active && r.dump_next == 2u);
    cmd.kind = BR_LINK_CMD_REC_ARM;
    assert_int_equal(br_rec_command(&r, &cmd), 1);
    assert_true(r.state == BR_REC_ARMED && r.n == 0u && !r.dump_active);
    assert_int_equal(br_rec_command(NULL, &cmd), 0);
}

/* N = 3: the samples of periods 0, 3, 6, 9; N = 1: every period */
static void test_tlm_decimation(void **st)
{
    (void)st;
    static golden_sink_t sink;
    const uint32_t ns[2] = {3u, 1u};
    for (int k = 0; k < 2; ++k) {
        br_link_t l;
        assert_int_equal(rec_link_init(&l, &sink, 4096u), BR_OK);
        br_tlm_t t;
        const br_tlm_cfg_t c = {ns[k]};
        assert_int_equal(br_tlm_init(&t, &c), BR_OK);
        for (uint32_t p = 0; p < 10u; ++p) {
            const br_rec_sample_t s = rec_sample_of(p);
            assert_int_equal(br_tlm_step(&t, &l, &s), BR_OK);
            br_link_cmd_t cmd;
            assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        }
        const size_t n = decode_sink(&sink, frames, 256);
        assert_int_equal(n, (10u + ns[k] - 1u) / ns[k]);
        assert_int_equal(t.n_sent, n);
        assert_int_equal(t.n_dropped, 0u);
        for (size_t i = 0; i < n; ++i) {
            assert_int_equal(frames[i].id, BR_LINK_MSG_TLM_SAMPLE);
            assert_int_equal(frames[i].len, BR_REC_SAMPLE_BYTES);
            br_rec_sample_t s;
            br_rec_sample_unpack(frames[i].payload, &s);
            assert_int_equal(s.tick, i * ns[k]);
        }
    }
}

/* a channel that takes nothing: the link's queue fills, every later sample is
 * dropped and counted, nothing waits and nothing grows */
static void test_tlm_drop_full(void **st)
{
    (void)st;
    static golden_sink_t sink;
    br_link_t l;
    assert_int_equal(rec_link_init(&l, &sink, 0u), BR_OK);
    br_tlm_t t;
    const br_tlm_cfg_t c = {1u};
    assert_int_equal(br_tlm_init(&t, &c), BR_OK);
    /* a tlm_sample frame on the wire: the body, a COBS code byte, two delimiters */
    const size_t frame = BR_REC_SAMPLE_BYTES + BR_LINK_BODY_MIN + 1u + 2u;
    const uint32_t fits = (uint32_t)(BR_LINK_TX_BUF_BYTES / frame);
    uint32_t busy = 0u;
    for (uint32_t p = 0; p < 50u; ++p) {
        const br_rec_sample_t s = rec_sample_of(p);
        const br_status_t r = br_tlm_step(&t, &l, &s);
        assert_true(r == BR_OK || r == BR_E_BUSY);
        busy += (r == BR_E_BUSY);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        assert_true(l.tx_len <= BR_LINK_TX_BUF_BYTES);
    }
    assert_int_equal(t.n_sent, fits);
    assert_int_equal(t.n_dropped, 50u - fits);
    assert_int_equal(busy, 50u - fits);
    assert_int_equal(l.dec.cnt.tx_busy, 50u - fits);
    assert_int_equal(sink.len, 0u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rec_init_guards),
        cmocka_unit_test(test_tlm_init_guards),
        cmocka_unit_test(test_ring_wrap),
        cmocka_unit_test(test_trigger_positions),
        cmocka_unit_test(test_fault_trigger),
        cmocka_unit_test(test_fault_trigger_app),
        cmocka_unit_test(test_sample_take),
        cmocka_unit_test(test_condition_trigger),
        cmocka_unit_test(test_dump_bounded_complete),
        cmocka_unit_test(test_commands),
        cmocka_unit_test(test_tlm_decimation),
        cmocka_unit_test(test_tlm_drop_full),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
