/* SPDX-License-Identifier: Apache-2.0 */
/* Host build of the replay (target/replay/br_replay.h) with a stdio shim: the
 * same core the mps2-an500 image runs under QEMU.  br_replay_host IN OUT [M [SCALAR_PATH]] */
#include <stdio.h>
#include <stdlib.h>

#include "replay/br_replay.h"

static int io_read(void *ctx, void *buf, uint32_t n)
{
    return (fread(buf, 1, n, ((FILE **)ctx)[0]) == n) ? 0 : -1;
}

static int io_write(void *ctx, const void *buf, uint32_t n)
{
    return (fwrite(buf, 1, n, ((FILE **)ctx)[1]) == n) ? 0 : -1;
}

int main(int argc, char **argv)
{
    if (argc < 3 || argc > 5) {
        fprintf(stderr, "usage: br_replay_host IN OUT [M [SCALAR_PATH]]\n");
        return 2;
    }
    FILE *f[2] = {fopen(argv[1], "rb"), fopen(argv[2], "wb")};
    if (f[0] == NULL || f[1] == NULL) {
        perror("br_replay_host");
        return 1;
    }
    br_replay_t *r = calloc(1, sizeof *r);
    if (r == NULL) return 1;
    const br_replay_io_t io = {f, io_read, io_write, NULL};
    const int rc = br_replay_run(r, &io, (argc >= 4) ? (uint32_t)strtoul(argv[3], NULL, 10) : 0u,
                                 (argc == 5) ? (uint32_t)strtoul(argv[4], NULL, 10) : 0u);
    fclose(f[0]);
    if (fclose(f[1]) != 0 || rc != 0) {
        fprintf(stderr, "br_replay_host: replay failed (%d)\n", rc);
        free(r);
        return 1;
    }
    printf("br_replay_host: %u steps, m = %u, %u axes\n", r->cfg.n_steps, r->cfg.pf.n_particles, r->cfg.n_axes);
    free(r);
    return 0;
}
