/* SPDX-License-Identifier: Apache-2.0 */
/* The CMSDK APB UART byte channel and the image in the loop's port
 * (hal/mps2, bristle/br_cmsdk_uart.h, bristle/br_pil_port.h; docs/link.md,
 * "The image in the loop") against fake register blocks in RAM.
 *
 * A fake block is plain memory: reading DATA does not clear RXFULL and
 * writing DATA does not set TXFULL, so the test plays the UART: it puts a
 * byte in DATA with RXFULL set, and clears RXFULL once the driver took it. */
#include "br_test.h"

#include <string.h>

#include "bristle/br_cmsdk_uart.h"
#include "bristle/br_link.h"
#include "bristle/br_link_pil.h"
#include "bristle/br_pil_port.h"

#define RING 8u

typedef struct {
    br_cmsdk_uart_regs_t regs;
    uint8_t rx[RING], tx[RING];
    br_cmsdk_uart_t u;
    br_byte_chan_t chan;
} rig_t;

static void rig_init(rig_t *g)
{
    memset(g, 0, sizeof *g);
    const br_cmsdk_uart_cfg_t c = {&g->regs, g->rx, RING, g->tx, RING, 16u};
    assert_int_equal(br_cmsdk_uart_init(&g->u, &c, &g->chan), BR_OK);
    /* init cleared the overrun flags (write 1 to clear); the UART drops them */
    assert_int_equal(g->regs.STATE, BR_CMSDK_UART_STATE_RXOVR | BR_CMSDK_UART_STATE_TXOVR);
    g->regs.STATE = 0u;
}

/* the UART receives byte b; the driver polls once; the UART's RXFULL drops if it was taken */
static void line_in(rig_t *g, uint8_t b)
{
    g->regs.DATA = b;
    g->regs.STATE |= BR_CMSDK_UART_STATE_RXFULL;
    const uint32_t before = g->u.cnt.rx_bytes;
    br_cmsdk_uart_poll(&g->u);
    if (g->u.cnt.rx_bytes != before) g->regs.STATE &= ~BR_CMSDK_UART_STATE_RXFULL;
}

static void test_init_guards(void **state)
{
    (void)state;
    br_cmsdk_uart_regs_t r;
    uint8_t b[4];
    br_cmsdk_uart_t u;
    br_byte_chan_t ch;
    br_cmsdk_uart_cfg_t c = {&r, b, 4u, b, 4u, 16u};
    memset(&r, 0, sizeof r);
    assert_int_equal(br_cmsdk_uart_init(NULL, &c, &ch), BR_E_NULL);
    assert_int_equal(br_cmsdk_uart_init(&u, &c, NULL), BR_E_NULL);
    c.regs = NULL;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_E_NULL);
    c.regs = &r;
    c.rx_len = 0u;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_E_PARAM);
    c.rx_len = BR_CMSDK_UART_RING_MAX + 1u;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_E_PARAM);
    c.rx_len = 4u;
    c.tx_len = 0u;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_E_PARAM);
    c.tx_len = 4u;
    c.bauddiv = 15u;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_E_PARAM);
    assert_int_equal(r.CTRL, 0u); /* a refused configuration leaves the UART alone */
    c.bauddiv = 16u;
    assert_int_equal(br_cmsdk_uart_init(&u, &c, &ch), BR_OK);
    assert_int_equal(r.BAUDDIV, 16u);
    assert_int_equal(r.CTRL, BR_CMSDK_UART_CTRL_TXEN | BR_CMSDK_UART_CTRL_RXEN); /* no interrupt */
    assert_ptr_equal(ch.ctx, &u);
}

/* bytes come through the ring in order, across its wrap; a full ring leaves the byte in the UART */
static void test_rx_ring(void **state)
{
    (void)state;
    rig_t g;
    rig_init(&g);
    uint8_t out[RING];
    assert_int_equal(g.chan.read(g.chan.ctx, out, sizeof out), 0u); /* nothing there: 0, at once */
    for (uint8_t round = 0; round < 3; round++) {
        for (uint8_t i = 0; i < 5; i++) line_in(&g, (uint8_t)(10 * round + i));
        assert_int_equal(g.chan.read(g.chan.ctx, out, sizeof out), 5u);
        for (uint8_t i = 0; i < 5; i++) assert_int_equal(out[i], 10 * round + i);
    }
    for (uint8_t i = 0; i < RING; i++) line_in(&g, i);
    line_in(&g, 0xAA); /* the ring is full: the byte stays in DATA, RXFULL stays set */
    assert_int_equal(g.u.cnt.rx_bytes, 15u + RING);
    assert_true((g.regs.STATE & BR_CMSDK_UART_STATE_RXFULL) != 0u);
    assert_int_equal(g.chan.read(g.chan.ctx, out, 3u), 3u);
    br_cmsdk_uart_poll(&g.u); /* room again: the next poll takes it */
    assert_int_equal(g.u.cnt.rx_bytes, 16u + RING);
}

