/* SPDX-License-Identifier: Apache-2.0 */
/* What test_link_golden and br_link_emit share: a link whose channel writes
 * into memory, and a golden report sent through the firmware's senders. */
#ifndef BR_LINK_GOLDEN_SEND_H
#define BR_LINK_GOLDEN_SEND_H

#include "bristle/br_link.h"
#include "br_link_golden.h"

typedef struct {
    uint8_t buf[4096];
    size_t len;
} golden_sink_t;

/* a link over a sink (nothing to read), budgets large enough for one frame a step */
br_status_t golden_link_init(br_link_t *l, golden_sink_t *sink);

/* Sends report g (g->to_target == 0) with g's sequence number through
 * br_link_send_status / _fault / _param_value, then steps the link until the
 * frame is in the sink. BR_E_INPUT for a case that is not a report. */
br_status_t golden_send(br_link_t *l, const br_link_golden_t *g);

#endif
