/* SPDX-License-Identifier: Apache-2.0 */
/* What the recorder's C tests and br_rec_emit share: a byte channel into
 * memory that takes at most `room` bytes per write (0: none), a link over it,
 * and a plain sample of tick t. */
#ifndef BR_REC_SUPPORT_H
#define BR_REC_SUPPORT_H

#include "bristle/br_link.h"
#include "bristle/br_rec.h"

typedef struct {
    uint8_t buf[65536];
    size_t len;
    size_t room;     /* bytes one write may take */
    size_t writes;   /* write calls */
} rec_sink_t;

/* a link over sink (nothing to read), both budgets at their maximum */
br_status_t rec_link_init(br_link_t *l, rec_sink_t *sink, size_t room);

/* A sample of tick t, fault NONE, every field a function of t. */
br_rec_sample_t rec_sample_of(uint32_t t);

#endif
