/* SPDX-License-Identifier: Apache-2.0 */
/* One control period's sample: taken from the application after
 * br_app_step, packed at the offsets of the generated message table
 * (bristle/br_rec.h, docs/link.md, "The sample"). */
#include "bristle/br_rec.h"

#include "br_le.h"

/* the ring's slots and the dump's chunks are the tlm_sample payload: the
 * rec_sample payload is its u16 index, then those bytes */
typedef char br_rec_layout_check[(BR_LINK_MSG_REC_SAMPLE_OFF_INDEX == 0u && BR_LINK_MSG_REC_SAMPLE_OFF_TICK == 2u &&
                                  BR_LINK_MSG_REC_SAMPLE_LEN == 2u + BR_REC_SAMPLE_BYTES)
                                     ? 1
                                     : -1];

br_status_t br_rec_sample_take(br_rec_sample_t *s, const br_app_t *app, uint32_t tick, br_status_t st)
{
    if (s == NULL || app == NULL) {
        return BR_E_NULL;
    }
    s->tick = tick;
    s->counts = app->last_counts;
    s->ref_counts = app->lim_counts;
    s->ref_frac = app->lim_frac;
    s->duty = app->last.duty;
    s->F_hat_N = app->F_hat_N;
    /* n_lock <= BR_APP_LOCK_WINDOW_MAX (1024): fits a u16 */
    s->n_outliers = (uint16_t)(app->n_lock > 0xFFFFu ? 0xFFFFu : app->n_lock);
    s->status = (int8_t)st; /* the status codes are -7..1 */
    s->fault = (uint8_t)app->fault;
    s->flags = (uint8_t)((app->ref_limited ? BR_REC_FLAG_REF_LIMITED : 0u) |
                         (app->last.saturated ? BR_REC_FLAG_SATURATED : 0u) |
                         (app->n_stale > 0u ? BR_REC_FLAG_HELD : 0u) |
                         (((unsigned)app->stop & 3u) << BR_REC_FLAG_STOP_SHIFT));
    return BR_OK;
}

void br_rec_sample_pack(const br_rec_sample_t *s, uint8_t out[BR_REC_SAMPLE_BYTES])
{
    br_le_put(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_TICK], s->tick, 4u);
    br_le_put(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_COUNTS], (uint32_t)s->counts, 4u);
    br_le_put(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_REF_COUNTS], (uint32_t)s->ref_counts, 4u);
    br_le_put_f32(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_REF_FRAC], s->ref_frac);
    br_le_put_f32(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_DUTY], s->duty);
    br_le_put_f32(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_F_HAT_N], s->F_hat_N);
    br_le_put(&out[BR_LINK_MSG_TLM_SAMPLE_OFF_N_OUTLIERS], s->n_outliers, 2u);
    out[BR_LINK_MSG_TLM_SAMPLE_OFF_STATUS] = (uint8_t)s->status;
    out[BR_LINK_MSG_TLM_SAMPLE_OFF_FAULT] = s->fault;
    out[BR_LINK_MSG_TLM_SAMPLE_OFF_FLAGS] = s->flags;
}

void br_rec_sample_unpack(const uint8_t in[BR_REC_SAMPLE_BYTES], br_rec_sample_t *s)
{
    s->tick = br_le_get(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_TICK], 4u);
    s->counts = (int32_t)br_le_get(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_COUNTS], 4u);
    s->ref_counts = (int32_t)br_le_get(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_REF_COUNTS], 4u);
    s->ref_frac = br_le_get_f32(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_REF_FRAC]);
    s->duty = br_le_get_f32(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_DUTY]);
    s->F_hat_N = br_le_get_f32(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_F_HAT_N]);
    s->n_outliers = (uint16_t)br_le_get(&in[BR_LINK_MSG_TLM_SAMPLE_OFF_N_OUTLIERS], 2u);
    s->status = (int8_t)in[BR_LINK_MSG_TLM_SAMPLE_OFF_STATUS];
    s->fault = in[BR_LINK_MSG_TLM_SAMPLE_OFF_FAULT];
    s->flags = in[BR_LINK_MSG_TLM_SAMPLE_OFF_FLAGS];
}

float br_rec_following_counts(const br_rec_sample_t *s)
{
    /* the counts' difference modulo 2^32 (both wrap like the encoder), then
     * the fraction against the count's centre, 0.5 */
    const int32_t d = (int32_t)((uint32_t)s->ref_counts - (uint32_t)s->counts);
    return (float)d + (s->ref_frac - 0.5f);
}
