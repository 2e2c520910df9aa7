/* SPDX-License-Identifier: Apache-2.0 */
/* The link (bristle/br_link.h, docs/link.md): the CRC's check value, the
 * encoder, every drop of the decoder with its counter, resynchronisation
 * after garbage, the bounded step over a fake byte channel, the command
 * decoding and the param_write range-check hook. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "bristle/br_link.h"
#include "link_support.h"

/* A fake channel: rx holds what the host sent, tx what the target wrote;
 * read_max / write_max limit each call (0: no limit), extra makes read lie. */
typedef struct {
    uint8_t rx[2048];
    size_t rx_len, rx_pos;
    uint8_t tx[2048];
    size_t tx_len;
    size_t read_max, write_max, extra;
    size_t last_read_n; /* the n of the last read call */
} chan_t;

static size_t ch_read(void *ctx, uint8_t *buf, size_t n)
{
    chan_t *c = ctx;
    c->last_read_n = n;
    size_t k = c->rx_len - c->rx_pos;
    if (k > n) k = n;
    if (c->read_max && k > c->read_max) k = c->read_max;
    memcpy(buf, &c->rx[c->rx_pos], k);
    c->rx_pos += k;
    return k + c->extra;
}

static size_t ch_write(void *ctx, const uint8_t *buf, size_t n)
{
    chan_t *c = ctx;
    size_t k = n;
    if (c->write_max && k > c->write_max) k = c->write_max;
    if (k > sizeof c->tx - c->tx_len) k = sizeof c->tx - c->tx_len;
    memcpy(&c->tx[c->tx_len], buf, k);
    c->tx_len += k;
    return k;
}

static void host_put(chan_t *c, const uint8_t *b, size_t n)
{
    assert_true(c->rx_len + n <= sizeof c->rx);
    memcpy(&c->rx[c->rx_len], b, n);
    c->rx_len += n;
}

/* a frame of the encoder into the channel */
static void host_frame(chan_t *c, uint8_t id, uint16_t seq, const uint8_t *p, size_t n)
{
    uint8_t w[BR_LINK_FRAME_MAX];
    size_t wl = 0;
    assert_int_equal(br_link_encode(w, sizeof w, id, seq, p, n, &wl), BR_OK);
    host_put(c, w, wl);
}

/* an arbitrary body (its CRC recomputed when fix_crc), stuffed and delimited */
static void host_body(chan_t *c, uint8_t *body, size_t n, int fix_crc)
{
    if (fix_crc) {
        const uint16_t crc = br_link_crc16(0xFFFFu, body, n - 2u);
        body[n - 2u] = (uint8_t)(crc >> 8);
        body[n - 1u] = (uint8_t)crc;
    }
    uint8_t w[512];
    w[0] = 0;
    const size_t m = br_link_cobs_encode(body, n, &w[1], sizeof w - 2u);
    assert_true(m > 0);
    w[m + 1] = 0;
    host_put(c, w, m + 2);
}

static br_link_cfg_t cfg_k(size_t k)
{
    br_link_cfg_t cfg = {k, 32u, NULL, NULL};
    return cfg;
}

static void link_up(br_link_t *l, chan_t *c, size_t k)
{
    memset(c, 0, sizeof *c);
    const br_byte_chan_t ch = {c, ch_read, ch_write};
    const br_link_cfg_t cfg = cfg_k(k);
    assert_int_equal(br_link_init(l, &cfg, &ch), BR_OK);
}

/* every command the channel holds, at most `steps` steps */
static size_t drain(br_link_t *l, br_link_cmd_t *cmds, size_t max, size_t steps)
{
    size_t n = 0;
    for (size_t i = 0; i < steps; ++i) {
        br_link_cmd_t c;
        assert_int_equal(br_link_step(l, &c), BR_OK);
        if (c.kind != BR_LINK_CMD_NONE && n < max) cmds[n++] = c;
    }
    return n;
}

