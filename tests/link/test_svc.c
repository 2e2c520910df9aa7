/* SPDX-License-Identifier: Apache-2.0 */
/* The command service (br_svc) driven as a host would: encoded frames
 * (br_link_encode) through a fake byte channel, against a br_app_t with the
 * machine's UKF on a fake HAL. Starts disarmed (duty 0), arm moves, disarm
 * stops, a fault reported once with its tick and reset, the enable input,
 * an underrun that faults, and the run-time parameters. */
#include "br_test.h"

#include <math.h>
#include <string.h>

#include "bristle/br_machine_cfg.h"
#include "bristle/br_param.h"
#include "bristle/br_svc.h"
#include "link_support.h"
#include "bristle_gen/machine/br_machine.h"

#define DT BR_MACHINE_CTRL_PERIOD_S_F
#define HOLD 3u

typedef struct {
    int32_t counts;
    float duty;
    int on;
    int enable; /* the enable input */
} hw_t;

typedef struct {
    uint8_t rx[4096]; /* host to target */
    size_t rx_len, rx_pos;
    uint8_t tx[16384]; /* target to host */
    size_t tx_len;
    uint16_t host_seq;
    int tx_blocked; /* 1: the host reads nothing, the target's transmit queue fills */
} wire_t;

static br_status_t hw_enc(void *ctx, int32_t *c)
{
    *c = ((hw_t *)ctx)->counts;
    return BR_OK;
}
static br_status_t hw_pwm(void *ctx, float d)
{
    ((hw_t *)ctx)->duty = d;
    return BR_OK;
}
static br_status_t hw_tick(void *ctx, uint32_t *t)
{
    (void)ctx;
    *t = 0u;
    return BR_OK;
}
static br_status_t hw_off(void *ctx)
{
    ((hw_t *)ctx)->on = 0;
    return BR_OK;
}
static br_status_t hw_on(void *ctx)
{
    ((hw_t *)ctx)->on = 1;
    return BR_OK;
}
static int hw_enable(void *ctx)
{
    return ((hw_t *)ctx)->enable;
}

static size_t wire_read(void *ctx, uint8_t *buf, size_t n)
{
    wire_t *w = ctx;
    const size_t k = n < w->rx_len - w->rx_pos ? n : w->rx_len - w->rx_pos;
    memcpy(buf, &w->rx[w->rx_pos], k);
    w->rx_pos += k;
    return k;
}
static size_t wire_write(void *ctx, const uint8_t *buf, size_t n)
{
    wire_t *w = ctx;
    if (w->tx_blocked) return 0u;
    const size_t k = n < sizeof w->tx - w->tx_len ? n : sizeof w->tx - w->tx_len;
    memcpy(&w->tx[w->tx_len], buf, k);
    w->tx_len += k;
    return k;
}

/* the host sends one request */
static void host_send(wire_t *w, uint8_t id, const uint8_t *p, size_t len)
{
    size_t n = 0u;
    assert_int_equal(br_link_encode(&w->rx[w->rx_len], sizeof w->rx - w->rx_len, id, w->host_seq++, p, len, &n),
                     BR_OK);
    w->rx_len += n;
}

static void put32(uint8_t *p, uint32_t v)
{
    for (unsigned i = 0u; i < 4u; ++i) p[i] = (uint8_t)(v >> (8u * i));
}
static void putf(uint8_t *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    put32(p, u);
}
static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static void host_param_write(wire_t *w, uint16_t id, float v)
{
    uint8_t p[BR_LINK_MSG_PARAM_WRITE_LEN];
    p[0] = (uint8_t)id;
    p[1] = (uint8_t)(id >> 8);
    putf(&p[BR_LINK_MSG_PARAM_WRITE_OFF_VALUE], v);
    host_send(w, BR_LINK_MSG_PARAM_WRITE, p, sizeof p);
}

static void host_setpoint(wire_t *w, uint32_t tick, int32_t counts, float omega, uint8_t flags)
{
    uint8_t p[BR_LINK_MSG_SETPOINT_LEN];
    put32(&p[BR_LINK_MSG_SETPOINT_OFF_TICK], tick);
    put32(&p[BR_LINK_MSG_SETPOINT_OFF_COUNTS], (uint32_t)counts);
    putf(&p[BR_LINK_MSG_SETPOINT_OFF_FRAC], 0.0f);
    putf(&p[BR_LINK_MSG_SETPOINT_OFF_OMEGA_RADPS], omega);
    p[BR_LINK_MSG_SETPOINT_OFF_FLAGS] = flags;
    host_send(w, BR_LINK_MSG_SETPOINT, p, sizeof p);
}

