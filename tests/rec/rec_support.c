/* SPDX-License-Identifier: Apache-2.0 */
#include "rec_support.h"

#include <string.h>

br_status_t rec_link_init(br_link_t *l, golden_sink_t *sink, size_t room)
{
    sink->len = 0u;
    sink->room = room;
    const br_byte_chan_t ch = golden_chan(sink);
    const br_link_cfg_t cfg = {BR_LINK_RX_BUDGET_MAX, BR_LINK_TX_BUF_BYTES, NULL, NULL};
    return br_link_init(l, &cfg, &ch);
}

br_rec_sample_t rec_sample_of(uint32_t t)
{
    br_rec_sample_t s;
    memset(&s, 0, sizeof s);
    s.tick = t;
    s.counts = (int32_t)(t * 7u);
    s.ref_counts = (int32_t)(t * 7u);
    s.ref_frac = 0.5f;
    s.duty = 0.001f * (float)(t % 100u);
    s.F_hat_N = 1.0f + (float)(t % 10u);
    s.n_outliers = (uint16_t)(t % 5u);
    s.status = BR_OK;
    s.fault = (uint8_t)BR_APP_FAULT_NONE;
    s.flags = 0u;
    return s;
}
