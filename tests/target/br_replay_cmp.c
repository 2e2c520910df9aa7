/* SPDX-License-Identifier: Apache-2.0 */
/* Compares replay outputs (target/replay/br_replay.h), and summarises their cost.
 *
 *   br_replay_cmp HOST.bin TARGET.bin [--expect EXPECT.bin]
 *     every record: same k and status, identical resampling-index hash,
 *     F_hat and duty within BR_CMP_TOL_ULP float32 ulps (docs/target.md);
 *     with --expect, HOST's F_hat and duty must equal the closed loop's bits.
 *   br_replay_cmp --cost OUT.bin
 *     steps, then mean / median / min / max / p99 of the cost field over
 *     k >= 1 (k = 0 is the PF's priming step), one line, raw units. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "replay/br_replay.h"

#define BR_CMP_TOL_ULP 4u

typedef uint32_t rec_t[BR_REPLAY_OUT_WORDS];

static rec_t *load(const char *path, size_t *n, size_t words)
{
    FILE *f = fopen(path, "rb");
    if (f == NULL) {
        perror(path);
        exit(1);
    }
    fseek(f, 0, SEEK_END);
    const long sz = ftell(f);
    rewind(f);
    if (sz <= 0 || (size_t)sz % (words * 4u) != 0u) {
        fprintf(stderr, "br_replay_cmp: %s: size %ld is not a whole number of records\n", path, sz);
        exit(1);
    }
    void *b = malloc((size_t)sz);
    if (b == NULL || fread(b, 1, (size_t)sz, f) != (size_t)sz) exit(1);
    fclose(f);
    *n = (size_t)sz / (words * 4u);
    return b;
}

/* distance in float32 ulps (ordered integer representation) */
static uint32_t ulps(uint32_t a, uint32_t b)
{
    const int64_t ia = (a & 0x80000000u) ? -(int64_t)(a & 0x7FFFFFFFu) : (int64_t)a;
    const int64_t ib = (b & 0x80000000u) ? -(int64_t)(b & 0x7FFFFFFFu) : (int64_t)b;
    const int64_t d = ia > ib ? ia - ib : ib - ia;
    return d > 0xFFFFFFFF ? 0xFFFFFFFFu : (uint32_t)d;
}

static int cmp_u32(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static int cost(const char *path)
{
    size_t n;
    rec_t *r = load(path, &n, BR_REPLAY_OUT_WORDS);
    if (n < 2) return 1;
    /* one cost per period k >= 1 (k = 0 is the PF's priming step): the
     * largest of its records' (the last axis's record holds the whole period) */
    uint32_t *c = calloc(n, sizeof *c);
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (r[i][0] == 0u) continue;
        if (i > 0 && r[i][0] == r[i - 1][0] && m > 0) {
            c[m - 1] = (r[i][5] > c[m - 1]) ? r[i][5] : c[m - 1];
        } else {
            c[m++] = r[i][5];
        }
    }
    if (m == 0) return 1;
    double sum = 0.0;
    for (size_t k = 0; k < m; k++) sum += (double)c[k];
    qsort(c, m, sizeof *c, cmp_u32);
    printf("%zu %.1f %u %u %u %u\n", m + 1, sum / (double)m, c[m / 2], c[0], c[m - 1], c[(m * 99) / 100]);
    free(c);
    free(r);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc == 3 && !strcmp(argv[1], "--cost")) return cost(argv[2]);
    if (!(argc == 3 || (argc == 5 && !strcmp(argv[3], "--expect")))) {
        fprintf(stderr, "usage: br_replay_cmp HOST TARGET [--expect EXPECT] | --cost OUT\n");
        return 2;
    }
    size_t nh, nt;
    rec_t *h = load(argv[1], &nh, BR_REPLAY_OUT_WORDS);
    rec_t *t = load(argv[2], &nt, BR_REPLAY_OUT_WORDS);
    int bad = 0;
    if (nh != nt) {
        fprintf(stderr, "br_replay_cmp: %zu host records, %zu target records\n", nh, nt);
        return 1;
    }
    uint32_t max_f = 0u, max_d = 0u;
    size_t same_bits = 0;
    for (size_t k = 0; k < nh; k++) {
        const uint32_t uf = ulps(h[k][3], t[k][3]), ud = ulps(h[k][4], t[k][4]);
        if (uf > max_f) max_f = uf;
        if (ud > max_d) max_d = ud;
        same_bits += (h[k][3] == t[k][3] && h[k][4] == t[k][4]);
        if (h[k][0] != t[k][0] || h[k][1] != t[k][1] || h[k][2] != t[k][2] || uf > BR_CMP_TOL_ULP ||
            ud > BR_CMP_TOL_ULP) {
            if (bad < 10) {
                fprintf(stderr, "step %zu: k %u/%u status %d/%d hash %08x/%08x F_hat %u ulp duty %u ulp\n", k,
                        h[k][0], t[k][0], (int)h[k][1], (int)t[k][1], h[k][2], t[k][2], uf, ud);
            }
            bad++;
        }
    }
    if (argc == 5) {
        size_t ne;
        uint32_t(*e)[2] = (uint32_t(*)[2])load(argv[4], &ne, 2u);
        if (ne != nh) {
            fprintf(stderr, "br_replay_cmp: %zu expected records, %zu host records\n", ne, nh);
            return 1;
        }
        size_t diff = 0;
        for (size_t k = 0; k < nh; k++) diff += (e[k][0] != h[k][3] || e[k][1] != h[k][4]);
        if (diff) {
            fprintf(stderr, "br_replay_cmp: the host replay differs from the closed loop at %zu steps\n", diff);
            bad++;
        }
        free(e);
    }
    printf("br_replay_cmp: %zu steps, index hashes %s, F_hat max %u ulp, duty max %u ulp, "
           "%zu/%zu steps bit-identical (tolerance %u ulp)\n",
           nh, bad ? "CHECK ABOVE" : "identical", max_f, max_d, same_bits, nh, BR_CMP_TOL_ULP);
    free(h);
    free(t);
    return bad ? 1 : 0;
}
