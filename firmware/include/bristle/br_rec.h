/* SPDX-License-Identifier: Apache-2.0 */
/* The on-target recorder: one control period's sample taken from the
 * application, and a RAM ring buffer of those samples with a trigger and a
 * pre-trigger share, dumped through the link a bounded number of frames per
 * period (docs/link.md, "The recorder"). Telemetry, the same sample sent
 * every N periods, is bristle/br_tlm.h.
 *
 * Per control period, after br_app_step:
 *
 *   br_rec_sample_take(&s, &app, tick, st);   the period's sample
 *   br_rec_push(&rec, &s);                    into the ring; triggers
 *   br_rec_dump_step(&rec, &link);            at most dump_frames_per_period frames
 *
 * and each request br_link_step returns goes to br_rec_command. A fault that
 * latches (br_app_t.fault changing to a cause other than DISARMED) triggers
 * the recorder whenever it is recording, so the samples around it are kept:
 * the pre_samples before the period it latched in and the post-trigger ones
 * after it, until the host re-arms the recorder. */
#ifndef BR_REC_H
#define BR_REC_H

#include <stdint.h>

#include "bristle/br_app.h"
#include "bristle/br_link.h"
#include "bristle/br_status.h"

/* A sample packed: the tlm_sample payload (bristle_gen/link/br_link_msgs.h). */
#define BR_REC_SAMPLE_BYTES BR_LINK_MSG_TLM_SAMPLE_LEN
/* The dump's index is a u16 on the wire. */
#define BR_REC_CAPACITY_MAX 65535u
/* The most dump frames one period may queue: the link's transmit buffer holds four frames. */
#define BR_REC_DUMP_FRAMES_MAX 4u

/* br_rec_sample_t.flags */
#define BR_REC_FLAG_REF_LIMITED 0x01u /* the reference was limited (br_app_t.ref_limited) */
#define BR_REC_FLAG_SATURATED 0x02u   /* the torque command was clipped */
#define BR_REC_FLAG_HELD 0x04u        /* the encoder read failed: the count was held */
#define BR_REC_FLAG_STOP_SHIFT 3u     /* bits 3-4: br_app_t.stop (how a latched fault stops) */

/* One control period, as br_app_step left it. */
typedef struct {
    uint32_t tick;         /* the period's index (the caller's count) */
    int32_t counts;        /* the encoder count the period used (br_app_t.last_counts) */
    int32_t ref_counts;    /* the limited reference the controller tracked: whole counts ... */
    float ref_frac;        /* ... and the fraction of a count */
    float duty;            /* PWM duty written */
    float F_hat_N;         /* compensation force used, N (load side) */
    uint16_t n_outliers;   /* outlier periods in the lock monitor's window (br_app_t.n_lock) */
    int8_t status;         /* br_app_step's status: BR_W_OUTLIER, a measurement skipped */
    uint8_t fault;         /* br_app_fault_t */
    uint8_t flags;         /* BR_REC_FLAG_* */
} br_rec_sample_t;

/* One slot of the ring: a sample packed (caller-owned storage, br_rec_cfg_t.slots). */
typedef struct {
    uint8_t b[BR_REC_SAMPLE_BYTES];
} br_rec_slot_t;

/* The sample of the period br_app_step(app) just ran, which returned st, at
 * tick. BR_E_NULL for a NULL pointer (*s untouched). */
br_status_t br_rec_sample_take(br_rec_sample_t *s, const br_app_t *app, uint32_t tick, br_status_t st);

/* s packed into out (BR_REC_SAMPLE_BYTES: the fields in the message table's
 * order, little-endian, f32 as IEEE 754 binary32), and back. */
void br_rec_sample_pack(const br_rec_sample_t *s, uint8_t out[BR_REC_SAMPLE_BYTES]);
void br_rec_sample_unpack(const uint8_t in[BR_REC_SAMPLE_BYTES], br_rec_sample_t *s);

/* The following error of a sample, counts: limited reference - position, the
 * position at the count's centre (as the estimator sees it). */
float br_rec_following_counts(const br_rec_sample_t *s);

typedef enum {
    BR_REC_ARMED = 0,      /* recording, waiting for a trigger */
    BR_REC_COLLECTING = 1, /* triggered: recording the post-trigger samples */
    BR_REC_DONE = 2        /* the capture is complete and held (nothing recorded) until re-armed */
} br_rec_state_t;

typedef enum {
    BR_REC_TRIG_NONE = 0,
    BR_REC_TRIG_FAULT = 1,     /* a fault latched */
    BR_REC_TRIG_COMMAND = 2,   /* br_rec_trigger (the host's rec_trigger) */
    BR_REC_TRIG_CONDITION = 3  /* |following| above trig_following_counts */
} br_rec_trig_t;

