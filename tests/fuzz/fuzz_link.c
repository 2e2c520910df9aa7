/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: the link's decoder (bristle/br_link.h, docs/link.md).
 * Input: byte 0 the step budget K (1..256), byte 1 the most the fake channel
 * hands over per read (1..256), then a recipe of the byte stream, records of
 * a tag byte and its bytes: a tag below 0x80 copies the next (tag & 0x3F) + 1
 * bytes raw; a tag from 0x80 writes a whole frame (id, seq lo, seq hi, length
 * modulo BR_LINK_PAYLOAD_MAX + 1, the payload) with a right CRC, of version
 * BR_LINK_VERSION, or of version tag & 0x3F when tag & 0x40 (so that valid,
 * replayed and other-version frames are reached, which random bytes with a
 * right CRC are not). The stream goes once through the bare decoder and once
 * through br_link_step. Properties:
 *   - every accepted frame is in the input whole: its canonical encoding
 *     (br_link_encode of what was accepted) occurs in the stream, so its CRC,
 *     length and version were right and nothing was skipped;
 *   - accepted sequence numbers advance (1..BR_LINK_SEQ_WINDOW, modulo 2^16),
 *     except a hello that opens a session (its session number not the one in
 *     force): any seq;
 *   - every non-empty segment between delimiters is counted exactly once;
 *   - a step takes at most K bytes and returns at most one valid command;
 *     a period of a step and br_link_next calls (every other one) at most K;
 *   - after any input, a valid frame with the next sequence number is decoded
 *     (resynchronisation).
 * A violated property aborts (a finding). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bristle/br_link.h"

typedef struct {
    const uint8_t *d;
    size_t n, pos, per_read;
} src_t;

static size_t src_read(void *ctx, uint8_t *buf, size_t n)
{
    src_t *s = ctx;
    size_t k = s->n - s->pos;
    if (k > n) k = n;
    if (k > s->per_read) k = s->per_read;
    memcpy(buf, &s->d[s->pos], k);
    s->pos += k;
    return k;
}

static size_t sink_write(void *ctx, const uint8_t *buf, size_t n)
{
    (void)ctx;
    (void)buf;
    return n;
}

static int occurs(const uint8_t *hay, size_t n, const uint8_t *needle, size_t m)
{
    for (size_t i = 0; i + m <= n; ++i) {
        if (memcmp(&hay[i], needle, m) == 0) return 1;
    }
    return 0;
}

static uint32_t drops(const br_link_counters_t *c)
{
    return c->rx_frames + c->rx_short + c->rx_oversized + c->rx_bad_len + c->rx_bad_cobs + c->rx_bad_crc +
           c->rx_bad_version + c->rx_replayed;
}

/* a frame of the recipe: its body with a right CRC, stuffed, delimited */
static size_t recipe_frame(uint8_t tag, const uint8_t *in, size_t n, size_t *used, uint8_t *out, size_t cap)
{
    if (n < 4u || cap < BR_LINK_FRAME_MAX) return 0u;
    uint8_t body[BR_LINK_BODY_MAX];
    const size_t len = in[3] % (BR_LINK_PAYLOAD_MAX + 1u);
    body[0] = (uint8_t)len;
    body[1] = (tag & 0x40u) ? (uint8_t)(tag & 0x3Fu) : (uint8_t)BR_LINK_VERSION;
    body[2] = in[0];
    body[3] = in[1];
    body[4] = in[2];
    *used = 4u;
    for (size_t j = 0; j < len; ++j) {
        body[BR_LINK_HEADER_BYTES + j] = (*used < n) ? in[(*used)++] : 0u;
    }
    const size_t m = BR_LINK_HEADER_BYTES + len;
    const uint16_t crc = br_link_crc16(0xFFFFu, body, m);
    body[m] = (uint8_t)(crc >> 8);
    body[m + 1u] = (uint8_t)crc;
    out[0] = 0u;
    const size_t c = br_link_cobs_encode(body, m + 2u, &out[1], cap - 2u);
    out[c + 1u] = 0u;
    return c + 2u;
}

