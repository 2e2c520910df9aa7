/* SPDX-License-Identifier: Apache-2.0 */
/* The reference queue (bristle/br_refq.h, docs/modules/refq.md). */
#include "bristle/br_refq.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"

uint32_t br_refq_fault_periods_min(const br_refq_cfg_t *cfg)
{
    if (cfg == NULL || !br_finite_pos(cfg->dt_s) || !br_finite_pos(cfg->max_speed_mps) ||
        !br_finite_pos(cfg->max_accel_mps2)) {
        return 0u;
    }
    /* the fault comes after the braking: hold + the periods max_speed takes to stop at max_accel */
    const float brake_periods = ceilf(cfg->max_speed_mps / (cfg->max_accel_mps2 * cfg->dt_s));
    if (!(brake_periods < 1.0e9f) || cfg->hold_periods > 1000000000u) {
        return 0u;
    }
    return cfg->hold_periods + (uint32_t)brake_periods + 1u;
}

br_status_t br_refq_init(br_refq_t *q, const br_refq_cfg_t *cfg)
{
    if (q == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    q->ready = 0;
    if (cfg->queue_len < 1u || cfg->queue_len > BR_REFQ_MAX || !br_finite_pos(cfg->dt_s) ||
        !br_finite_pos(cfg->rad_per_count) || !br_finite_pos(cfg->counts_per_m) ||
        !br_finite_pos(cfg->max_speed_mps) || !br_finite_pos(cfg->max_accel_mps2)) {
        return BR_E_PARAM;
    }
    const uint32_t fault_min = br_refq_fault_periods_min(cfg);
    if (fault_min == 0u || cfg->fault_periods < fault_min) {
        return BR_E_PARAM;
    }
    q->cfg = *cfg;
    /* eq. refq-1: max_accel in counts per period^2 */
    q->a_cpp2 = cfg->max_accel_mps2 * cfg->counts_per_m * cfg->dt_s * cfg->dt_s;
    q->head = 0u;
    q->n = 0u;
    q->have_end = 0;
    q->end_tick = 0u;
    q->cnt = (br_refq_counters_t){0u, 0u, 0u, 0u};
    q->ready = 1;
    return br_refq_start(q, 0);
}

br_status_t br_refq_start(br_refq_t *q, int32_t counts)
{
    if (q == NULL) {
        return BR_E_NULL;
    }
    if (!q->ready) {
        return BR_E_STATE;
    }
    q->state = BR_REFQ_IDLE;
    q->pos_counts = counts;
    q->pos_frac = 0.0f;
    q->v_cpp = 0.0f;
    q->n_under = 0u;
    return BR_OK;
}

br_status_t br_refq_clear(br_refq_t *q)
{
    if (q == NULL) {
        return BR_E_NULL;
    }
    if (!q->ready) {
        return BR_E_STATE;
    }
    q->n = 0u;
    q->have_end = 0;
    q->state = BR_REFQ_IDLE;
    q->v_cpp = 0.0f;
    q->n_under = 0u;
    return BR_OK;
}

/* 1 when the item's fields are usable (see br_refq_push) */
static int item_ok(const br_refq_item_t *it, const br_refq_cfg_t *c)
{
    if (it->kind > BR_REFQ_SEGMENT || (it->flags & (uint8_t)~BR_REFQ_FLAG_LAST) != 0u ||
        !(it->frac >= 0.0f && it->frac < 1.0f) || !isfinite(it->v)) {
        return 0;
    }
    if (it->kind == BR_REFQ_SETPOINT) {
        /* its speed held over a period stays within a segment's bound */
        return it->periods == 1u && fabsf(it->v) * c->dt_s / c->rad_per_count <= BR_REFQ_SEG_MAX_COUNTS;
    }
    if (it->periods < 1u || !isfinite(it->a) || !isfinite(it->j)) {
        return 0;
    }
    /* the displacement's bound over the segment, T = periods dt */
    const float T = (float)it->periods * c->dt_s;
    const float bound = fabsf(it->v) * T + 0.5f * fabsf(it->a) * T * T + fabsf(it->j) * T * T * T / 6.0f;
    return bound <= BR_REFQ_SEG_MAX_COUNTS;
}

br_status_t br_refq_push(br_refq_t *q, const br_refq_item_t *it)
{
    if (q == NULL || it == NULL) {
        return BR_E_NULL;
    }
    if (!q->ready) {
        return BR_E_STATE;
    }
    if (!item_ok(it, &q->cfg)) {
        ++q->cnt.rejected;
        return BR_E_INPUT;
    }
    /* after the last item queued: its start at or after that item's end (modulo 2^32) */
    if (q->have_end && (int32_t)(it->tick - q->end_tick) < 0) {
        ++q->cnt.late;
        return BR_E_INPUT;
    }
    if (q->n >= q->cfg.queue_len) {
        ++q->cnt.dropped;
        return BR_E_BUSY;
    }
    q->q[(q->head + q->n) % q->cfg.queue_len] = *it;
    ++q->n;
    q->end_tick = it->tick + it->periods;
    q->have_end = 1;
    return BR_OK;
}

/* out from the position (pos_counts, pos_frac) and the velocity v_cpp */
static void out_held(const br_refq_t *q, br_ref_t *out)
{
    out->ref_counts = q->pos_counts;
    out->ref_frac_counts = q->pos_frac;
    out->ref_omega_radps = q->v_cpp / q->cfg.dt_s * q->cfg.rad_per_count;
}

/* moves the held position by d counts (|d| < 2^24: the whole part fits an int32) */
static void advance(br_refq_t *q, float d)
{
    const float p = q->pos_frac + d;
    const float whole = floorf(p);
    q->pos_counts = (int32_t)((uint32_t)q->pos_counts + (uint32_t)(int32_t)whole);
    q->pos_frac = p - whole;
    if (!(q->pos_frac < 1.0f)) { /* p - floor(p) rounded up to 1 */
        q->pos_frac = 0.0f;
        q->pos_counts = (int32_t)((uint32_t)q->pos_counts + 1u);
    }
}

/* the head item's reference at period tick (its time has come) */
static void item_ref(br_refq_t *q, const br_refq_item_t *it, uint32_t tick, br_ref_t *out)
{
    if (it->kind == BR_REFQ_SETPOINT) {
        out->ref_counts = it->counts;
        out->ref_frac_counts = it->frac;
        out->ref_omega_radps = it->v;
        q->pos_counts = it->counts;
        q->pos_frac = it->frac;
        q->v_cpp = it->v * q->cfg.dt_s / q->cfg.rad_per_count;
        return;
    }
    const float t = (float)(tick - it->tick) * q->cfg.dt_s;
    /* eq. refq-2: the cubic's displacement and velocity at t (Horner) */
    const float d = t * (it->v + t * (0.5f * it->a + t * it->j / 6.0f));
    const float w = it->v + t * (it->a + 0.5f * t * it->j);
    q->pos_counts = it->counts;
    q->pos_frac = it->frac;
    advance(q, d);
    q->v_cpp = w * q->cfg.dt_s;
    out->ref_counts = q->pos_counts;
    out->ref_frac_counts = q->pos_frac;
    out->ref_omega_radps = w * q->cfg.rad_per_count;
}

/* the head leaves the queue */
static void pop(br_refq_t *q)
{
    q->head = (q->head + 1u) % q->cfg.queue_len;
    --q->n;
}

/* one underrun period: hold, then brake at max_accel (eq. refq-3), then the fault */
static br_status_t underrun(br_refq_t *q, br_ref_t *out)
{
    if (q->n_under == 0u) {
        ++q->cnt.underruns;
    }
    if (q->n_under < UINT32_MAX) {
        ++q->n_under;
    }
    if (q->n_under > q->cfg.hold_periods) {
        const float s = fabsf(q->v_cpp) - q->a_cpp2;
        q->v_cpp = s > 0.0f ? copysignf(s, q->v_cpp) : 0.0f;
        q->state = BR_REFQ_BRAKE;
    } else {
        q->state = BR_REFQ_HOLD;
    }
    advance(q, q->v_cpp);
    out_held(q, out);
    if (q->n_under > q->cfg.fault_periods) {
        q->state = BR_REFQ_FAULT;
        return BR_E_FAULT;
    }
    return BR_OK;
}

br_status_t br_refq_step(br_refq_t *q, uint32_t tick, br_ref_t *out)
{
    if (q == NULL || out == NULL) {
        return BR_E_NULL;
    }
    if (!q->ready) {
        return BR_E_STATE;
    }
    /* items over before this period are late: at most the queue's length */
    while (q->n > 0u && (int32_t)(tick - (q->q[q->head].tick + q->q[q->head].periods)) >= 0) {
        pop(q);
        ++q->cnt.late;
    }
    if (q->n > 0u && (int32_t)(tick - q->q[q->head].tick) >= 0) {
        const br_refq_item_t it = q->q[q->head];
        item_ref(q, &it, tick, out);
        q->state = BR_REFQ_STREAM;
        q->n_under = 0u;
        if (tick - it.tick + 1u >= it.periods) {
            pop(q);
            if ((it.flags & BR_REFQ_FLAG_LAST) != 0u) {
                q->state = BR_REFQ_IDLE; /* the end: hold there */
                q->v_cpp = 0.0f;
            }
        }
        return BR_OK;
    }
    if (q->state == BR_REFQ_IDLE) {
        q->v_cpp = 0.0f;
        out_held(q, out);
        return BR_OK;
    }
    return underrun(q, out);
}