static void host_segment(wire_t *w, uint32_t tick, uint32_t periods, int32_t counts)
{
    uint8_t p[BR_LINK_MSG_SEGMENT_LEN];
    memset(p, 0, sizeof p); /* frac, v, a, j 0: a segment holding counts */
    put32(&p[BR_LINK_MSG_SEGMENT_OFF_TICK], tick);
    put32(&p[BR_LINK_MSG_SEGMENT_OFF_PERIODS], periods);
    put32(&p[BR_LINK_MSG_SEGMENT_OFF_COUNTS], (uint32_t)counts);
    host_send(w, BR_LINK_MSG_SEGMENT, p, sizeof p);
}

typedef struct {
    hw_t hw;
    wire_t wire;
    br_hal_t hal;
    br_ctrl_cfg_t ctrl;
    br_ukf_cfg_t ukfc;
    br_ukf_t ukf;
    br_app_mem_t mem;
    br_app_cfg_t cfg;
    br_app_t app;
    br_svc_cfg_t scfg;
    br_svc_t svc;
} rig_t;

static br_refq_cfg_t refq_cfg(void)
{
    const br_app_machine_t m = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t mo = br_app_motion_cfg(&m);
    br_refq_cfg_t c = {8u, DT, BR_MACHINE_RAD_PER_COUNT_F, mo.counts_per_m, mo.max_speed_mps, mo.max_accel_mps2,
                       HOLD, 0u};
    c.fault_periods = br_refq_fault_periods_min(&c);
    return c;
}

/* the machine's UKF, the tests' controller at the machine's period, wide drive protections */
static void rig_init(rig_t *g, int with_enable, int enable0)
{
    memset(g, 0, sizeof *g);
    g->hw.enable = enable0;
    const br_hal_t hal = {&g->hw, hw_enc, hw_pwm, hw_tick, hw_off, hw_on};
    g->hal = hal;
    const br_ctrl_cfg_t k = {{-0.5f, -0.01f, -10.0f}, DT, 0.64f, 0.64f, BR_MACHINE_RAD_PER_COUNT_F,
                             BR_MACHINE_LEAD_MPRAD_F};
    g->ctrl = k;
    const br_ukf_cfg_t u = BR_MACHINE_UKF_CFG_DEFAULT(DT);
    g->ukfc = u;
    g->mem.ukf = &g->ukf;
    const br_app_cfg_t c = {&g->ctrl, BR_APP_EST_UKF, NULL, &g->ukfc, NULL, {100000u, 3u, 10u, 9u},
                            BR_TEST_WIDE_MOTION};
    g->cfg = c;
    assert_int_equal(br_app_init(&g->app, &g->cfg, &g->hal, &g->mem), BR_OK);
    const br_svc_cfg_t s = {64u, BR_LINK_TX_BUF_BYTES, refq_cfg(), 10u, with_enable ? hw_enable : NULL, &g->hw,
                            BR_MACHINE_NAME};
    g->scfg = s;
    const br_byte_chan_t ch = {&g->wire, wire_read, wire_write};
    assert_int_equal(br_svc_init(&g->svc, &g->scfg, &g->app, &g->cfg, &g->mem, &ch), BR_OK);
}

/* the frames of id the target sent since the last call (up to max) */
static size_t host_frames(rig_t *g, uint8_t id, br_link_frame_t *out, size_t max)
{
    static br_link_frame_t all[256];
    const size_t n = link_decode_all(g->wire.tx, g->wire.tx_len, all, 256u);
    size_t k = 0u;
    for (size_t i = 0u; i < n && i < 256u; ++i) {
        if (all[i].id == id) {
            if (k < max) out[k] = all[i];
            ++k;
        }
    }
    return k;
}

static void steps(rig_t *g, unsigned n)
{
    for (unsigned i = 0u; i < n; ++i) (void)br_svc_step(&g->svc);
}

/* an arm request and its period; the tick after it */
static uint32_t rig_arm(rig_t *g)
{
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 1u);
    return g->svc.tick;
}