/* write takes what fits, never waits; one byte to DATA per poll, only when TXFULL is clear */
static void test_tx(void **state)
{
    (void)state;
    rig_t g;
    rig_init(&g);
    const uint8_t msg[12] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
    g.regs.STATE = BR_CMSDK_UART_STATE_TXFULL;
    assert_int_equal(g.chan.write(g.chan.ctx, msg, sizeof msg), RING); /* the ring's room */
    assert_int_equal(g.u.cnt.tx_short, 1u);
    assert_int_equal(g.u.cnt.tx_bytes, 0u); /* TXFULL: nothing to DATA */
    g.regs.STATE = 0u;
    for (uint8_t i = 0; i < RING; i++) {
        br_cmsdk_uart_poll(&g.u);
        assert_int_equal(g.regs.DATA, msg[i]);
    }
    br_cmsdk_uart_poll(&g.u);
    assert_int_equal(g.u.cnt.tx_bytes, RING);
}

static void test_overruns_counted(void **state)
{
    (void)state;
    rig_t g;
    rig_init(&g);
    g.regs.STATE = BR_CMSDK_UART_STATE_RXOVR;
    br_cmsdk_uart_poll(&g.u);
    assert_int_equal(g.u.cnt.rx_overruns, 1u);
    assert_int_equal(g.regs.STATE, BR_CMSDK_UART_STATE_RXOVR); /* the write-1-to-clear of the flag */
    g.regs.STATE = BR_CMSDK_UART_STATE_TXOVR;
    br_cmsdk_uart_poll(&g.u);
    assert_int_equal(g.u.cnt.tx_overruns, 1u);
}

/* a frame's bytes through the UART one by one reach the link's decoder whole */
static void test_link_over_uart(void **state)
{
    (void)state;
    rig_t g;
    rig_init(&g);
    br_link_t link;
    const br_link_cfg_t lc = {64u, BR_LINK_TX_BUF_BYTES, NULL, NULL};
    assert_int_equal(br_link_init(&link, &lc, &g.chan), BR_OK);
    uint8_t fr[BR_LINK_FRAME_MAX];
    size_t n = 0;
    assert_int_equal(br_link_encode(fr, sizeof fr, BR_LINK_MSG_ARM, 7u, NULL, 0u, &n), BR_OK);
    br_link_cmd_t cmd;
    int got = 0;
    for (size_t i = 0; i < n; i++) {
        line_in(&g, fr[i]);
        assert_int_equal(br_link_step(&link, &cmd), BR_OK);
        got |= cmd.kind == BR_LINK_CMD_ARM;
    }
    assert_true(got);
}

/* the PIL port over two fake UARTs: a tick waits for the link's bytes, counts and duty pass */
typedef struct {
    rig_t plant, link;
    br_pil_port_t port;
    br_hal_t hal;
} pil_rig_t;

static void pil_init(pil_rig_t *r, uint32_t wait_polls)
{
    rig_init(&r->plant);
    rig_init(&r->link);
    const br_pil_port_cfg_t c = {&r->plant.u, r->plant.chan, &r->link.u, wait_polls};
    assert_int_equal(br_pil_port_init(&r->port, &c, &r->hal), BR_OK);
}

/* the tick frame's bytes into the plant UART (the ring holds RING: the test feeds what fits) */
static void tick_bytes(pil_rig_t *r, uint32_t tick, int32_t counts, uint32_t link_bytes, uint8_t *fr, size_t *n)
{
    const br_link_pil_tick_t t = {tick, counts, link_bytes};
    uint8_t pay[BR_LINK_MSG_PIL_TICK_LEN];
    br_link_pil_tick_pack(pay, &t);
    assert_int_equal(br_link_encode(fr, BR_LINK_FRAME_MAX, BR_LINK_MSG_PIL_TICK, (uint16_t)(tick + 1u), pay,
                                    sizeof pay, n), BR_OK);
    (void)r;
}