static void test_crc_check_value(void **s)
{
    (void)s;
    /* CRC-16/CCITT-FALSE's catalogue check value */
    assert_int_equal(br_link_crc16(0xFFFFu, (const uint8_t *)"123456789", 9), 0x29B1);
}

static void test_cobs_has_no_zero(void **s)
{
    (void)s;
    uint8_t in[300], out[310];
    for (size_t i = 0; i < sizeof in; ++i) in[i] = (uint8_t)(i % 7u == 0u ? 0u : i);
    const size_t m = br_link_cobs_encode(in, sizeof in, out, sizeof out);
    assert_int_equal(m, sizeof in + 1u); /* a zero every 7 bytes: one code byte more in all */
    for (size_t i = 0; i < m; ++i) assert_int_not_equal(out[i], 0);
    assert_int_equal(br_link_cobs_encode(in, sizeof in, out, sizeof in), 0); /* cap too small */
}

static void test_encode_guards(void **s)
{
    (void)s;
    uint8_t w[BR_LINK_FRAME_MAX + 8], p[BR_LINK_PAYLOAD_MAX + 1] = {0};
    size_t wl = 99;
    assert_int_equal(br_link_encode(w, sizeof w, 1, 0, p, BR_LINK_PAYLOAD_MAX + 1u, &wl), BR_E_PARAM);
    assert_int_equal(wl, 0);
    /* the largest frame fits BR_LINK_FRAME_MAX, one byte less does not */
    assert_int_equal(br_link_encode(w, BR_LINK_FRAME_MAX, 1, 0, p, BR_LINK_PAYLOAD_MAX, &wl), BR_OK);
    assert_int_equal(wl, BR_LINK_FRAME_MAX);
    assert_int_equal(br_link_encode(w, BR_LINK_FRAME_MAX - 1u, 1, 0, p, BR_LINK_PAYLOAD_MAX, &wl), BR_E_PARAM);
    assert_int_equal(br_link_encode(NULL, sizeof w, 1, 0, p, 1, &wl), BR_E_NULL);
    assert_int_equal(br_link_encode(w, sizeof w, 1, 0, NULL, 1, &wl), BR_E_NULL);
}

static void test_init_validates(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    const br_byte_chan_t ch = {&c, ch_read, ch_write}, no_read = {&c, NULL, ch_write};
    br_link_cfg_t cfg = cfg_k(0);
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_E_PARAM);
    cfg = cfg_k(BR_LINK_RX_BUDGET_MAX + 1u);
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_E_PARAM);
    cfg = cfg_k(16);
    cfg.tx_budget_bytes = 0;
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_E_PARAM);
    cfg.tx_budget_bytes = BR_LINK_TX_BUF_BYTES + 1u;
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_E_PARAM);
    cfg = cfg_k(16);
    assert_int_equal(br_link_init(&l, &cfg, &no_read), BR_E_NULL);
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(&l, &cmd), BR_E_STATE);
    assert_int_equal(br_link_send(&l, 1, NULL, 0), BR_E_STATE);
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_OK);
}

static void test_commands_decoded(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 64);
    const uint8_t rd[2] = {0x34, 0x12};
    uint8_t wr[6] = {0x02, 0x00};
    const float v = -2.5f;
    memcpy(&wr[2], &v, 4); /* the host is little-endian, as the wire */
    host_frame(&c, BR_LINK_MSG_ARM, 1, NULL, 0);
    host_frame(&c, BR_LINK_MSG_PARAM_READ, 2, rd, 2);
    host_frame(&c, BR_LINK_MSG_PARAM_WRITE, 3, wr, 6);
    host_frame(&c, BR_LINK_MSG_DISARM, 4, NULL, 0);
    host_frame(&c, BR_LINK_MSG_FAULT_RESET, 5, NULL, 0);
    br_link_cmd_t cmds[8];
    assert_int_equal(drain(&l, cmds, 8, 20), 5);
    assert_int_equal(cmds[0].kind, BR_LINK_CMD_ARM);
    assert_int_equal(cmds[1].kind, BR_LINK_CMD_PARAM_READ);
    assert_int_equal(cmds[1].param, 0x1234);
    assert_int_equal(cmds[2].kind, BR_LINK_CMD_PARAM_WRITE);
    assert_int_equal(cmds[2].param, 2);
    assert_true(cmds[2].value == v);
    assert_int_equal(cmds[3].kind, BR_LINK_CMD_DISARM);
    assert_int_equal(cmds[4].kind, BR_LINK_CMD_FAULT_RESET);
    assert_int_equal(cmds[4].seq, 5);
    assert_int_equal(l.dec.cnt.rx_frames, 5);
}