/* the reports a period queues leave at the next period's br_link_step */
#define SENT(g) steps((g), 1u)

static void test_init_guards(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    const br_byte_chan_t ch = {&g->wire, wire_read, wire_write};
    br_svc_t s;
    assert_int_equal(br_svc_init(NULL, &g->scfg, &g->app, &g->cfg, &g->mem, &ch), BR_E_NULL);
    assert_int_equal(br_svc_init(&s, &g->scfg, &g->app, &g->cfg, &g->mem, NULL), BR_E_NULL);
    br_svc_cfg_t c = g->scfg;
    c.status_periods = 0u;
    assert_int_equal(br_svc_init(&s, &c, &g->app, &g->cfg, &g->mem, &ch), BR_E_PARAM);
    assert_int_equal(br_svc_step(&s), BR_E_STATE);
    c = g->scfg;
    c.ref.queue_len = 0u;
    assert_int_equal(br_svc_init(&s, &c, &g->app, &g->cfg, &g->mem, &ch), BR_E_PARAM);
    c = g->scfg;
    c.rx_budget_bytes = 0u;
    assert_int_equal(br_svc_init(&s, &c, &g->app, &g->cfg, &g->mem, &ch), BR_E_PARAM);
    br_app_t cold;
    memset(&cold, 0, sizeof cold);
    assert_int_equal(br_svc_init(&s, &g->scfg, &cold, &g->cfg, &g->mem, &ch), BR_E_STATE);
    test_free(g);
}

/* disarmed at start (duty 0, outputs off) until an arm; the arm moves the
 * axis towards a setpoint; a disarm stops it at once */
static void test_arm_disarm(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    host_setpoint(&g->wire, 5u, 500, 0.0f, 0u); /* a setpoint while disarmed does not move it */
    steps(g, 20u);
    assert_true(g->hw.duty == 0.0f);
    assert_int_equal(g->hw.on, 0);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    br_link_frame_t f[4];
    assert_true(host_frames(g, BR_LINK_MSG_STATUS, f, 4u) >= 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_STATUS_OFF_ARMED], 0);
    assert_int_equal(f[0].payload[BR_LINK_MSG_STATUS_OFF_FAULT], BR_APP_FAULT_DISARMED);

    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    const uint32_t t0 = g->svc.tick;
    host_setpoint(&g->wire, t0 + 5u, 500, 0.0f, 0u);
    steps(g, 10u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    assert_int_equal(g->hw.on, 1);
    assert_true(g->hw.duty != 0.0f); /* driving towards the setpoint 500 counts ahead */
    g->wire.tx_len = 0u;
    host_send(&g->wire, BR_LINK_MSG_DISARM, NULL, 0u);
    steps(g, 1u);
    assert_true(g->hw.duty == 0.0f);
    assert_int_equal(g->hw.on, 0);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    SENT(g);
    /* a disarm is not a fault: a status, no fault report */
    assert_int_equal(host_frames(g, BR_LINK_MSG_FAULT, f, 4u), 0u);
    assert_int_equal(host_frames(g, BR_LINK_MSG_STATUS, f, 4u), 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_STATUS_OFF_ARMED], 0);
    test_free(g);
}

/* a fault latches: one fault report with its cause and period, whatever the
 * periods after; no arm before a fault_reset, then the arm */
static void test_fault_once_and_reset(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 5u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    const uint32_t t_fault = g->svc.tick;
    g->hw.counts += 200000; /* beyond enc_max_delta_counts: ENC_JUMP */
    steps(g, 30u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_ENC_JUMP);
    br_link_frame_t f[4];
    assert_int_equal(host_frames(g, BR_LINK_MSG_FAULT, f, 4u), 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_FAULT_OFF_CAUSE], BR_APP_FAULT_ENC_JUMP);
    assert_int_equal(get32(&f[0].payload[BR_LINK_MSG_FAULT_OFF_TICK]), t_fault);
    assert_true(g->hw.duty == 0.0f);
    /* an arm without a reset is refused */
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 2u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_ENC_JUMP);
    assert_int_equal(g->svc.cnt.arm_refused, 1u);
    g->wire.tx_len = 0u;
    host_send(&g->wire, BR_LINK_MSG_FAULT_RESET, NULL, 0u);
    steps(g, 1u);
    SENT(g);
    assert_true(host_frames(g, BR_LINK_MSG_STATUS, f, 4u) >= 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_STATUS_OFF_FAULT], BR_APP_FAULT_DISARMED);
    assert_int_equal(get32(&f[0].payload[BR_LINK_MSG_STATUS_OFF_FAULT_TICK]), t_fault);
    assert_int_equal(g->hw.on, 0); /* a reset does not arm */
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 2u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    assert_int_equal(g->hw.on, 1);
    test_free(g);
}