static void test_pil_port(void **state)
{
    (void)state;
    pil_rig_t r;
    pil_init(&r, 1000u);
    br_pil_port_cfg_t bad = r.port.cfg;
    bad.wait_polls = 0u;
    br_pil_port_t p2;
    br_hal_t h2;
    assert_int_equal(br_pil_port_init(&p2, &bad, &h2), BR_E_PARAM);
    /* no tick: the wait gives up after its polls */
    uint32_t tick = 99u;
    assert_int_equal(r.hal.tick_wait(r.hal.ctx, &tick), BR_E_STATE);
    /* a tick whose link bytes (2) have not come: it waits, and gives up */
    uint8_t fr[BR_LINK_FRAME_MAX];
    size_t n = 0;
    tick_bytes(&r, 5u, -123456, 2u, fr, &n);
    for (size_t i = 0; i < n; i++) {
        line_in(&r.plant, fr[i]);
        if (i % 4u == 3u) { /* the ring is small: the port's decoder empties it as the test goes */
            assert_int_equal(r.hal.tick_wait(r.hal.ctx, &tick), BR_E_STATE);
        }
    }
    assert_int_equal(r.hal.tick_wait(r.hal.ctx, &tick), BR_E_STATE);
    assert_int_equal(r.port.n_ticks, 0u);
    line_in(&r.link, 0x11);
    line_in(&r.link, 0x22); /* the link's 2 bytes are in: the period runs */
    assert_int_equal(r.hal.tick_wait(r.hal.ctx, &tick), BR_OK);
    assert_int_equal(tick, 5u);
    int32_t c = 0;
    assert_int_equal(r.hal.encoder_read(r.hal.ctx, &c), BR_OK);
    assert_int_equal(c, -123456);
    /* the PWM port: off at init, clamped, non-finite holds 0 */
    assert_int_equal(r.port.on, 0u);
    assert_int_equal(r.hal.pwm_enable(r.hal.ctx), BR_OK);
    assert_int_equal(r.hal.pwm_write(r.hal.ctx, 1.5f), BR_OK);
    assert_true(r.port.duty == 1.0f);
    assert_int_equal(r.hal.pwm_write(r.hal.ctx, NAN), BR_E_INPUT);
    assert_true(r.port.duty == 0.0f);
    assert_int_equal(r.hal.pwm_write(r.hal.ctx, -0.25f), BR_OK);
    /* the report: a pil_out frame with the duty, the outputs and the sample, decoded as the host does */
    br_rec_sample_t s;
    memset(&s, 0, sizeof s);
    s.tick = 5u;
    s.duty = -0.25f;
    s.F_hat_N = 3.5f;
    s.status = 1;
    assert_int_equal(br_pil_port_report(&r.port, &s), BR_E_BUSY); /* the 8-byte ring cannot take a frame */
    assert_int_equal(r.port.n_report_short, 1u);
}

static void test_pil_out_round_trip(void **state)
{
    (void)state;
    br_link_pil_out_t o;
    memset(&o, 0, sizeof o);
    o.port_duty = -0.25f;
    o.on = 1u;
    o.s.tick = 77u;
    o.s.counts = -5;
    o.s.duty = -0.25f;
    o.s.F_hat_N = 3.5f;
    o.s.status = -6;
    o.s.fault = 4u;
    o.s.flags = 2u;
    br_link_frame_t f = {BR_LINK_MSG_PIL_OUT, 1u, BR_LINK_MSG_PIL_OUT_LEN, {0}};
    br_link_pil_out_pack(f.payload, &o);
    br_link_pil_out_t back;
    assert_int_equal(br_link_pil_out_unpack(&f, &back), BR_OK);
    assert_true(back.port_duty == o.port_duty && back.on == 1u && back.s.tick == 77u && back.s.counts == -5);
    assert_int_equal(back.s.status, -6);
    assert_int_equal(back.s.fault, 4u);
    assert_int_equal(back.s.flags, 2u);
    f.len--; /* another length, or another id: refused */
    assert_int_equal(br_link_pil_out_unpack(&f, &back), BR_E_INPUT);
    f.len++;
    f.id = BR_LINK_MSG_PIL_TICK;
    assert_int_equal(br_link_pil_out_unpack(&f, &back), BR_E_INPUT);
    br_link_pil_tick_t t;
    assert_int_equal(br_link_pil_tick_unpack(&f, &t), BR_E_INPUT); /* a pil_tick's id with pil_out's length */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_rx_ring),
        cmocka_unit_test(test_tx),
        cmocka_unit_test(test_overruns_counted),
        cmocka_unit_test(test_link_over_uart),
        cmocka_unit_test(test_pil_port),
        cmocka_unit_test(test_pil_out_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