/* one frame per body case; the counter that must move */
static void test_each_drop_counted(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 256);
    uint8_t b[BR_LINK_BODY_MAX + 4];
    /* short: 6 bytes */
    memset(b, 1, sizeof b);
    host_body(&c, b, 6, 0);
    /* a length byte of BR_LINK_PAYLOAD_MAX + 1 with that many bytes, and a
     * longer body: both pass BR_LINK_BODY_MAX */
    uint8_t big[BR_LINK_BODY_MAX + 4] = {BR_LINK_PAYLOAD_MAX + 1u, BR_LINK_VERSION, BR_LINK_MSG_ARM, 1, 0};
    host_body(&c, big, BR_LINK_BODY_MIN + BR_LINK_PAYLOAD_MAX + 1u, 1);
    big[0] = BR_LINK_PAYLOAD_MAX;
    host_body(&c, big, sizeof big, 1);
    /* bad length: says 1 payload byte, has 2 */
    uint8_t bl[9] = {1, BR_LINK_VERSION, BR_LINK_MSG_ARM, 1, 0, 7, 7, 0, 0};
    host_body(&c, bl, sizeof bl, 1);
    /* a length byte above BR_LINK_PAYLOAD_MAX on a short body: the length disagrees */
    bl[0] = 200;
    host_body(&c, bl, sizeof bl, 1);
    /* bad CRC */
    uint8_t bc[7] = {0, BR_LINK_VERSION, BR_LINK_MSG_ARM, 1, 0, 0, 0};
    host_body(&c, bc, sizeof bc, 1);
    bc[6] ^= 0x01u;
    host_body(&c, bc, sizeof bc, 0);
    /* wrong version, CRC right */
    uint8_t bv[7] = {0, BR_LINK_VERSION + 1u, BR_LINK_MSG_ARM, 2, 0, 0, 0};
    host_body(&c, bv, sizeof bv, 1);
    /* bad stuffing: a code byte promising 4 bytes, the delimiter after 2 */
    const uint8_t cobs_cut[5] = {0, 5, 1, 1, 0};
    host_put(&c, cobs_cut, sizeof cobs_cut);
    /* an unknown id, a report's id, a request with a payload of the wrong length */
    const uint8_t one = 9;
    host_frame(&c, 0x7F, 2, NULL, 0);
    host_frame(&c, BR_LINK_MSG_STATUS, 3, NULL, 0);
    host_frame(&c, BR_LINK_MSG_ARM, 4, &one, 1);
    br_link_cmd_t cmds[8];
    /* the first valid frame (the one before the bad CRC) is an arm */
    assert_int_equal(drain(&l, cmds, 8, 10), 1);
    const br_link_counters_t *k = &l.dec.cnt;
    assert_int_equal(k->rx_short, 1);
    assert_int_equal(k->rx_oversized, 2);
    assert_int_equal(k->rx_bad_len, 2);
    assert_int_equal(k->rx_bad_crc, 1);
    assert_int_equal(k->rx_bad_version, 1);
    assert_int_equal(k->rx_bad_cobs, 1);
    assert_int_equal(k->rx_unknown_id, 2);
    assert_int_equal(k->rx_bad_payload, 1);
    assert_int_equal(k->rx_frames, 4);
    assert_int_equal(k->rx_bytes, c.rx_len);
}