/* the enable input: its rising edge arms, low disarms, an arm request needs it high */
/* the period's request stays readable after the step (svc.cmd): the
 * recorder's, which the service does not act on, reach the caller; a period
 * without a request reads NONE */
static void test_request_exposed(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_NONE);
    const uint8_t p[BR_LINK_MSG_REC_DUMP_LEN] = {37u, 0u};
    host_send(&g->wire, BR_LINK_MSG_REC_DUMP, p, sizeof p);
    steps(g, 1u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_REC_DUMP);
    assert_int_equal(g->svc.cmd.first, 37);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    steps(g, 1u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_NONE);
    test_free(g);
}

static void test_enable_input(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 1, 0);
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 3u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    assert_int_equal(g->svc.cnt.arm_refused, 1u);
    g->hw.enable = 1;
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    assert_int_equal(g->hw.on, 1);
    g->hw.enable = 0;
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    assert_int_equal(g->hw.on, 0);
    test_free(g);
}

/* an enable already high at start does not arm: it takes a rising edge */
static void test_enable_high_at_start(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 1, 1);
    steps(g, 5u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    assert_int_equal(g->hw.on, 0);
    g->hw.enable = 0;
    steps(g, 1u);
    g->hw.enable = 1;
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    test_free(g);
}

/* a stream that stops: hold, brake, then REF_UNDERRUN latched and reported */
static void test_underrun_faults(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    const uint32_t t0 = rig_arm(g);
    for (uint32_t k = 0u; k < 4u; ++k) host_setpoint(&g->wire, t0 + 1u + k, 0, 0.0f, 0u);
    steps(g, 6u);
    assert_int_equal(g->svc.ref.state, BR_REFQ_HOLD);
    const uint32_t fp = g->scfg.ref.fault_periods;
    /* the underrun began at t0 + 5: the fault at its fault_periods + 1-th period */
    while (g->svc.tick < t0 + 5u + fp) {
        steps(g, 1u);
        assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    }
    g->wire.tx_len = 0u;
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_REF_UNDERRUN);
    SENT(g);
    br_link_frame_t f[2];
    assert_int_equal(host_frames(g, BR_LINK_MSG_FAULT, f, 2u), 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_FAULT_OFF_CAUSE], BR_APP_FAULT_REF_UNDERRUN);
    assert_int_equal(g->svc.ref.n, 0u);
    /* ref_status carries the counters */
    steps(g, 10u);
    assert_true(host_frames(g, BR_LINK_MSG_REF_STATUS, f, 2u) >= 1u);
    assert_int_equal(get32(&f[0].payload[BR_LINK_MSG_REF_STATUS_OFF_UNDERRUNS]), 1u);
    test_free(g);
}

/* the application and the service again, with another link budget K */
static void rig_budget(rig_t *g, size_t k)
{
    assert_int_equal(br_app_init(&g->app, &g->cfg, &g->hal, &g->mem), BR_OK);
    g->scfg.rx_budget_bytes = k;
    const br_byte_chan_t ch = {&g->wire, wire_read, wire_write};
    assert_int_equal(br_svc_init(&g->svc, &g->scfg, &g->app, &g->cfg, &g->mem, &ch), BR_OK);
}

/* one step; the bytes the link took in it */
static uint32_t step_bytes(rig_t *g)
{
    const uint32_t before = g->svc.link.dec.cnt.rx_bytes;
    steps(g, 1u);
    return g->svc.link.dec.cnt.rx_bytes - before;
}

/* up to BR_SVC_REQUESTS_MAX (2) requests a period, the second only after a
 * setpoint or segment and only within the period's K bytes: two 27-byte
 * setpoint frames fit K = 64, two 39-byte segment frames do not */
