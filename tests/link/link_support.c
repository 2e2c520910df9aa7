/* SPDX-License-Identifier: Apache-2.0 */
#include "link_support.h"

#include <string.h>

static size_t sink_read(void *ctx, uint8_t *buf, size_t n)
{
    (void)ctx;
    (void)buf;
    (void)n;
    return 0u;
}

static size_t sink_write(void *ctx, const uint8_t *buf, size_t n)
{
    golden_sink_t *s = ctx;
    size_t k = n < sizeof s->buf - s->len ? n : sizeof s->buf - s->len;
    k = k < s->room ? k : s->room;
    memcpy(&s->buf[s->len], buf, k);
    s->len += k;
    return k;
}

br_byte_chan_t golden_chan(golden_sink_t *sink)
{
    const br_byte_chan_t ch = {sink, sink_read, sink_write};
    return ch;
}

br_status_t golden_link_init(br_link_t *l, golden_sink_t *sink)
{
    sink->len = 0u;
    sink->room = sizeof sink->buf;
    const br_byte_chan_t ch = golden_chan(sink);
    const br_link_cfg_t cfg = {16u, BR_LINK_FRAME_MAX, NULL, NULL};
    return br_link_init(l, &cfg, &ch);
}

br_status_t golden_send(br_link_t *l, const br_link_golden_t *g)
{
    br_status_t st;
    float v;
    l->tx_seq = g->seq;
    switch (g->to_target ? 0u : g->id) {
    case BR_LINK_MSG_STATUS: {
        const br_link_status_t s = {g->f[0], g->f[1], (uint8_t)g->f[2], (uint8_t)g->f[3]};
        st = br_link_send_status(l, &s);
        break;
    }
    case BR_LINK_MSG_FAULT:
        st = br_link_send_fault(l, (uint8_t)g->f[0], g->f[1]);
        break;
    case BR_LINK_MSG_PARAM_VALUE:
        memcpy(&v, &g->f[1], sizeof v);
        st = br_link_send_param_value(l, (uint16_t)g->f[0], v, (br_status_t)(int32_t)g->f[2]);
        break;
    case BR_LINK_MSG_REF_STATUS: {
        const br_link_ref_status_t r = {g->f[0], (uint8_t)g->f[1], (uint8_t)g->f[2], (uint8_t)g->f[3],
                                        g->f[4], g->f[5], g->f[6]};
        st = br_link_send_ref_status(l, &r);
        break;
    }
    case BR_LINK_MSG_HELLO_REPLY: {
        /* f[1] the version: the link writes its own, BR_LINK_VERSION */
        char name[17];
        for (size_t i = 0u; i < 16u; ++i) name[i] = (char)(g->f[3u + i / 4u] >> (8u * (i % 4u)));
        name[16] = '\0';
        st = g->f[1] == BR_LINK_VERSION ? br_link_send_hello_reply(l, g->f[0], g->f[2], name) : BR_E_INPUT;
        break;
    }
    default:
        return BR_E_INPUT;
    }
    if (st != BR_OK) {
        return st;
    }
    br_link_cmd_t cmd;
    return br_link_step(l, &cmd);
}

size_t link_decode_all(const uint8_t *b, size_t n, br_link_frame_t *frames, size_t max)
{
    br_link_dec_t d;
    br_link_dec_init(&d);
    br_link_frame_t f;
    size_t got = 0u;
    for (size_t i = 0u; i < n; ++i) {
        if (br_link_dec_push(&d, b[i], &f)) {
            if (got < max) frames[got] = f;
            ++got;
        }
    }
    return got;
}