static void test_replay_dropped(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 256);
    /* first frame: any seq; then only 1..0x7FFF ahead (modulo 2^16) */
    const uint16_t seqs[] = {0xFFFE, 0xFFFE, 0xFFFD, 0xFFFF, 0x0000, 0x8000, 0x7FFF, 0x7FFF};
    const int fresh[] = {1, 0, 0, 1, 1, 0, 1, 0};
    for (size_t i = 0; i < sizeof seqs / sizeof seqs[0]; ++i) {
        host_frame(&c, BR_LINK_MSG_ARM, seqs[i], NULL, 0);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        assert_int_equal(cmd.kind == BR_LINK_CMD_ARM, fresh[i]);
    }
    assert_int_equal(l.dec.cnt.rx_replayed, 4);
    assert_int_equal(l.dec.cnt.rx_frames, 4);
}

/* one frame of id (hello: session number `session`) at seq: the kind the step hands on */
static br_link_cmd_kind_t hello_step(br_link_t *l, chan_t *c, uint8_t id, uint16_t seq, uint32_t session)
{
    const uint8_t p[4] = {(uint8_t)session, (uint8_t)(session >> 8), (uint8_t)(session >> 16),
                          (uint8_t)(session >> 24)};
    host_frame(c, id, seq, id == BR_LINK_MSG_HELLO ? p : NULL, id == BR_LINK_MSG_HELLO ? sizeof p : 0u);
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(l, &cmd), BR_OK);
    if (cmd.kind == BR_LINK_CMD_HELLO) assert_int_equal(cmd.session, session);
    return cmd.kind;
}

/* A hello of a new session is accepted whatever its seq and restarts the
 * window there; within the session a repeated or old frame is still dropped,
 * and so is the session's own hello repeated (a replay of it must not reopen
 * the window). */
static void test_hello_opens_a_session(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 256);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x4000, 0), BR_LINK_CMD_ARM);
    /* a host restarted from seq 0: its arm is old, its hello opens a session */
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x0000, 0), BR_LINK_CMD_NONE);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_HELLO, 0x0000, 7), BR_LINK_CMD_HELLO);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x0001, 0), BR_LINK_CMD_ARM);
    /* within the session: the same frame again, an older one, the hello again */
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x0001, 0), BR_LINK_CMD_NONE);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x0000, 0), BR_LINK_CMD_NONE);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_HELLO, 0x0000, 7), BR_LINK_CMD_NONE);
    assert_int_equal(l.dec.cnt.rx_replayed, 4);
    /* the session's hello inside the window is an ordinary frame; a new session reopens */
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_HELLO, 0x0002, 7), BR_LINK_CMD_HELLO);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_HELLO, 0x9000, 8), BR_LINK_CMD_HELLO);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x8FFF, 0), BR_LINK_CMD_NONE);
    assert_int_equal(hello_step(&l, &c, BR_LINK_MSG_ARM, 0x9001, 0), BR_LINK_CMD_ARM);
    assert_int_equal(l.dec.cnt.rx_replayed, 5);
}

static void test_resync_after_garbage(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 256);
    uint8_t junk[200];
    uint32_t x = 12345u;
    for (size_t i = 0; i < sizeof junk; ++i) {
        x = x * 1103515245u + 12345u;
        junk[i] = (uint8_t)(1u + (x >> 16) % 255u); /* no delimiter in the garbage */
    }
    host_put(&c, junk, sizeof junk);
    host_frame(&c, BR_LINK_MSG_DISARM, 9, NULL, 0);
    br_link_cmd_t cmds[2];
    assert_int_equal(drain(&l, cmds, 2, 4), 1);
    assert_int_equal(cmds[0].kind, BR_LINK_CMD_DISARM);
    assert_int_equal(l.dec.cnt.rx_oversized, 1); /* the garbage, dropped at the frame's leading 0x00 */
}

