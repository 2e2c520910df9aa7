/* SPDX-License-Identifier: Apache-2.0 */
/* Golden frames, Python to C (docs/link.md): the frames bristle.link wrote
 * (br_link_golden.h, tests/link/gen_golden.py) decode in C to the values
 * they were written from, and the target's reports the firmware encodes from
 * those values are the same bytes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "link_support.h"

static uint32_t f32_bits(float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

/* each request, alone, through the stream decoder and the command decoding */
static void test_requests_decode(void **s)
{
    (void)s;
    size_t n = 0;
    for (size_t i = 0; i < BR_LINK_GOLDEN_N; ++i) {
        const br_link_golden_t *g = &br_link_golden[i];
        if (!g->to_target) continue;
        br_link_frame_t f;
        assert_int_equal(link_decode_all(g->wire, g->wire_len, &f, 1), 1);
        assert_int_equal(f.id, g->id);
        assert_int_equal(f.seq, g->seq);
        br_link_cmd_t cmd;
        assert_int_equal(br_link_cmd_decode(&f, &cmd), BR_OK);
        assert_int_equal(cmd.seq, g->seq);
        if (g->id == BR_LINK_MSG_HELLO) {
            assert_int_equal(cmd.kind, BR_LINK_CMD_HELLO);
            assert_int_equal(cmd.session, g->f[0]);
        }
        if (g->id == BR_LINK_MSG_ARM) assert_int_equal(cmd.kind, BR_LINK_CMD_ARM);
        if (g->id == BR_LINK_MSG_DISARM) assert_int_equal(cmd.kind, BR_LINK_CMD_DISARM);
        if (g->id == BR_LINK_MSG_FAULT_RESET) assert_int_equal(cmd.kind, BR_LINK_CMD_FAULT_RESET);
        if (g->id == BR_LINK_MSG_PARAM_READ) {
            assert_int_equal(cmd.kind, BR_LINK_CMD_PARAM_READ);
            assert_int_equal(cmd.param, g->f[0]);
        }
        if (g->id == BR_LINK_MSG_PARAM_WRITE) {
            assert_int_equal(cmd.kind, BR_LINK_CMD_PARAM_WRITE);
            assert_int_equal(cmd.param, g->f[0]);
            assert_int_equal(f32_bits(cmd.value), g->f[1]);
        }
        if (g->id == BR_LINK_MSG_SETPOINT) {
            assert_int_equal(cmd.kind, BR_LINK_CMD_SETPOINT);
            assert_int_equal(cmd.ref.kind, BR_REFQ_SETPOINT);
            assert_int_equal(cmd.ref.tick, g->f[0]);
            assert_int_equal(cmd.ref.periods, 1u);
            assert_int_equal((uint32_t)cmd.ref.counts, g->f[1]);
            assert_int_equal(f32_bits(cmd.ref.frac), g->f[2]);
            assert_int_equal(f32_bits(cmd.ref.v), g->f[3]);
            assert_int_equal(cmd.ref.flags, g->f[4]);
        }
        if (g->id == BR_LINK_MSG_SEGMENT) {
            assert_int_equal(cmd.kind, BR_LINK_CMD_SEGMENT);
            assert_int_equal(cmd.ref.kind, BR_REFQ_SEGMENT);
            assert_int_equal(cmd.ref.tick, g->f[0]);
            assert_int_equal(cmd.ref.periods, g->f[1]);
            assert_int_equal((uint32_t)cmd.ref.counts, g->f[2]);
            assert_int_equal(f32_bits(cmd.ref.frac), g->f[3]);
            assert_int_equal(f32_bits(cmd.ref.v), g->f[4]);
            assert_int_equal(f32_bits(cmd.ref.a), g->f[5]);
            assert_int_equal(f32_bits(cmd.ref.j), g->f[6]);
            assert_int_equal(cmd.ref.flags, g->f[7]);
        }
        ++n;
    }
    assert_int_equal(n, 9);
}

/* the reports: the firmware's bytes are the Python's */
static void test_reports_encode_equal(void **s)
{
    (void)s;
    size_t n = 0;
    for (size_t i = 0; i < BR_LINK_GOLDEN_N; ++i) {
        const br_link_golden_t *g = &br_link_golden[i];
        if (g->to_target) continue;
        br_link_t l;
        golden_sink_t sink;
        assert_int_equal(golden_link_init(&l, &sink), BR_OK);
        assert_int_equal(golden_send(&l, g), BR_OK);
        assert_int_equal(sink.len, g->wire_len);
        assert_memory_equal(sink.buf, g->wire, g->wire_len);
        ++n;
    }
    assert_int_equal(n, 8);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_requests_decode),
        cmocka_unit_test(test_reports_encode_equal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
