/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: the replay stream (target/replay), outside data that the
 * host tool and the M7 image read. The input is laid over a valid stream of
 * the reference machine's H-inf + PF configuration: its first bytes are
 * XORed into the header (so the fuzzer reaches past the magic and the
 * version into every configuration field), the rest are step records. Every
 * input must end in a clean status, never a crash, a sanitizer report or a
 * non-finite or out-of-range duty written to the PWM. docs/reliability.md. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"
#include "replay/br_replay.h"

typedef struct {
    const uint8_t *data;
    size_t size, pos;
} stream_t;

static int io_read(void *ctx, void *buf, uint32_t n)
{
    stream_t *s = ctx;
    if (s->size - s->pos < n) return -1;
    memcpy(buf, s->data + s->pos, n);
    s->pos += n;
    return 0;
}

static int io_write(void *ctx, const void *buf, uint32_t n)
{
    (void)ctx;
    (void)buf;
    (void)n;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static br_replay_t r; /* ~95 KB: static, zeroed per run below */
    static uint8_t buf[4u * BR_REPLAY_HDR_WORDS + 4096u];
    const size_t hdr_bytes = 4u * BR_REPLAY_HDR_WORDS;
    if (size > sizeof buf) return 0;
    /* a valid header of the reference configuration ... */
    const br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    br_replay_cfg_t cfg = {16u, br_circle_ctrl_cfg(&c), c.pf, 1u};
    uint32_t hdr[BR_REPLAY_HDR_WORDS];
    br_replay_hdr_encode(&cfg, hdr);
    memcpy(buf, hdr, hdr_bytes);
    /* ... with the input XORed into it, the rest as step records */
    const size_t nx = size < hdr_bytes ? size : hdr_bytes;
    for (size_t i = 0; i < nx; i++) buf[i] ^= data[i];
    const size_t total = size > hdr_bytes ? size : hdr_bytes;
    if (size > hdr_bytes) memcpy(buf + hdr_bytes, data + hdr_bytes, size - hdr_bytes);
    stream_t s = {buf, total, 0u};
    const br_replay_io_t io = {&s, io_read, io_write, NULL};
    memset(&r, 0, sizeof r);
    const int rc = br_replay_run(&r, &io, 0u, 0u);
    /* nothing runs the motor on a NaN or beyond full scale */
    if (!(fabsf(r.ax[0].duty) <= 1.0f) || !(fabsf(r.ax[1].duty) <= 1.0f)) abort();
    (void)rc;
    return 0;
}
