/* SPDX-License-Identifier: Apache-2.0 */
/* The recorder: a ring of samples in the caller's RAM, its triggers and its
 * dump through the link (bristle/br_rec.h, docs/link.md, "The recorder"). */
#include "bristle/br_rec.h"

#include <math.h>
#include <string.h>

#include "br_le.h"

br_status_t br_rec_init(br_rec_t *rec, const br_rec_cfg_t *cfg)
{
    if (rec == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    rec->ready = 0;
    if (cfg->slots == NULL) {
        return BR_E_NULL;
    }
    /* pre_samples < capacity: room for the trigger sample (and so capacity >= 1) */
    if (cfg->capacity > BR_REC_CAPACITY_MAX || cfg->pre_samples >= cfg->capacity ||
        !isfinite(cfg->trig_following_counts) || cfg->trig_following_counts < 0.0f ||
        cfg->dump_frames_per_period < 1u || cfg->dump_frames_per_period > BR_REC_DUMP_FRAMES_MAX) {
        return BR_E_PARAM;
    }
    rec->cfg = *cfg;
    rec->prev_fault = (uint8_t)BR_APP_FAULT_DISARMED;
    rec->missed_faults = 0u;
    rec->ready = 1;
    return br_rec_arm(rec);
}

br_status_t br_rec_arm(br_rec_t *rec)
{
    if (rec == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready) {
        return BR_E_STATE;
    }
    rec->head = 0u;
    rec->n = 0u;
    rec->state = BR_REC_ARMED;
    rec->cause = BR_REC_TRIG_NONE;
    rec->post_left = 0u;
    rec->trig_tick = 0u;
    rec->trig_pending = 0;
    rec->dump_active = 0;
    rec->dump_next = 0u;
    return BR_OK;
}

br_status_t br_rec_trigger(br_rec_t *rec)
{
    if (rec == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready || rec->state != BR_REC_ARMED) {
        return BR_E_STATE;
    }
    rec->trig_pending = 1;
    return BR_OK;
}

/* the sample just recorded is the trigger: cap - 1 - pre samples to come */
static void trigger_here(br_rec_t *rec, br_rec_trig_t cause, uint32_t tick)
{
    rec->cause = cause;
    rec->trig_tick = tick;
    rec->trig_pending = 0;
    rec->post_left = rec->cfg.capacity - 1u - rec->cfg.pre_samples;
    rec->state = (rec->post_left == 0u) ? BR_REC_DONE : BR_REC_COLLECTING;
}

br_status_t br_rec_push(br_rec_t *rec, const br_rec_sample_t *s)
{
    if (rec == NULL || s == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready) {
        return BR_E_STATE;
    }
    /* a fault latching: the cause changed to one that is not DISARMED */
    const int fault_now = (s->fault != rec->prev_fault && s->fault != (uint8_t)BR_APP_FAULT_NONE &&
                           s->fault != (uint8_t)BR_APP_FAULT_DISARMED);
    rec->prev_fault = s->fault;
    if (rec->state == BR_REC_DONE) {
        /* the capture is held: nothing overwrites it */
        if (fault_now) {
            ++rec->missed_faults;
        }
        return BR_OK;
    }
    br_rec_sample_pack(s, rec->cfg.slots[rec->head].b);
    rec->head = (rec->head + 1u == rec->cfg.capacity) ? 0u : rec->head + 1u;
    if (rec->n < rec->cfg.capacity) {
        ++rec->n;
    }
    if (rec->state == BR_REC_ARMED) {
        if (fault_now) {
            trigger_here(rec, BR_REC_TRIG_FAULT, s->tick);
        } else if (rec->trig_pending) {
            trigger_here(rec, BR_REC_TRIG_COMMAND, s->tick);
        } else if (rec->cfg.trig_following_counts > 0.0f && s->fault == (uint8_t)BR_APP_FAULT_NONE &&
                   fabsf(br_rec_following_counts(s)) > rec->cfg.trig_following_counts) {
            trigger_here(rec, BR_REC_TRIG_CONDITION, s->tick);
        }
        return BR_OK;
    }
    /* COLLECTING */
    if (fault_now && rec->cause != BR_REC_TRIG_FAULT) {
        /* the fault's surroundings come first: the ring still holds the
         * samples before it, the post-trigger count starts again */
        trigger_here(rec, BR_REC_TRIG_FAULT, s->tick);
        return BR_OK;
    }
    if (--rec->post_left == 0u) {
        rec->state = BR_REC_DONE;
    }
    return BR_OK;
}

uint32_t br_rec_count(const br_rec_t *rec)
{
    return (rec != NULL && rec->ready && rec->state == BR_REC_DONE) ? rec->n : 0u;
}

uint32_t br_rec_trigger_index(const br_rec_t *rec)
{
    /* DONE: the newest capacity - 1 - pre samples came after the trigger */
    if (br_rec_count(rec) == 0u) {
        return 0u;
    }
    return rec->n - 1u - (rec->cfg.capacity - 1u - rec->cfg.pre_samples);
}

/* the slot of index i, 0 the oldest sample held */
static const br_rec_slot_t *slot_of(const br_rec_t *rec, uint32_t i)
{
    const uint32_t oldest = (rec->head + rec->cfg.capacity - rec->n) % rec->cfg.capacity;
    return &rec->cfg.slots[(oldest + i) % rec->cfg.capacity];
}

br_status_t br_rec_get(const br_rec_t *rec, uint32_t i, br_rec_sample_t *s)
{
    if (rec == NULL || s == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready) {
        return BR_E_STATE;
    }
    if (i >= rec->n) {
        return BR_E_PARAM;
    }
    br_rec_sample_unpack(slot_of(rec, i)->b, s);
    return BR_OK;
}

br_status_t br_rec_dump_request(br_rec_t *rec, uint32_t first)
{
    if (rec == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready) {
        return BR_E_STATE;
    }
    rec->dump_active = 1;
    rec->dump_next = first;
    return BR_OK;
}

static br_status_t send_sample(br_link_t *link, const br_rec_t *rec, uint32_t i)
{
    uint8_t p[BR_LINK_MSG_REC_SAMPLE_LEN];
    br_le_put(&p[BR_LINK_MSG_REC_SAMPLE_OFF_INDEX], i, 2u);
    memcpy(&p[BR_LINK_MSG_REC_SAMPLE_OFF_TICK], slot_of(rec, i)->b, BR_REC_SAMPLE_BYTES);
    return br_link_send(link, BR_LINK_MSG_REC_SAMPLE, p, sizeof p);
}

static br_status_t send_end(br_link_t *link, const br_rec_t *rec)
{
    uint8_t p[BR_LINK_MSG_REC_END_LEN];
    br_le_put(&p[BR_LINK_MSG_REC_END_OFF_COUNT], br_rec_count(rec), 2u);
    br_le_put(&p[BR_LINK_MSG_REC_END_OFF_TRIGGER_INDEX], br_rec_trigger_index(rec), 2u);
    br_le_put(&p[BR_LINK_MSG_REC_END_OFF_TRIGGER_TICK], rec->trig_tick, 4u);
    p[BR_LINK_MSG_REC_END_OFF_CAUSE] = (uint8_t)rec->cause;
    p[BR_LINK_MSG_REC_END_OFF_STATE] = (uint8_t)rec->state;
    br_le_put(&p[BR_LINK_MSG_REC_END_OFF_MISSED_FAULTS],
              rec->missed_faults > 0xFFFFu ? 0xFFFFu : rec->missed_faults, 2u);
    return br_link_send(link, BR_LINK_MSG_REC_END, p, sizeof p);
}

br_status_t br_rec_dump_step(br_rec_t *rec, br_link_t *link)
{
    if (rec == NULL || link == NULL) {
        return BR_E_NULL;
    }
    if (!rec->ready) {
        return BR_E_STATE;
    }
    const uint32_t count = br_rec_count(rec);
    for (uint32_t f = 0u; f < rec->cfg.dump_frames_per_period && rec->dump_active; ++f) {
        const int end = (rec->dump_next >= count);
        const br_status_t st = end ? send_end(link, rec) : send_sample(link, rec, rec->dump_next);
        if (st == BR_E_BUSY) {
            return BR_OK; /* the link's queue is full: this frame again next period */
        }
        if (st != BR_OK) {
            return st;
        }
        if (end) {
            rec->dump_active = 0;
        } else {
            ++rec->dump_next;
        }
    }
    return BR_OK;
}

int br_rec_command(br_rec_t *rec, const br_link_cmd_t *cmd)
{
    if (rec == NULL || cmd == NULL || !rec->ready) {
        return 0;
    }
    switch (cmd->kind) {
    case BR_LINK_CMD_REC_ARM:
        (void)br_rec_arm(rec);
        return 1;
    case BR_LINK_CMD_REC_TRIGGER:
        (void)br_rec_trigger(rec); /* not ARMED: nothing to trigger */
        return 1;
    case BR_LINK_CMD_REC_DUMP:
        (void)br_rec_dump_request(rec, cmd->first);
        return 1;
    default:
        return 0;
    }
}