static void test_two_refs_a_period(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    /* an arm and two setpoints: the arm alone in its period */
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    const uint32_t t0 = g->svc.tick;
    host_setpoint(&g->wire, t0 + 100u, 0, 0.0f, 0u);
    host_setpoint(&g->wire, t0 + 101u, 0, 0.0f, 0u);
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    assert_int_equal(g->svc.ref.n, 0u);
    steps(g, 1u);
    assert_int_equal(g->svc.ref.n, 2u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_SETPOINT);
    /* six setpoints: two a period */
    for (uint32_t k = 2u; k < 8u; ++k) host_setpoint(&g->wire, t0 + 100u + k, 0, 0.0f, 0u);
    for (uint32_t k = 1u; k <= 3u; ++k) {
        assert_true(step_bytes(g) <= g->scfg.rx_budget_bytes);
        assert_int_equal(g->svc.ref.n, 2u + 2u * k);
    }
    /* a setpoint, then a request of another kind: both in the period, the latter the caller's */
    (void)br_refq_clear(&g->svc.ref);
    const uint8_t d[BR_LINK_MSG_REC_DUMP_LEN] = {37u, 0u};
    host_setpoint(&g->wire, t0 + 200u, 0, 0.0f, 0u);
    host_send(&g->wire, BR_LINK_MSG_REC_DUMP, d, sizeof d);
    host_setpoint(&g->wire, t0 + 201u, 0, 0.0f, 0u);
    steps(g, 1u);
    assert_int_equal(g->svc.ref.n, 1u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_REC_DUMP);
    assert_int_equal(g->svc.cmd.first, 37);
    steps(g, 1u);
    assert_int_equal(g->svc.ref.n, 2u);
    /* segments: the second frame does not fit the period's K bytes; 3 in two periods */
    (void)br_refq_clear(&g->svc.ref);
    for (uint32_t k = 0u; k < 3u; ++k) host_segment(&g->wire, t0 + 300u + 4u * k, 4u, 0);
    assert_true(step_bytes(g) <= g->scfg.rx_budget_bytes);
    assert_int_equal(g->svc.ref.n, 1u);
    assert_true(step_bytes(g) <= g->scfg.rx_budget_bytes);
    assert_int_equal(g->svc.ref.n, 3u);
    /* with K = 256 (eight setpoint frames would fit) still two a period */
    rig_budget(g, 256u);
    const uint32_t t1 = rig_arm(g);
    for (uint32_t k = 0u; k < 6u; ++k) host_setpoint(&g->wire, t1 + 100u + k, 0, 0.0f, 0u);
    steps(g, 1u);
    assert_int_equal(g->svc.ref.n, 2u);
    steps(g, 1u);
    assert_int_equal(g->svc.ref.n, 4u);
    assert_int_equal(g->svc.ref.cnt.dropped + g->svc.ref.cnt.late + g->svc.ref.cnt.rejected, 0u);
    test_free(g);
}

/* a host that sends more than the queue holds: two a period fill it, each
 * item beyond refused and counted (dropped), reported by ref_status; the
 * queued ones kept in order */
static void test_overflow_refused(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    const uint32_t t0 = rig_arm(g);
    const uint32_t len = g->scfg.ref.queue_len, extra = 4u;
    for (uint32_t k = 0u; k < len + extra; ++k) host_setpoint(&g->wire, t0 + 100u + k, (int32_t)k, 0.0f, 0u);
    steps(g, (len + extra) / 2u);
    assert_int_equal(g->svc.ref.n, len);
    assert_int_equal(g->svc.ref.cnt.dropped, extra);
    for (uint32_t k = 0u; k < len; ++k) {
        const br_refq_item_t *it = &g->svc.ref.q[(g->svc.ref.head + k) % len];
        assert_int_equal(it->tick, t0 + 100u + k);
        assert_int_equal(it->counts, (int32_t)k);
    }
    g->wire.tx_len = 0u;
    steps(g, g->scfg.status_periods + 1u);
    br_link_frame_t f[4];
    assert_true(host_frames(g, BR_LINK_MSG_REF_STATUS, f, 4u) >= 1u);
    assert_int_equal(f[0].payload[BR_LINK_MSG_REF_STATUS_OFF_QUEUED], len);
    assert_int_equal(f[0].payload[BR_LINK_MSG_REF_STATUS_OFF_FREE], 0u);
    assert_int_equal(get32(&f[0].payload[BR_LINK_MSG_REF_STATUS_OFF_DROPPED]), extra);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    test_free(g);
}

