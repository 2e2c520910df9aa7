/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's messages (bristle/br_link_pil.h). */
#include "bristle/br_link_pil.h"

#include <stddef.h>

#include "br_le.h"

void br_link_pil_tick_pack(uint8_t *p, const br_link_pil_tick_t *t)
{
    br_le_put(&p[BR_LINK_MSG_PIL_TICK_OFF_TICK], t->tick, 4u);
    br_le_put(&p[BR_LINK_MSG_PIL_TICK_OFF_COUNTS], (uint32_t)t->counts, 4u);
    br_le_put(&p[BR_LINK_MSG_PIL_TICK_OFF_LINK_BYTES], t->link_bytes, 4u);
}

void br_link_pil_out_pack(uint8_t *p, const br_link_pil_out_t *o)
{
    br_le_put_f32(&p[BR_LINK_MSG_PIL_OUT_OFF_PORT_DUTY], o->port_duty);
    p[BR_LINK_MSG_PIL_OUT_OFF_ON] = o->on;
    br_rec_sample_pack(&o->s, &p[BR_LINK_MSG_PIL_OUT_OFF_TICK]);
}

void br_link_setpoint_pack(uint8_t *p, const br_refq_item_t *sp)
{
    br_le_put(&p[BR_LINK_MSG_SETPOINT_OFF_TICK], sp->tick, 4u);
    br_le_put(&p[BR_LINK_MSG_SETPOINT_OFF_COUNTS], (uint32_t)sp->counts, 4u);
    br_le_put_f32(&p[BR_LINK_MSG_SETPOINT_OFF_FRAC], sp->frac);
    br_le_put_f32(&p[BR_LINK_MSG_SETPOINT_OFF_OMEGA_RADPS], sp->v);
    p[BR_LINK_MSG_SETPOINT_OFF_FLAGS] = sp->flags;
}

br_status_t br_link_pil_tick_unpack(const br_link_frame_t *f, br_link_pil_tick_t *t)
{
    if (f == NULL || t == NULL) {
        return BR_E_NULL;
    }
    if (f->id != BR_LINK_MSG_PIL_TICK || f->len != BR_LINK_MSG_PIL_TICK_LEN) {
        return BR_E_INPUT;
    }
    t->tick = br_le_get(&f->payload[BR_LINK_MSG_PIL_TICK_OFF_TICK], 4u);
    t->counts = (int32_t)br_le_get(&f->payload[BR_LINK_MSG_PIL_TICK_OFF_COUNTS], 4u);
    t->link_bytes = br_le_get(&f->payload[BR_LINK_MSG_PIL_TICK_OFF_LINK_BYTES], 4u);
    return BR_OK;
}

br_status_t br_link_pil_out_unpack(const br_link_frame_t *f, br_link_pil_out_t *o)
{
    if (f == NULL || o == NULL) {
        return BR_E_NULL;
    }
    if (f->id != BR_LINK_MSG_PIL_OUT || f->len != BR_LINK_MSG_PIL_OUT_LEN) {
        return BR_E_INPUT;
    }
    o->port_duty = br_le_get_f32(&f->payload[BR_LINK_MSG_PIL_OUT_OFF_PORT_DUTY]);
    o->on = f->payload[BR_LINK_MSG_PIL_OUT_OFF_ON];
    br_rec_sample_unpack(&f->payload[BR_LINK_MSG_PIL_OUT_OFF_TICK], &o->s);
    return BR_OK;
}
