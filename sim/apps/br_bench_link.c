/* SPDX-License-Identifier: Apache-2.0 */
/* make bench: the link's host cost (docs/link.md, "Cost"): decoding a stream
 * of host requests byte by byte (br_link_dec_push), encoding a status report
 * (br_link_encode through br_link_send_status), and one br_link_step with
 * K = 64 over an in-memory channel; and the memory of a br_link_t. Median of
 * REPS repetitions, printed on stdout. No options. */
#define _POSIX_C_SOURCE 200809L /* clock_gettime */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bristle/br_link.h"

#define REPS 31
#define FRAMES 4096

static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v)
{
    qsort(v, REPS, sizeof v[0], cmp);
    return v[REPS / 2];
}

typedef struct {
    const uint8_t *d;
    size_t n, pos;
    size_t written;
} mem_t;

static size_t mem_read(void *ctx, uint8_t *buf, size_t n)
{
    mem_t *m = ctx;
    size_t k = m->n - m->pos;
    if (k > n) k = n;
    memcpy(buf, &m->d[m->pos], k);
    m->pos += k;
    return k;
}

static size_t mem_write(void *ctx, const uint8_t *buf, size_t n)
{
    (void)buf;
    ((mem_t *)ctx)->written += n;
    return n;
}

int main(int argc, char **argv)
{
    if (argc > 1) {
        fprintf(stderr, "%s: takes no options ('%s')\n", argv[0], argv[1]);
        return 2;
    }
    /* the stream: param_write and arm requests, alternating */
    static uint8_t stream[FRAMES * BR_LINK_FRAME_MAX];
    size_t n = 0;
    for (uint16_t i = 0; i < FRAMES; ++i) {
        const uint8_t p[BR_LINK_MSG_PARAM_WRITE_LEN] = {(uint8_t)i, 0, 0x00, 0x00, 0xC0, 0x3F};
        size_t wl = 0;
        const int w = i % 2u;
        if (br_link_encode(&stream[n], sizeof stream - n, w ? BR_LINK_MSG_ARM : BR_LINK_MSG_PARAM_WRITE, i, p,
                           w ? 0u : sizeof p, &wl) != BR_OK) {
            return 1;
        }
        n += wl;
    }
    double dec[REPS], enc[REPS], step[REPS];
    uint32_t frames = 0;
    for (int r = 0; r < REPS; ++r) {
        br_link_dec_t d;
        br_link_dec_init(&d);
        br_link_frame_t f;
        double t0 = now_ns();
        for (size_t i = 0; i < n; ++i) frames += (uint32_t)br_link_dec_push(&d, stream[i], &f);
        dec[r] = (now_ns() - t0) / (double)n;

        mem_t m = {stream, n, 0, 0};
        const br_byte_chan_t ch = {&m, mem_read, mem_write};
        const br_link_cfg_t cfg = {64u, BR_LINK_TX_BUF_BYTES, NULL, NULL};
        br_link_t l;
        if (br_link_init(&l, &cfg, &ch) != BR_OK) return 1;
        const br_link_status_t st = {1u, 0u, 1u, 0u};
        t0 = now_ns();
        for (int i = 0; i < FRAMES; ++i) {
            if (br_link_send_status(&l, &st) != BR_OK) return 1;
            l.tx_len = 0; /* the channel's part is not timed here */
        }
        enc[r] = (now_ns() - t0) / FRAMES;

        size_t steps = 0;
        br_link_cmd_t cmd;
        t0 = now_ns();
        while (m.pos < m.n || l.rx_pos < l.rx_end) {
            if (br_link_step(&l, &cmd) != BR_OK) return 1;
            ++steps;
        }
        step[r] = (now_ns() - t0) / (double)steps;
    }
    if (frames != (uint32_t)FRAMES * REPS) {
        fprintf(stderr, "br_bench_link: decoded %u frames, want %u\n", frames, (unsigned)FRAMES * REPS);
        return 1;
    }
    printf("link: decode %.2f ns/byte (%zu bytes, %d frames), encode a status report %.1f ns, "
           "br_link_step (K = 64) %.1f ns; sizeof(br_link_t) %zu bytes; median of %d\n",
           median(dec), n, FRAMES, median(enc), median(step), sizeof(br_link_t), REPS);
    return 0;
}
