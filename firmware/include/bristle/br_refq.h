/* SPDX-License-Identifier: Apache-2.0 */
/* The reference queue: a reference source fed by the link (docs/link.md,
 * "Setpoints and segments"; docs/modules/refq.md). Timed setpoints and cubic
 * segments wait in a bounded queue (its length fixed in the configuration);
 * br_refq_step makes one br_ref_t per control period from the item whose time
 * it is. When the stream runs dry (an underrun) the reference
 *
 *   1. holds: the last reference goes on at its last velocity for hold_periods,
 *   2. brakes: its velocity falls to 0 at the machine's max_accel_mps2,
 *   3. faults: after fault_periods of underrun, br_refq_step returns BR_E_FAULT
 *      (the caller latches BR_APP_FAULT_REF_UNDERRUN),
 *
 * unless an item ends the stream (BR_REFQ_FLAG_LAST): then the reference holds
 * its last position, with no underrun. The application's reference limiter
 * (br_app_step) still applies on top. Caller-owned, no allocation, bounded work. */
#ifndef BR_REFQ_H
#define BR_REFQ_H

#include <stdint.h>

#include "bristle/br_ref.h"
#include "bristle/br_status.h"

/* the largest queue (br_refq_cfg_t.queue_len) */
#define BR_REFQ_MAX 64u
/* the largest displacement of one segment, counts: a float32 keeps a
 * displacement below 2^24 counts to within one unit in its last place (below
 * 1 count); larger moves are several segments */
#define BR_REFQ_SEG_MAX_COUNTS 16777216.0f

/* item kinds */
#define BR_REFQ_SETPOINT 0u /* one period's reference: counts + frac, v = omega_radps */
#define BR_REFQ_SEGMENT 1u  /* periods periods of p(t) = counts + frac + v t + a t^2 / 2 + j t^3 / 6 */
/* item flags */
#define BR_REFQ_FLAG_LAST 1u /* the stream's last item: afterwards the reference holds, no underrun */

typedef struct {
    uint8_t kind;     /* BR_REFQ_SETPOINT or BR_REFQ_SEGMENT */
    uint8_t flags;    /* BR_REFQ_FLAG_* */
    uint32_t tick;    /* the control period it starts at (br_refq_step's tick) */
    uint32_t periods; /* SEGMENT: its duration in periods, >= 1 (a SETPOINT: 1) */
    int32_t counts;   /* start position, whole counts */
    float frac;       /* its fraction, [0, 1) */
    float v;          /* SETPOINT: omega_radps, motor side; SEGMENT: counts/s */
    float a;          /* SEGMENT: counts/s^2 */
    float j;          /* SEGMENT: counts/s^3 */
} br_refq_item_t;

typedef enum {
    BR_REFQ_IDLE = 0,    /* no stream (since the start, or after its last item): the position held */
    BR_REFQ_STREAM = 1,  /* an item's reference */
    BR_REFQ_HOLD = 2,    /* underrun: the last reference going on at its velocity */
    BR_REFQ_BRAKE = 3,   /* underrun: braking at max_accel */
    BR_REFQ_FAULT = 4    /* underrun beyond fault_periods */
} br_refq_state_t;

typedef struct {
    uint32_t queue_len;      /* 1..BR_REFQ_MAX */
    float dt_s;              /* control period, > 0 */
    float rad_per_count;     /* encoder resolution, > 0 */
    float counts_per_m;      /* load metres to counts (br_app_motion_cfg_t.counts_per_m), > 0 */
    float max_speed_mps;     /* the machine's limits (br_app_motion_cfg_t), > 0 */
    float max_accel_mps2;
    uint32_t hold_periods;   /* underrun: periods the last reference goes on */
    uint32_t fault_periods;  /* underrun: periods before BR_E_FAULT; more than hold_periods plus
                                the braking from max_speed (ceil(max_speed / (max_accel dt))) */
} br_refq_cfg_t;

typedef struct {
    uint32_t dropped;   /* items refused: the queue full */
    uint32_t late;      /* items refused (not after the last one queued) or dropped (over before their time) */
    uint32_t rejected;  /* items refused: a field non-finite or out of range */
    uint32_t underruns; /* underruns begun */
} br_refq_counters_t;

typedef struct {
    br_refq_cfg_t cfg;
    br_refq_item_t q[BR_REFQ_MAX]; /* a ring: head, n items */
    uint32_t head, n;
    uint32_t end_tick;    /* the period after the last queued item (order check) */
    int have_end;
    br_refq_state_t state;
    int32_t pos_counts;   /* the last reference made: whole counts ... */
    float pos_frac;       /* ... fraction ... */
    float v_cpp;          /* ... and velocity, counts per period */
    uint32_t n_under;     /* periods of the current underrun */
    float a_cpp2;         /* max_accel in counts per period^2 */
    br_refq_counters_t cnt;
    int ready;
} br_refq_t;

/* The smallest fault_periods br_refq_init accepts for cfg's other fields:
 * hold_periods + ceil(max_speed / (max_accel dt)) + 1 (the fault one period
 * after the braking from max_speed); 0 when they give none (a limit or the
 * period not finite positive, the braking 1e9 periods or more, hold_periods
 * above 1e9). */
uint32_t br_refq_fault_periods_min(const br_refq_cfg_t *cfg);

/* Validates cfg (BR_E_NULL, BR_E_PARAM); the queue empty, IDLE at count 0. */
br_status_t br_refq_init(br_refq_t *q, const br_refq_cfg_t *cfg);

/* IDLE at counts (the axis's position; at an arm); the queue is kept. */
br_status_t br_refq_start(br_refq_t *q, int32_t counts);

/* Empties the queue (a disarm, a fault: the stream is abandoned); the state IDLE at the last reference. */
br_status_t br_refq_clear(br_refq_t *q);

/* Queues one item. BR_E_INPUT (counted in rejected): a kind or flag unknown, a
 * field non-finite, frac outside [0, 1), a segment of 0 periods or whose
 * displacement bound |v| T + |a| T^2 / 2 + |j| T^3 / 6 exceeds
 * BR_REFQ_SEG_MAX_COUNTS; BR_E_INPUT (counted in late): it does not start
 * after the last item queued ends; BR_E_BUSY (counted in dropped): the queue
 * is full. BR_E_NULL, BR_E_STATE. */
br_status_t br_refq_push(br_refq_t *q, const br_refq_item_t *it);

/* The reference of period tick into *out (always written, also on BR_E_FAULT):
 * items over before tick are dropped (late); the head's reference when its
 * time has come (a setpoint: its fields as they are; a segment at t = (tick -
 * start) dt: counts + frac + t (v + t (a / 2 + t j / 6)), omega = (v + t (a +
 * t j / 2)) rad_per_count); else the underrun's hold / brake, or the idle
 * position. BR_OK; BR_E_FAULT once an underrun lasts more than fault_periods
 * (and every period after, until an item comes or br_refq_start/clear);
 * BR_E_NULL, BR_E_STATE. */
br_status_t br_refq_step(br_refq_t *q, uint32_t tick, br_ref_t *out);

#endif