/* the answer to the last parameter request */
static br_link_frame_t last_value(rig_t *g)
{
    SENT(g);
    br_link_frame_t f[32];
    const size_t n = host_frames(g, BR_LINK_MSG_PARAM_VALUE, f, 32u);
    assert_true(n >= 1u && n <= 32u);
    return f[n - 1u];
}
static float value_of(const br_link_frame_t *f)
{
    const uint32_t u = get32(&f->payload[BR_LINK_MSG_PARAM_VALUE_OFF_VALUE]);
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}
static int8_t status_of(const br_link_frame_t *f)
{
    return (int8_t)f->payload[BR_LINK_MSG_PARAM_VALUE_OFF_STATUS];
}

static void test_params(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    const float rpc = BR_MACHINE_RAD_PER_COUNT_F;
    /* in range, disarmed: accepted, into the RAM copy; the filter gets it at the arm */
    host_param_write(&g->wire, BR_LINK_PARAM_R_COUNTS2, 0.5f);
    steps(g, 1u);
    br_link_frame_t f = last_value(g);
    assert_int_equal(status_of(&f), BR_OK);
    BR_ASSERT_NEAR(value_of(&f), 0.5f, 1e-6);
    assert_true(g->ukf.cfg.est.r_var_rad2 == g->ukfc.est.r_var_rad2);
    /* the gate's transient term: counts on the wire, rad in the filter (rad_per_count^1) */
    host_param_write(&g->wire, BR_LINK_PARAM_OUTLIER_TRANSIENT_COUNTS, 10.0f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_OK);
    BR_ASSERT_NEAR(value_of(&f), 10.0f, 1e-5);
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    assert_true(g->ukf.cfg.est.r_var_rad2 == 0.5f * rpc * rpc);
    assert_true(g->ukf.cfg.est.outlier_transient_rad == 10.0f * rpc);
    /* while armed: a parameter read at init only is refused, the live one taken at once */
    host_param_write(&g->wire, BR_LINK_PARAM_OUTLIER_SIGMA, 7.0f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_STATE);
    assert_true(g->ukf.cfg.est.outlier_sigma == g->ukfc.est.outlier_sigma);
    host_param_write(&g->wire, BR_LINK_PARAM_COMP_AHEAD_PERIODS, 0.5f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_OK);
    assert_true(g->ukf.cfg.est.comp_ahead_periods == 0.5f);
    host_send(&g->wire, BR_LINK_MSG_DISARM, NULL, 0u);
    steps(g, 1u);
    /* out of the machine file's range, not finite, not whole, unknown, another estimator's */
    host_param_write(&g->wire, BR_LINK_PARAM_OUTLIER_SIGMA, 2.0e4f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    BR_ASSERT_NEAR(value_of(&f), 2.0e4f, 0.0);
    host_param_write(&g->wire, BR_LINK_PARAM_OUTLIER_SIGMA, 0.0f); /* (0, 1e4]: 0 excluded */
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    host_param_write(&g->wire, BR_LINK_PARAM_R_COUNTS2, NAN);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    host_param_write(&g->wire, BR_LINK_PARAM_R_COUNTS2, 0.0f); /* R: 0 excluded */
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    host_param_write(&g->wire, BR_LINK_PARAM_Q_Z_M2, 1.0e-40f); /* subnormal */
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    host_param_write(&g->wire, BR_LINK_PARAM_REANCHOR_AFTER, 2.5f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    host_param_write(&g->wire, 0x7777u, 1.0f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_INPUT);
    host_param_write(&g->wire, BR_LINK_PARAM_Q_THETA_COUNTS2, 1.0f); /* the PF's, not this UKF's */
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_INPUT);
    /* the table's own rule, apart from the estimators' (which refuse subnormals too) */
    assert_int_equal(br_param_check(BR_LINK_PARAM_Q_Z_M2, BR_LINK_PARAM_EST_UKF, 1.0e-40f), BR_E_PARAM);
    assert_int_equal(br_param_check(BR_LINK_PARAM_Q_Z_M2, BR_LINK_PARAM_EST_UKF, 0.0f), BR_OK);
    /* the estimators' own rule on the whole configuration: R below BR_EST_R_MIN_COUNTS2 */
    host_param_write(&g->wire, BR_LINK_PARAM_R_COUNTS2, 0.5f * BR_EST_R_MIN_COUNTS2);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_PARAM);
    assert_int_equal(g->svc.link.dec.cnt.rx_refused, 10u);
    /* an integer, and a read of it */
    host_param_write(&g->wire, BR_LINK_PARAM_REANCHOR_AFTER, 12.0f);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_OK);
    uint8_t rd[2] = {(uint8_t)BR_LINK_PARAM_REANCHOR_AFTER, 0u};
    host_send(&g->wire, BR_LINK_MSG_PARAM_READ, rd, 2u);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_OK);
    assert_true(value_of(&f) == 12.0f);
    rd[0] = 0x77u;
    host_send(&g->wire, BR_LINK_MSG_PARAM_READ, rd, 2u);
    steps(g, 1u);
    f = last_value(g);
    assert_int_equal(status_of(&f), BR_E_INPUT);
    test_free(g);
}

