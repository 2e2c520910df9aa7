/* SPDX-License-Identifier: Apache-2.0 */
/* Decodes the file named by its one argument with the firmware's stream
 * decoder (br_link_dec_push) and prints, one per line, each accepted frame
 * ("frame ID SEQ PAYLOAD-HEX") and then the counters ("NAME VALUE"): what
 * test_link_differential.py compares with bristle.link's Decoder (docs/link.md). */
#include <stdio.h>

#include "bristle/br_link.h"

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: br_link_decode IN\n");
        return 2;
    }
    FILE *in = fopen(argv[1], "rb");
    if (in == NULL) {
        perror(argv[1]);
        return 1;
    }
    br_link_dec_t d;
    br_link_dec_init(&d);
    br_link_frame_t f;
    int c;
    while ((c = fgetc(in)) != EOF) {
        if (br_link_dec_push(&d, (uint8_t)c, &f)) {
            printf("frame %u %u ", (unsigned)f.id, (unsigned)f.seq);
            for (unsigned i = 0; i < f.len; ++i) printf("%02x", (unsigned)f.payload[i]);
            printf("\n");
        }
    }
    fclose(in);
    const br_link_counters_t *k = &d.cnt;
    printf("frames %u\nshort %u\noversized %u\nbad_len %u\nbad_cobs %u\nbad_crc %u\nbad_version %u\nreplayed %u\n",
           (unsigned)k->rx_frames, (unsigned)k->rx_short, (unsigned)k->rx_oversized, (unsigned)k->rx_bad_len,
           (unsigned)k->rx_bad_cobs, (unsigned)k->rx_bad_crc, (unsigned)k->rx_bad_version, (unsigned)k->rx_replayed);
    return 0;
}
