/* SPDX-License-Identifier: Apache-2.0 */
/* What every MCU port needs and computes the same way (docs/porting.md):
 * the extension of an n-bit hardware encoder counter to the free-running
 * int32 count of br_hal_t.encoder_read, the sign-magnitude split of a duty
 * into two compare values, and the exact control tick in processor cycles.
 * One home for these conversions: a port only moves register values. */
#ifndef BR_PORT_H
#define BR_PORT_H

#include <stdint.h>

#include "bristle/br_status.h"

/* Extension of an n-bit hardware counter (2 <= n <= 32) to a free-running
 * 32-bit count: each update adds the raw difference read as a signed n-bit
 * value. Correct while the counter moves less than 2^(n-1) between updates. */
typedef struct {
    uint32_t mask;      /* 2^n - 1 */
    uint32_t half;      /* 2^(n-1): sign bit of an n-bit difference */
    uint32_t last_raw;  /* raw counter at the previous update */
    uint32_t ext;       /* extended count modulo 2^32 */
} br_count_ext_t;

/* BR_E_NULL, BR_E_PARAM (counter_bits outside 2..32). */
br_status_t br_count_ext_init(br_count_ext_t *e, uint32_t counter_bits, uint32_t raw);

/* Folds in a new raw reading (bits above n are ignored); returns the extended
 * count as int32 (two's complement of ext). */
int32_t br_count_ext_update(br_count_ext_t *e, uint32_t raw);

/* Sign-magnitude PWM on two half-bridge legs with compare range 0..full:
 * |duty| clamped to 1, compare = round(|duty| full) (<= full);
 * duty >= 0: *ccr_a = compare, *ccr_b = 0; duty < 0: *ccr_a = 0, *ccr_b = compare.
 * A non-finite duty gives both 0 and BR_E_INPUT (the motor is never driven
 * from a NaN). full must be <= 2^24 (exact in float). BR_E_NULL, BR_E_PARAM. */
br_status_t br_duty_split(float duty, uint32_t full, uint32_t *ccr_a, uint32_t *ccr_b);

/* Processor cycles per control tick, exact: from control_hz (then period_ns
 * = 0; cpu_hz must be a multiple) or from period_ns (then control_hz = 0;
 * cpu_hz * period_ns must be a whole number of cycles, e.g. the PF's
 * 1.5 ms). BR_E_PARAM when neither or both are given, when the period is
 * not exact, or when the cycles are outside min_cycles .. max_cycles. */
br_status_t br_tick_cycles(uint32_t cpu_hz, uint32_t control_hz, uint32_t period_ns, uint32_t min_cycles,
                           uint32_t max_cycles, uint32_t *cycles);

#endif
