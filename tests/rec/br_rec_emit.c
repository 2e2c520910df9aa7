/* SPDX-License-Identifier: Apache-2.0 */
/* Writes, to the file named by its one argument, the bytes of the scripted
 * run of br_rec_golden.h as the firmware sends them (telemetry, the dump):
 * what test_rec_golden.py decodes with bristle.link (golden frames, C to
 * Python; docs/link.md). */
#include <stdio.h>

#include "rec_golden_run.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: br_rec_emit OUT\n");
        return 2;
    }
    static golden_sink_t sink;
    if (rec_golden_run(&sink) != BR_OK) {
        fprintf(stderr, "br_rec_emit: the scripted run failed\n");
        return 1;
    }
    FILE *out = fopen(argv[1], "wb");
    if (out == NULL) {
        perror(argv[1]);
        return 1;
    }
    const int ok = fwrite(sink.buf, 1, sink.len, out) == sink.len;
    return (fclose(out) == 0 && ok) ? 0 : 1;
}
