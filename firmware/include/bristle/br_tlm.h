/* SPDX-License-Identifier: Apache-2.0 */
/* Telemetry: the period's sample (bristle/br_rec.h) sent to the host as a
 * tlm_sample frame every N control periods, N = 1 being the control rate
 * (docs/link.md, "Telemetry"). One br_link_send per sent sample, never a
 * wait: a sample the link's transmit queue has no room for is dropped and
 * counted, never queued (the host sees the gap in the ticks). */
#ifndef BR_TLM_H
#define BR_TLM_H

#include <stdint.h>

#include "bristle/br_link.h"
#include "bristle/br_rec.h"

typedef struct {
    uint32_t every_n_periods; /* one sample sent every so many periods, >= 1 (1: every period) */
} br_tlm_cfg_t;

typedef struct {
    br_tlm_cfg_t cfg;
    uint32_t k;         /* periods since the last sample due */
    uint32_t n_sent;    /* samples queued on the link (wraps) */
    uint32_t n_dropped; /* samples due that the link refused (wraps) */
    int ready;
} br_tlm_t;

/* BR_E_NULL, BR_E_PARAM (every_n_periods 0). The first sample sent is the
 * first period's; then every every_n_periods-th. */
br_status_t br_tlm_init(br_tlm_t *t, const br_tlm_cfg_t *cfg);

/* One period: when a sample is due, s packed and queued on link (one
 * br_link_send). BR_OK (sent, or not due), BR_E_BUSY (due, the link's queue
 * full: dropped, n_dropped counted), the link's other error (dropped and
 * counted too), BR_E_NULL, BR_E_STATE. */
br_status_t br_tlm_step(br_tlm_t *t, br_link_t *link, const br_rec_sample_t *s);

#endif
