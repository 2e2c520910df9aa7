/* SPDX-License-Identifier: Apache-2.0 */
/* What the recorder's C tests and br_rec_emit share: a link over the link
 * tests' memory channel (tests/link/link_support.h) taking at most `room`
 * bytes per write, and a plain sample of tick t. */
#ifndef BR_REC_SUPPORT_H
#define BR_REC_SUPPORT_H

#include "bristle/br_link.h"
#include "bristle/br_rec.h"
#include "link_support.h"

/* a link over sink (nothing to read), both budgets at their maximum, the
 * channel taking at most room bytes a write (0: none) */
br_status_t rec_link_init(br_link_t *l, golden_sink_t *sink, size_t room);

/* A sample of tick t, fault NONE, every field a function of t. */
br_rec_sample_t rec_sample_of(uint32_t t);

#endif