static void test_step_bounded(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    const size_t k = 5;
    link_up(&l, &c, k);
    host_frame(&c, BR_LINK_MSG_ARM, 1, NULL, 0);   /* 10 bytes on the wire */
    host_frame(&c, BR_LINK_MSG_DISARM, 2, NULL, 0);
    size_t steps = 0, got = 0;
    uint32_t before = 0;
    while (c.rx_pos < c.rx_len || l.rx_pos < l.rx_end) {
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        assert_true(c.last_read_n <= k);
        assert_true(l.dec.cnt.rx_bytes - before <= k);
        before = l.dec.cnt.rx_bytes;
        got += cmd.kind != BR_LINK_CMD_NONE;
        assert_true(++steps < 100);
    }
    assert_int_equal(got, 2);
    assert_true(steps >= c.rx_len / k);
    /* with a large budget, two frames in the channel still give one command per step */
    link_up(&l, &c, 256);
    host_frame(&c, BR_LINK_MSG_ARM, 1, NULL, 0);
    host_frame(&c, BR_LINK_MSG_DISARM, 2, NULL, 0);
    br_link_cmd_t a, b;
    assert_int_equal(br_link_step(&l, &a), BR_OK);
    assert_int_equal(br_link_step(&l, &b), BR_OK);
    assert_int_equal(a.kind, BR_LINK_CMD_ARM);
    assert_int_equal(b.kind, BR_LINK_CMD_DISARM); /* from the bytes kept from the first read */
}

/* br_link_next: the period's next request within what is left of its K bytes
 * and its one read; the budget and the read are the period's, not the call's */
static void test_next_shares_the_budget(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    const size_t k = 25; /* two 10-byte arms and half of a third */
    link_up(&l, &c, k);
    for (uint16_t q = 1; q <= 4; ++q) host_frame(&c, q % 2u ? BR_LINK_MSG_ARM : BR_LINK_MSG_DISARM, q, NULL, 0);
    br_link_cmd_t a, b, d;
    assert_int_equal(br_link_step(&l, &a), BR_OK);
    assert_int_equal(a.kind, BR_LINK_CMD_ARM);
    assert_int_equal(br_link_next(&l, &b), BR_OK);
    assert_int_equal(b.kind, BR_LINK_CMD_DISARM);
    assert_int_equal(br_link_next(&l, &d), BR_OK);
    assert_int_equal(d.kind, BR_LINK_CMD_NONE); /* the third frame's rest is beyond the period's k bytes */
    assert_int_equal(l.dec.cnt.rx_bytes, k);    /* one read of k bytes in the period */
    assert_int_equal(l.rx_done, k);
    assert_int_equal(br_link_next(&l, &d), BR_OK);
    assert_int_equal(d.kind, BR_LINK_CMD_NONE);
    assert_int_equal(l.dec.cnt.rx_bytes, k);
    /* the next period: the third frame, then the fourth, from a new read */
    assert_int_equal(br_link_step(&l, &a), BR_OK);
    assert_int_equal(a.kind, BR_LINK_CMD_ARM);
    assert_int_equal(a.seq, 3);
    assert_int_equal(br_link_next(&l, &b), BR_OK);
    assert_int_equal(b.kind, BR_LINK_CMD_DISARM);
    assert_int_equal(b.seq, 4);
    /* the period made its one read in the step: br_link_next does not read again */
    link_up(&l, &c, 64);
    c.read_max = 10; /* the channel hands one arm a read */
    host_frame(&c, BR_LINK_MSG_ARM, 1, NULL, 0);
    host_frame(&c, BR_LINK_MSG_DISARM, 2, NULL, 0);
    assert_int_equal(br_link_step(&l, &a), BR_OK);
    assert_int_equal(a.kind, BR_LINK_CMD_ARM);
    assert_int_equal(br_link_next(&l, &b), BR_OK);
    assert_int_equal(b.kind, BR_LINK_CMD_NONE);
    assert_int_equal(l.dec.cnt.rx_bytes, 10);
    assert_int_equal(br_link_step(&l, &b), BR_OK);
    assert_int_equal(b.kind, BR_LINK_CMD_DISARM);
    /* the guards */
    assert_int_equal(br_link_next(NULL, &b), BR_E_NULL);
    assert_int_equal(br_link_next(&l, NULL), BR_E_NULL);
    br_link_t cold;
    memset(&cold, 0, sizeof cold);
    assert_int_equal(br_link_next(&cold, &b), BR_E_STATE);
}