/* the filter refuses a configuration at the arm that the write's checks let
 * through: the arm fails, the last good parameters are back for the next arm */
static void test_arm_restores_params(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    const br_est_cfg_t before = g->ukf.cfg.est;
    g->svc.pend.r_var_rad2 = NAN; /* as if a write had slipped past its checks */
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_DISARMED);
    assert_int_equal(g->svc.cnt.arm_failed, 1u);
    assert_memory_equal(&g->ukf.cfg.est, &before, sizeof before);
    host_send(&g->wire, BR_LINK_MSG_ARM, NULL, 0u);
    steps(g, 1u);
    assert_int_equal(g->app.fault, BR_APP_FAULT_NONE);
    test_free(g);
}

/* the recorder's requests are the caller's: the service leaves them in
 * svc.cmd for br_rec_command (a dump over a service's link needs it), and the
 * next period without a request leaves kind NONE there */
static void test_rec_request_to_caller(void **st)
{
    (void)st;
    rig_t *g = test_malloc(sizeof *g);
    rig_init(g, 0, 0);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_NONE);
    uint8_t p[BR_LINK_MSG_REC_DUMP_LEN] = {37u, 0u};
    host_send(&g->wire, BR_LINK_MSG_REC_DUMP, p, sizeof p);
    steps(g, 1u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_REC_DUMP);
    assert_int_equal(g->svc.cmd.first, 37u);
    steps(g, 1u);
    assert_int_equal(g->svc.cmd.kind, BR_LINK_CMD_NONE);
    test_free(g);
}

/* A hello_reply that finds the transmit queue full waits for room: the host
 * that opened the session gets its answer, never silence (it is not retried
 * by a host that already sent its hello). */
static void test_hello_reply_waits_for_room(void **st)
{
    (void)st;
    static rig_t g;
    rig_init(&g, 0, 0);
    g.wire.tx_blocked = 1;
    steps(&g, 300u); /* the periodic reports fill the queue */
    const uint32_t deferred = g.svc.cnt.tx_deferred;
    assert_true(deferred > 0u);
    uint8_t p[BR_LINK_MSG_HELLO_LEN];
    put32(&p[BR_LINK_MSG_HELLO_OFF_SESSION], 0xCAFE5u);
    host_send(&g.wire, BR_LINK_MSG_HELLO, p, sizeof p);
    steps(&g, 5u);
    br_link_frame_t f[4];
    assert_int_equal(g.wire.tx_len, 0u);
    assert_true(g.svc.cnt.tx_deferred > deferred);
    g.wire.tx_blocked = 0;
    steps(&g, 40u);
    assert_int_equal(host_frames(&g, BR_LINK_MSG_HELLO_REPLY, f, 4u), 1u);
    assert_int_equal(get32(&f[0].payload[BR_LINK_MSG_HELLO_REPLY_OFF_SESSION]), 0xCAFE5u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_arm_disarm),
        cmocka_unit_test(test_fault_once_and_reset),
        cmocka_unit_test(test_request_exposed),
        cmocka_unit_test(test_enable_input),
        cmocka_unit_test(test_enable_high_at_start),
        cmocka_unit_test(test_underrun_faults),
        cmocka_unit_test(test_two_refs_a_period),
        cmocka_unit_test(test_overflow_refused),
        cmocka_unit_test(test_params),
        cmocka_unit_test(test_arm_restores_params),
        cmocka_unit_test(test_rec_request_to_caller),
        cmocka_unit_test(test_hello_reply_waits_for_room),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
