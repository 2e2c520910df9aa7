/* SPDX-License-Identifier: Apache-2.0 */
/* The conversions every port shares (bristle/br_port.h, docs/porting.md). */
#include "bristle/br_port.h"

#include <math.h>
#include <stddef.h>

#define BR_DUTY_FULL_MAX (1u << 24)

/* uint32 -> int32 two's complement without implementation-defined casts. */
static int32_t br_u32_to_i32(uint32_t u)
{
    return (u <= (uint32_t)INT32_MAX) ? (int32_t)u : -(int32_t)(~u) - 1;
}

br_status_t br_count_ext_init(br_count_ext_t *e, uint32_t counter_bits, uint32_t raw)
{
    if (e == NULL) {
        return BR_E_NULL;
    }
    if (counter_bits < 2u || counter_bits > 32u) {
        return BR_E_PARAM;
    }
    e->mask = (counter_bits == 32u) ? 0xFFFFFFFFu : ((1u << counter_bits) - 1u);
    e->half = 1u << (counter_bits - 1u);
    e->last_raw = raw & e->mask;
    e->ext = e->last_raw;
    return BR_OK;
}

int32_t br_count_ext_update(br_count_ext_t *e, uint32_t raw)
{
    uint32_t now = raw & e->mask;
    uint32_t d = (now - e->last_raw) & e->mask; /* difference modulo 2^n */
    if ((d & e->half) != 0u) {
        d |= ~e->mask;                           /* negative: sign-extend to 32 bits */
    }
    e->last_raw = now;
    e->ext += d;                                 /* modulo 2^32 */
    return br_u32_to_i32(e->ext);
}

br_status_t br_duty_split(float duty, uint32_t full, uint32_t *ccr_a, uint32_t *ccr_b)
{
    float mag;
    uint32_t ccr;

    if (ccr_a == NULL || ccr_b == NULL) {
        return BR_E_NULL;
    }
    *ccr_a = 0u;
    *ccr_b = 0u;
    if (full > BR_DUTY_FULL_MAX) {
        return BR_E_PARAM;
    }
    if (!isfinite(duty)) {
        return BR_E_INPUT;
    }
    mag = fabsf(duty);
    if (mag > 1.0f) {
        mag = 1.0f;
    }
    /* full <= 2^24 is exact in float; the +0.5 rounds to nearest */
    ccr = (uint32_t)(mag * (float)full + 0.5f);
    if (ccr > full) {
        ccr = full;
    }
    if (duty >= 0.0f) {
        *ccr_a = ccr;
    } else {
        *ccr_b = ccr;
    }
    return BR_OK;
}

br_status_t br_tick_cycles(uint32_t cpu_hz, uint32_t control_hz, uint32_t period_ns, uint32_t min_cycles,
                           uint32_t max_cycles, uint32_t *cycles)
{
    uint32_t c;

    if (cycles == NULL) {
        return BR_E_NULL;
    }
    if (cpu_hz == 0u || (control_hz == 0u) == (period_ns == 0u)) {
        return BR_E_PARAM; /* exactly one of control_hz and period_ns */
    }
    /* The tick must be exact (the controller's dt is the nominal period). */
    if (period_ns != 0u) {
        const uint64_t c_ns = (uint64_t)cpu_hz * (uint64_t)period_ns;
        if (c_ns % 1000000000u != 0u || c_ns / 1000000000u > (uint64_t)UINT32_MAX) {
            return BR_E_PARAM;
        }
        c = (uint32_t)(c_ns / 1000000000u);
    } else {
        if (cpu_hz % control_hz != 0u) {
            return BR_E_PARAM;
        }
        c = cpu_hz / control_hz;
    }
    if (c < min_cycles || c > max_cycles) {
        return BR_E_PARAM;
    }
    *cycles = c;
    return BR_OK;
}
