/* SPDX-License-Identifier: Apache-2.0 */
/* Golden frames of the recorder, Python to C (docs/link.md): the requests
 * bristle.link wrote (br_rec_golden.h, tests/rec/gen_rec_golden.py) decode
 * in C to the commands they were written from, and the scripted run's
 * telemetry and dump are, byte for byte, the frames bristle.link encodes
 * from the same samples. */
#include "br_test.h"

#include <string.h>

#include "br_rec_golden.h"
#include "rec_golden_run.h"

static void test_requests_decode(void **s)
{
    (void)s;
    const br_link_cmd_kind_t kinds[3] = {BR_LINK_CMD_REC_ARM, BR_LINK_CMD_REC_TRIGGER, BR_LINK_CMD_REC_DUMP};
    assert_int_equal(BR_REC_GOLDEN_N_REQS, 3);
    for (size_t i = 0; i < BR_REC_GOLDEN_N_REQS; ++i) {
        const br_rec_golden_req_t *g = &br_rec_golden_reqs[i];
        br_link_dec_t d;
        br_link_dec_init(&d);
        br_link_frame_t f;
        int got = 0;
        for (size_t k = 0; k < g->wire_len; ++k) got += br_link_dec_push(&d, g->wire[k], &f);
        assert_int_equal(got, 1);
        assert_int_equal(f.id, g->id);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_cmd_decode(&f, &cmd), BR_OK);
        assert_int_equal(cmd.kind, kinds[i]);
        assert_int_equal(cmd.seq, g->seq);
        assert_int_equal(cmd.first, g->first);
    }
}

static void test_run_encodes_equal(void **s)
{
    (void)s;
    static golden_sink_t sink;
    assert_int_equal(rec_golden_run(&sink), BR_OK);
    assert_int_equal(sink.len, sizeof br_rec_golden_stream);
    assert_memory_equal(sink.buf, br_rec_golden_stream, sizeof br_rec_golden_stream);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_requests_decode),
        cmocka_unit_test(test_run_encodes_equal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
