/* SPDX-License-Identifier: Apache-2.0 */
/* Encoder counts: wrap-safe differences and the counts-to-radians conversion.
 * Position stays in integer counts; only differences become float. */
#ifndef BR_ENCODER_H
#define BR_ENCODER_H

#include <stdint.h>

/* now - prev modulo 2^32, read as a signed value: correct across a wrap of a
 * free-running int32 counter as long as |now - prev| < 2^31 counts. */
static inline int32_t br_counts_delta(int32_t now, int32_t prev)
{
    uint32_t d = (uint32_t)now - (uint32_t)prev;
    return (d <= (uint32_t)INT32_MAX) ? (int32_t)d : -(int32_t)(~d) - 1;
}

#endif