static size_t build_stream(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
    size_t i = 0u, o = 0u;
    while (i < n) {
        const uint8_t tag = in[i++];
        if (tag < 0x80u) {
            for (size_t j = 0; j < (size_t)(tag & 0x3Fu) + 1u && i < n && o < cap; ++j) out[o++] = in[i++];
        } else {
            size_t used = 0u;
            const size_t w = recipe_frame(tag, &in[i], n - i, &used, &out[o], cap - o);
            if (w == 0u) break;
            o += w;
            i += used;
        }
    }
    return o;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 2u) return 0;
    const size_t k = 1u + data[0];
    static uint8_t stream[8192]; /* the fuzzer's own buffer (a harness, not firmware) */
    const uint8_t *s = stream;
    const size_t n = build_stream(data + 2, size - 2u, stream, sizeof stream);

    /* the bare decoder */
    br_link_dec_t d;
    br_link_dec_init(&d);
    br_link_frame_t f;
    uint32_t segments = 0u;
    int in_segment = 0;
    for (size_t i = 0; i < n; ++i) {
        if (s[i] != 0u) {
            in_segment = 1;
        } else if (in_segment) {
            ++segments;
            in_segment = 0;
        }
        const uint16_t last = d.last_seq;
        const int had = d.have_seq;
        const int had_session = d.have_session;
        const uint32_t session = d.session;
        if (br_link_dec_push(&d, s[i], &f)) {
            uint8_t w[BR_LINK_FRAME_MAX];
            size_t wl = 0;
            if (f.len > BR_LINK_PAYLOAD_MAX) abort();
            if (br_link_encode(w, sizeof w, f.id, f.seq, f.payload, f.len, &wl) != BR_OK) abort();
            if (!occurs(s, n, &w[1], wl - 1u)) abort();
            const uint16_t ahead = (uint16_t)(f.seq - last);
            const uint32_t fs = (uint32_t)f.payload[0] | ((uint32_t)f.payload[1] << 8) |
                                ((uint32_t)f.payload[2] << 16) | ((uint32_t)f.payload[3] << 24);
            const int opens = f.id == BR_LINK_MSG_HELLO && f.len == BR_LINK_MSG_HELLO_LEN &&
                              (!had_session || fs != session);
            if (!opens && had && (ahead == 0u || ahead > BR_LINK_SEQ_WINDOW)) abort();
        }
    }
    if (drops(&d.cnt) != segments) abort();
    /* resynchronisation: a delimiter (it may complete a last frame), then a
     * valid frame with the next seq */
    int got = br_link_dec_push(&d, 0x00u, &f);
    const uint16_t next = (uint16_t)(d.last_seq + 1u);
    uint8_t w[BR_LINK_FRAME_MAX];
    size_t wl = 0;
    if (br_link_encode(w, sizeof w, BR_LINK_MSG_ARM, next, NULL, 0, &wl) != BR_OK) abort();
    for (size_t i = 0; i < wl; ++i) got = br_link_dec_push(&d, w[i], &f);
    if (!got || f.id != BR_LINK_MSG_ARM || f.seq != next) abort();

    /* the link's step over a channel handing the stream in pieces */
    src_t src = {s, n, 0u, 1u + data[1]};
    const br_byte_chan_t ch = {&src, src_read, sink_write};
    const br_link_cfg_t cfg = {k, 64u, NULL, NULL};
    br_link_t l;
    if (br_link_init(&l, &cfg, &ch) != BR_OK) abort();
    for (size_t steps = 0; steps < 4u * n + 8u; ++steps) {
        const uint32_t before = l.dec.cnt.rx_bytes;
        br_link_cmd_t cmd;
        if (br_link_step(&l, &cmd) != BR_OK) abort();
        /* every other period, the period's further requests (br_svc's second): the same K bytes */
        for (unsigned m = 0u; m < 2u && steps % 2u == 1u && cmd.kind != BR_LINK_CMD_NONE; ++m) {
            if (cmd.kind == BR_LINK_CMD_PARAM_WRITE && cmd.value != cmd.value) abort();
            if (br_link_next(&l, &cmd) != BR_OK) abort();
        }
        if (l.dec.cnt.rx_bytes - before > k) abort();
        if (cmd.kind == BR_LINK_CMD_PARAM_WRITE && cmd.value != cmd.value) abort(); /* NaN reached the caller */
        if (src.pos == n && l.rx_pos == l.rx_end) break;
    }
    if (l.dec.cnt.rx_bytes != n) abort();
    /* the same stream, the same verdicts */
    if (drops(&l.dec.cnt) != segments) abort();
    return 0;
}