typedef struct {
    br_rec_slot_t *slots;             /* the ring: capacity slots, the caller's RAM */
    uint32_t capacity;                /* samples, 1..BR_REC_CAPACITY_MAX */
    uint32_t pre_samples;             /* kept before the trigger sample, 0..capacity - 1; the
                                         capture is these, the trigger sample and
                                         capacity - 1 - pre_samples after it */
    float trig_following_counts;      /* > 0: a sample of a running axis (fault NONE) whose
                                         |following| is above it triggers; 0: no condition */
    uint32_t dump_frames_per_period;  /* frames br_rec_dump_step may queue, 1..BR_REC_DUMP_FRAMES_MAX */
} br_rec_cfg_t;

typedef struct {
    br_rec_cfg_t cfg;
    uint32_t head;          /* the slot of the next sample */
    uint32_t n;             /* samples in the ring, <= capacity */
    br_rec_state_t state;
    br_rec_trig_t cause;    /* the trigger of the capture (NONE while armed) */
    uint32_t post_left;     /* COLLECTING: samples still to record after the trigger */
    uint32_t trig_tick;     /* the trigger sample's tick */
    uint8_t prev_fault;     /* the last sample's fault (a change to a cause is a fault latching) */
    int trig_pending;       /* a command trigger: the next sample recorded is the trigger */
    uint32_t missed_faults; /* faults that latched while a capture was held (wraps) */
    int dump_active;        /* a dump is under way */
    uint32_t dump_next;     /* the next index it sends; past the capture: rec_end */
    int ready;
} br_rec_t;

/* Validates cfg (BR_E_NULL: rec, cfg or slots NULL; BR_E_PARAM: capacity 0 or
 * above BR_REC_CAPACITY_MAX, pre_samples >= capacity, trig_following_counts
 * negative or not finite, dump_frames_per_period out of range) and starts
 * ARMED with an empty ring. After a failed init every call returns BR_E_STATE. */
br_status_t br_rec_init(br_rec_t *rec, const br_rec_cfg_t *cfg);

/* Records one sample (ARMED, COLLECTING) and applies the triggers; in DONE
 * nothing is recorded (a fault latching then is counted in missed_faults).
 * ARMED: a fault latching, else a pending command, else the condition
 * triggers at this sample. COLLECTING: a fault latching after a command or
 * condition trigger moves the trigger to it (the pre-trigger samples before
 * it are still in the ring); otherwise one post-trigger sample fewer to go,
 * DONE at zero. BR_E_NULL, BR_E_STATE. */
br_status_t br_rec_push(br_rec_t *rec, const br_rec_sample_t *s);

/* Drops the capture and any dump, empties the ring and records again (ARMED).
 * BR_E_NULL, BR_E_STATE. */
br_status_t br_rec_arm(br_rec_t *rec);

/* The next sample recorded is the trigger: BR_OK when ARMED, BR_E_STATE otherwise
 * (or not initialised; nothing changes). BR_E_NULL. */
br_status_t br_rec_trigger(br_rec_t *rec);

/* Starts a dump from index first: br_rec_dump_step then sends the capture's
 * samples first..count - 1 and rec_end; before a capture is complete, or with
 * first >= count, rec_end alone. A dump under way restarts at first. BR_E_NULL, BR_E_STATE. */
br_status_t br_rec_dump_request(br_rec_t *rec, uint32_t first);

/* At most dump_frames_per_period frames of the dump under way queued on
 * link, in index order; a frame the link refuses (BR_E_BUSY, its queue full)
 * is sent again at the next call, nothing skipped. BR_OK (also with no dump),
 * BR_E_NULL, BR_E_STATE, or the link's error other than BUSY. */
br_status_t br_rec_dump_step(br_rec_t *rec, br_link_t *link);

/* A host's request from br_link_step: REC_ARM, REC_TRIGGER, REC_DUMP are
 * acted on (1 returned; a trigger while not ARMED is ignored), any other kind
 * is the caller's (0). A NULL rec or cmd, or rec not initialised: 0. */
int br_rec_command(br_rec_t *rec, const br_link_cmd_t *cmd);

/* Samples in the capture (DONE), 0 before it is complete. */
uint32_t br_rec_count(const br_rec_t *rec);

/* The trigger sample's index in the capture (DONE; 0 otherwise). */
uint32_t br_rec_trigger_index(const br_rec_t *rec);

/* Sample i of what the ring holds, 0 the oldest (i < rec->n). BR_E_NULL,
 * BR_E_STATE, BR_E_PARAM (i out of range). */
br_status_t br_rec_get(const br_rec_t *rec, uint32_t i, br_rec_sample_t *s);

#endif