static void test_channel_claiming_more_refused(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    link_up(&l, &c, 8);
    host_frame(&c, BR_LINK_MSG_ARM, 1, NULL, 0);
    c.extra = 1;
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(&l, &cmd), BR_E_INPUT);
    assert_int_equal(cmd.kind, BR_LINK_CMD_NONE);
    assert_int_equal(l.dec.cnt.rx_bytes, 0);
}

static br_status_t only_positive(void *ctx, uint16_t param, float value)
{
    *(int *)ctx += 1;
    return (param == 7u && value > 0.0f) ? BR_OK : BR_E_PARAM;
}

/* the answer the target queued: one param_value frame */
static void expect_answer(br_link_t *l, chan_t *c, uint16_t param, int8_t st)
{
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(l, &cmd), BR_OK); /* flushes the queue */
    br_link_frame_t f;
    assert_int_equal(link_decode_all(c->tx, c->tx_len, &f, 1), 1);
    assert_int_equal(f.id, BR_LINK_MSG_PARAM_VALUE);
    assert_int_equal(f.payload[BR_LINK_MSG_PARAM_VALUE_OFF_PARAM], param);
    assert_int_equal((int8_t)f.payload[BR_LINK_MSG_PARAM_VALUE_OFF_STATUS], st);
    c->tx_len = 0;
}

static void test_param_write_checked(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    memset(&c, 0, sizeof c);
    int calls = 0;
    const br_byte_chan_t ch = {&c, ch_read, ch_write};
    const br_link_cfg_t cfg = {64, 64, only_positive, &calls};
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_OK);
    const float vals[3] = {NAN, -1.0f, 3.0f};
    for (uint16_t i = 0; i < 3; ++i) {
        uint8_t p[6] = {7, 0};
        memcpy(&p[2], &vals[i], 4);
        host_frame(&c, BR_LINK_MSG_PARAM_WRITE, (uint16_t)(i + 1u), p, 6);
    }
    /* one step: the NaN refused before the hook, -1 refused by the hook
     * (both answered, neither handed on), 3 accepted and handed on */
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(&l, &cmd), BR_OK);
    assert_int_equal(calls, 2);
    assert_int_equal(l.dec.cnt.rx_refused, 2);
    assert_int_equal(cmd.kind, BR_LINK_CMD_PARAM_WRITE);
    assert_true(cmd.value == 3.0f);
    assert_int_equal(br_link_step(&l, &cmd), BR_OK); /* flushes the answers */
    /* the two refusals' answers, in order */
    br_link_frame_t f[2];
    assert_int_equal(link_decode_all(c.tx, c.tx_len, f, 2), 2);
    for (size_t i = 0; i < 2; ++i) {
        assert_int_equal(f[i].id, BR_LINK_MSG_PARAM_VALUE);
        assert_int_equal((int8_t)f[i].payload[BR_LINK_MSG_PARAM_VALUE_OFF_STATUS], BR_E_PARAM);
    }
    c.tx_len = 0;
    assert_int_equal(br_link_send_param_value(&l, 7, 3.0f, BR_OK), BR_OK);
    expect_answer(&l, &c, 7, BR_OK);
}

