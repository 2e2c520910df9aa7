/* SPDX-License-Identifier: Apache-2.0 */
/* Writes, to the file named by its one argument, the target's reports of
 * br_link_golden.h as the firmware encodes them (br_link_send_* through a
 * br_link_t), one after the other: what test_link_golden.py decodes with
 * bristle.link (golden frames, C to Python; docs/link.md). */
#include <stdio.h>

#include "link_support.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: br_link_emit OUT\n");
        return 2;
    }
    FILE *out = fopen(argv[1], "wb");
    if (out == NULL) {
        perror(argv[1]);
        return 1;
    }
    for (size_t i = 0; i < BR_LINK_GOLDEN_N; ++i) {
        if (br_link_golden[i].to_target) continue;
        br_link_t l;
        golden_sink_t sink;
        if (golden_link_init(&l, &sink) != BR_OK || golden_send(&l, &br_link_golden[i]) != BR_OK ||
            fwrite(sink.buf, 1, sink.len, out) != sink.len) {
            fprintf(stderr, "br_link_emit: case %zu failed\n", i);
            fclose(out);
            return 1;
        }
    }
    return fclose(out) == 0 ? 0 : 1;
}
