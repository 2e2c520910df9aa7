/* SPDX-License-Identifier: Apache-2.0 */
/* What the link's C tests and br_link_emit share: a link whose channel
 * writes into memory, a golden report sent through the firmware's senders,
 * and a buffer decoded whole. */
#ifndef BR_LINK_SUPPORT_H
#define BR_LINK_SUPPORT_H

#include "bristle/br_link.h"
#include "br_link_golden.h"

typedef struct {
    uint8_t buf[4096];
    size_t len;
    size_t room; /* bytes one write takes at most (golden_link_init: all of buf) */
} golden_sink_t;

/* a channel writing into sink (nothing to read) */
br_byte_chan_t golden_chan(golden_sink_t *sink);

/* a link over a sink (nothing to read), budgets large enough for one frame a step */
br_status_t golden_link_init(br_link_t *l, golden_sink_t *sink);

/* Sends report g (g->to_target == 0) with g's sequence number through
 * br_link_send_status / _fault / _param_value, then steps the link until the
 * frame is in the sink. BR_E_INPUT for a case that is not a report. */
br_status_t golden_send(br_link_t *l, const br_link_golden_t *g);

/* Decodes n bytes with a fresh decoder; returns the number of frames
 * accepted, the first max of them in frames. */
size_t link_decode_all(const uint8_t *b, size_t n, br_link_frame_t *frames, size_t max);

#endif