static void test_send_partial_and_busy(void **s)
{
    (void)s;
    br_link_t l;
    chan_t c;
    memset(&c, 0, sizeof c);
    c.write_max = 3; /* the channel takes 3 bytes a call */
    const br_byte_chan_t ch = {&c, ch_read, ch_write};
    const br_link_cfg_t cfg = {8, 4, NULL, NULL};
    assert_int_equal(br_link_init(&l, &cfg, &ch), BR_OK);
    const br_link_status_t st = {1000u, 990u, 0u, 5u};
    size_t queued = 0;
    br_status_t r;
    while ((r = br_link_send_status(&l, &st)) == BR_OK) ++queued;
    assert_int_equal(r, BR_E_BUSY);
    assert_int_equal(l.dec.cnt.tx_busy, 1);
    uint8_t w[BR_LINK_FRAME_MAX];
    size_t wl = 0;
    const uint8_t zeros[BR_LINK_MSG_STATUS_LEN] = {0};
    assert_int_equal(br_link_encode(w, sizeof w, BR_LINK_MSG_STATUS, 0, zeros, sizeof zeros, &wl), BR_OK);
    assert_int_equal(queued, BR_LINK_TX_BUF_BYTES / wl);
    /* each step offers at most tx_budget_bytes; everything arrives, in order, seq 0, 1, ... */
    for (int i = 0; i < 200 && l.tx_len > 0; ++i) {
        const size_t before = c.tx_len;
        br_link_cmd_t cmd;
        assert_int_equal(br_link_step(&l, &cmd), BR_OK);
        assert_true(c.tx_len - before <= 3);
    }
    assert_int_equal(l.tx_len, 0);
    br_link_frame_t f[32];
    assert_true(queued <= 32);
    assert_int_equal(link_decode_all(c.tx, c.tx_len, f, 32), queued);
    for (size_t i = 0; i < queued; ++i) {
        assert_int_equal(f[i].seq, i);
        assert_int_equal(f[i].id, BR_LINK_MSG_STATUS);
    }
    assert_int_equal(br_link_send(&l, 1, NULL, BR_LINK_PAYLOAD_MAX + 1u), BR_E_NULL);
    uint8_t p[BR_LINK_PAYLOAD_MAX + 1] = {0};
    assert_int_equal(br_link_send(&l, 1, p, sizeof p), BR_E_PARAM);
}

static void test_null_guards(void **s)
{
    (void)s;
    br_link_frame_t f;
    br_link_dec_t d;
    br_link_dec_init(NULL);
    br_link_dec_init(&d);
    assert_int_equal(br_link_dec_push(NULL, 0, &f), 0);
    assert_int_equal(br_link_dec_push(&d, 0, NULL), 0);
    assert_int_equal(br_link_crc16(0x1234u, NULL, 5), 0x1234u);
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(NULL, &cmd), BR_E_NULL);
    assert_int_equal(br_link_cmd_decode(NULL, &cmd), BR_E_NULL);
    assert_int_equal(br_link_send_status(NULL, NULL), BR_E_NULL);
    assert_int_equal(br_link_init(NULL, NULL, NULL), BR_E_NULL);
}

static void test_msg_len_from_table(void **s)
{
    (void)s;
    assert_int_equal(br_link_msg_len(BR_LINK_MSG_STATUS, BR_LINK_TO_HOST), BR_LINK_MSG_STATUS_LEN);
    assert_int_equal(br_link_msg_len(BR_LINK_MSG_STATUS, BR_LINK_TO_TARGET), -1);
    assert_int_equal(br_link_msg_len(BR_LINK_MSG_PARAM_WRITE, BR_LINK_TO_TARGET), BR_LINK_MSG_PARAM_WRITE_LEN);
    assert_int_equal(br_link_msg_len(0xEE, BR_LINK_TO_TARGET), -1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_crc_check_value),
        cmocka_unit_test(test_cobs_has_no_zero),
        cmocka_unit_test(test_encode_guards),
        cmocka_unit_test(test_init_validates),
        cmocka_unit_test(test_commands_decoded),
        cmocka_unit_test(test_each_drop_counted),
        cmocka_unit_test(test_replay_dropped),
        cmocka_unit_test(test_hello_opens_a_session),
        cmocka_unit_test(test_resync_after_garbage),
        cmocka_unit_test(test_step_bounded),
        cmocka_unit_test(test_next_shares_the_budget),
        cmocka_unit_test(test_channel_claiming_more_refused),
        cmocka_unit_test(test_param_write_checked),
        cmocka_unit_test(test_send_partial_and_busy),
        cmocka_unit_test(test_null_guards),
        cmocka_unit_test(test_msg_len_from_table),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
