/* SPDX-License-Identifier: Apache-2.0 */
/* libFuzzer target: the ports' counter extension
 * (br_count_ext_update, bristle/br_port.h, used by every port), which turns an n-bit timer
 * count (outside data: whatever the encoder did between two reads) into the
 * 32-bit count, read through the application's encoder guard (br_app_step,
 * BR_APP_FAULT_ENC_JUMP) as on the target. The input: the counter width
 * (2..32 bits), the guard's largest delta per period (below half the
 * counter's range), the true count at the start, then one motion per period
 * (an int16 scaled by 2^0..2^15). Properties, for every period:
 *   - a motion of at most the guard's delta: accepted, and the extended count
 *     equals the true count (less the start's bits above n, which the
 *     extension cannot know);
 *   - a motion more than the guard's delta away from every multiple of 2^n:
 *     a latched ENC_JUMP fault, duty 0 (within half the range the extension
 *     is still exact; beyond it the count aliases, and the guard must catch
 *     it rather than pass a wrong count);
 *   - a motion within the guard's delta of a non-zero multiple of 2^n (a
 *     whole counter turn in one period) cannot be seen by any reader of an
 *     n-bit counter: the run ends there.
 * A violated property aborts (a finding). docs/reliability.md. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_port.h"

typedef struct {
    br_count_ext_t ext;
    uint32_t true_counts; /* the axis's position, modulo 2^32 */
    float duty;
} port_t;

static br_status_t enc_read(void *ctx, int32_t *c)
{
    port_t *p = ctx;
    *c = br_count_ext_update(&p->ext, p->true_counts); /* the timer holds the low n bits */
    return BR_OK;
}
static br_status_t pwm_write(void *ctx, float d)
{
    ((port_t *)ctx)->duty = d;
    return BR_OK;
}
static br_status_t tick_wait(void *ctx, uint32_t *t)
{
    (void)ctx;
    *t = 0u;
    return BR_OK;
}

static uint32_t get_u32(const uint8_t *d)
{
    return (uint32_t)d[0] | ((uint32_t)d[1] << 8) | ((uint32_t)d[2] << 16) | ((uint32_t)d[3] << 24);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 9u) return 0;
    const uint32_t bits = 2u + data[0] % 31u;
    const uint64_t range = (uint64_t)1u << bits, half = range / 2u;
    const uint64_t dmax_limit = (half - 1u < (1u << 30)) ? half - 1u : (1u << 30);
    const uint32_t max_delta = 1u + get_u32(data + 1) % (uint32_t)dmax_limit;
    port_t p;
    memset(&p, 0, sizeof p);
    p.true_counts = get_u32(data + 5);
    if (br_count_ext_init(&p.ext, bits, p.true_counts) != BR_OK) abort();
    /* the bits above n at the start: the extension starts from the counter's value */
    const uint32_t offset = p.true_counts - p.ext.ext;

    const br_hal_t hal = {&p, enc_read, pwm_write, tick_wait, NULL, NULL};
    const br_ctrl_cfg_t k = {{-0.5f, -0.01f, -10.0f}, 1e-3f, 0.64f, 0.64f, 6.0e-6f, 1.27e-3f};
    br_app_guard_cfg_t g = br_app_guard_cfg(1e-3f, 1.0e6f);
    g.enc_max_delta_counts = max_delta;
    /* drive protections far from the counter's range (1 count = 1 m): the
     * extension is what this fuzzes; a motion fault ends the input */
    const br_app_motion_cfg_t mc = {.counts_per_m = 1.0f, .max_speed_mps = 1e9f, .max_accel_mps2 = 1e15f,
                                    .speed_fault_mps = 1.1e9f, .max_following_m = 1e9f, .soft_min_m = -9e8f,
                                    .soft_max_m = 9e8f, .stop_bound_m = 1.0f, .brake_N = 0.0f, .mass_kg = 10.0f,
                                    .stuck_band_N = 36.0f, .stuck_counts = 8.0f};
    const br_app_cfg_t c = {&k, BR_APP_EST_NONE, NULL, NULL, NULL, g, mc};
    br_app_t app;
    if (br_app_init(&app, &c, &hal, NULL) != BR_OK || br_app_arm(&app) != BR_OK) abort();

    /* the first period reads the start (no delta yet) */
    br_ref_t r = {(int32_t)(p.true_counts - offset), 0.0f, 0.0f};
    const br_status_t st0 = br_app_step(&app, &r);
    if (st0 == BR_E_FAULT && app.fault == BR_APP_FAULT_TRAVEL) return 0; /* a start beyond the stroke */
    if (BR_FAILED(st0)) abort();
    for (size_t i = 9u; i + 3u <= size; i += 3u) {
        const int16_t v = (int16_t)((uint16_t)data[i] | (uint16_t)((uint16_t)data[i + 1] << 8));
        const int64_t step = (int64_t)v * ((int64_t)1 << (data[i + 2] % 16u));
        const uint64_t mag = (uint64_t)(step < 0 ? -step : step);
        const uint64_t m = mag % range; /* the motion the counter shows, as 0..2^n - 1 */
        const int whole_turn = mag > max_delta && (m <= max_delta || range - m <= max_delta);
        p.true_counts += (uint32_t)step; /* modulo 2^32 */
        r.ref_counts = (int32_t)(p.true_counts - offset);
        const br_status_t st = br_app_step(&app, &r);
        if (st == BR_E_FAULT && (app.fault == BR_APP_FAULT_TRAVEL || app.fault == BR_APP_FAULT_ENC_FROZEN ||
                                 app.fault == BR_APP_FAULT_SPEED || app.fault == BR_APP_FAULT_FOLLOWING)) {
            return 0;
        }
        if (mag <= max_delta) {
            /* accepted, exact */
            if (st != BR_OK || p.ext.ext != p.true_counts - offset) abort();
        } else if (!whole_turn) {
            /* implausible: latched, duty 0 */
            if (st != BR_E_FAULT || app.fault != BR_APP_FAULT_ENC_JUMP || p.duty != 0.0f) abort();
            if (mag < half && p.ext.ext != p.true_counts - offset) abort(); /* still exact */
            return 0;
        } else {
            return 0; /* a whole counter turn in one period: invisible to an n-bit counter */
        }
    }
    return 0;
}
