/* SPDX-License-Identifier: Apache-2.0 */
#include "rec_golden_run.h"

#include "bristle/br_tlm.h"
#include "br_rec_golden.h"

br_status_t rec_golden_run(golden_sink_t *sink)
{
    br_link_t l;
    br_status_t st = rec_link_init(&l, sink, 4096u);
    l.tx_seq = (uint16_t)BR_REC_GOLDEN_SEQ0;
    br_tlm_t t;
    const br_tlm_cfg_t tc = {1u};
    static br_rec_slot_t slots[BR_REC_GOLDEN_N_SAMPLES];
    const uint32_t n = (uint32_t)BR_REC_GOLDEN_N_SAMPLES;
    const br_rec_cfg_t rc = {slots, n, n - 1u, 0.0f, BR_REC_DUMP_FRAMES_MAX};
    br_rec_t r;
    if (st != BR_OK || (st = br_tlm_init(&t, &tc)) != BR_OK || (st = br_rec_init(&r, &rc)) != BR_OK) {
        return st;
    }
    br_link_cmd_t cmd;
    for (uint32_t i = 0u; i < n && st == BR_OK; ++i) {
        if (i + 1u == n) {
            st = br_rec_trigger(&r);
        }
        if (st == BR_OK && (st = br_tlm_step(&t, &l, &br_rec_golden_samples[i])) == BR_OK &&
            (st = br_rec_push(&r, &br_rec_golden_samples[i])) == BR_OK) {
            st = br_link_step(&l, &cmd);
        }
    }
    if (st == BR_OK) {
        st = br_rec_dump_request(&r, 0u);
    }
    for (unsigned p = 0u; p < 100u && st == BR_OK && (r.dump_active || l.tx_len > 0u); ++p) {
        if ((st = br_rec_dump_step(&r, &l)) == BR_OK) {
            st = br_link_step(&l, &cmd);
        }
    }
    return (st == BR_OK && (r.dump_active || l.tx_len > 0u)) ? BR_E_STATE : st;
}
