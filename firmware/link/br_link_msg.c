/* SPDX-License-Identifier: Apache-2.0 */
/* The link's messages: the target's reports packed, the host's requests
 * unpacked, at the offsets of the generated table
 * (bristle_gen/link/br_link_msgs.h; docs/link.md, "Messages"). */
#include "bristle/br_link.h"

#include <string.h>

static void put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (unsigned i = 0u; i < 4u; ++i) {
        p[i] = (uint8_t)((v >> (8u * i)) & 0xFFu);
    }
}

static uint16_t get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/* f32 on the wire: the IEEE 754 binary32 bits as a little-endian u32 */
static void put_f32(uint8_t *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    put_u32(p, u);
}

static float get_f32(const uint8_t *p)
{
    const uint32_t u = get_u32(p);
    float v;
    memcpy(&v, &u, sizeof v);
    return v;
}

br_status_t br_link_send_status(br_link_t *l, const br_link_status_t *s)
{
    if (s == NULL) {
        return BR_E_NULL;
    }
    uint8_t p[BR_LINK_MSG_STATUS_LEN];
    put_u32(&p[BR_LINK_MSG_STATUS_OFF_TICK], s->tick);
    put_u32(&p[BR_LINK_MSG_STATUS_OFF_FAULT_TICK], s->fault_tick);
    p[BR_LINK_MSG_STATUS_OFF_ARMED] = s->armed;
    p[BR_LINK_MSG_STATUS_OFF_FAULT] = s->fault;
    return br_link_send(l, BR_LINK_MSG_STATUS, p, sizeof p);
}

br_status_t br_link_send_fault(br_link_t *l, uint8_t cause, uint32_t tick)
{
    uint8_t p[BR_LINK_MSG_FAULT_LEN];
    p[BR_LINK_MSG_FAULT_OFF_CAUSE] = cause;
    put_u32(&p[BR_LINK_MSG_FAULT_OFF_TICK], tick);
    return br_link_send(l, BR_LINK_MSG_FAULT, p, sizeof p);
}

br_status_t br_link_send_param_value(br_link_t *l, uint16_t param, float value, br_status_t st)
{
    uint8_t p[BR_LINK_MSG_PARAM_VALUE_LEN];
    put_u16(&p[BR_LINK_MSG_PARAM_VALUE_OFF_PARAM], param);
    put_f32(&p[BR_LINK_MSG_PARAM_VALUE_OFF_VALUE], value);
    /* i8: the status codes are -128..127 */
    p[BR_LINK_MSG_PARAM_VALUE_OFF_STATUS] = (uint8_t)(int8_t)st;
    return br_link_send(l, BR_LINK_MSG_PARAM_VALUE, p, sizeof p);
}

br_status_t br_link_send_ref_status(br_link_t *l, const br_link_ref_status_t *s)
{
    if (s == NULL) {
        return BR_E_NULL;
    }
    uint8_t p[BR_LINK_MSG_REF_STATUS_LEN];
    put_u32(&p[BR_LINK_MSG_REF_STATUS_OFF_TICK], s->tick);
    p[BR_LINK_MSG_REF_STATUS_OFF_QUEUED] = s->queued;
    p[BR_LINK_MSG_REF_STATUS_OFF_FREE] = s->free;
    p[BR_LINK_MSG_REF_STATUS_OFF_STATE] = s->state;
    put_u32(&p[BR_LINK_MSG_REF_STATUS_OFF_DROPPED], s->dropped);
    put_u32(&p[BR_LINK_MSG_REF_STATUS_OFF_LATE], s->late);
    put_u32(&p[BR_LINK_MSG_REF_STATUS_OFF_UNDERRUNS], s->underruns);
    return br_link_send(l, BR_LINK_MSG_REF_STATUS, p, sizeof p);
}

br_status_t br_link_send_hello_reply(br_link_t *l, uint32_t session, uint32_t fw_version, const char *machine)
{
    uint8_t p[BR_LINK_MSG_HELLO_REPLY_LEN];
    memset(p, 0, sizeof p);
    put_u32(&p[BR_LINK_MSG_HELLO_REPLY_OFF_SESSION], session);
    p[BR_LINK_MSG_HELLO_REPLY_OFF_VERSION] = (uint8_t)BR_LINK_VERSION;
    put_u32(&p[BR_LINK_MSG_HELLO_REPLY_OFF_FW_VERSION], fw_version);
    /* c16: at most 16 bytes of the name, the rest NUL (bounded by the field) */
    for (size_t i = 0u; machine != NULL && i < BR_LINK_MSG_HELLO_REPLY_LEN - BR_LINK_MSG_HELLO_REPLY_OFF_MACHINE &&
                        machine[i] != '\0';
         ++i) {
        p[BR_LINK_MSG_HELLO_REPLY_OFF_MACHINE + i] = (uint8_t)machine[i];
    }
    return br_link_send(l, BR_LINK_MSG_HELLO_REPLY, p, sizeof p);
}

/* the payloads of setpoint and segment as a queue item */
static void get_setpoint(const uint8_t *p, br_refq_item_t *r)
{
    r->kind = BR_REFQ_SETPOINT;
    r->tick = get_u32(&p[BR_LINK_MSG_SETPOINT_OFF_TICK]);
    r->periods = 1u;
    r->counts = (int32_t)get_u32(&p[BR_LINK_MSG_SETPOINT_OFF_COUNTS]);
    r->frac = get_f32(&p[BR_LINK_MSG_SETPOINT_OFF_FRAC]);
    r->v = get_f32(&p[BR_LINK_MSG_SETPOINT_OFF_OMEGA_RADPS]);
    r->flags = p[BR_LINK_MSG_SETPOINT_OFF_FLAGS];
}

static void get_segment(const uint8_t *p, br_refq_item_t *r)
{
    r->kind = BR_REFQ_SEGMENT;
    r->tick = get_u32(&p[BR_LINK_MSG_SEGMENT_OFF_TICK]);
    r->periods = get_u32(&p[BR_LINK_MSG_SEGMENT_OFF_PERIODS]);
    r->counts = (int32_t)get_u32(&p[BR_LINK_MSG_SEGMENT_OFF_COUNTS]);
    r->frac = get_f32(&p[BR_LINK_MSG_SEGMENT_OFF_FRAC]);
    r->v = get_f32(&p[BR_LINK_MSG_SEGMENT_OFF_V_CPS]);
    r->a = get_f32(&p[BR_LINK_MSG_SEGMENT_OFF_A_CPS2]);
    r->j = get_f32(&p[BR_LINK_MSG_SEGMENT_OFF_J_CPS3]);
    r->flags = p[BR_LINK_MSG_SEGMENT_OFF_FLAGS];
}

int br_link_msg_len(uint8_t id, unsigned direction)
{
#define BR_LINK_MSG_ROW(name, mid, len, dir) \
    if (id == (mid) && direction == (dir)) { \
        return (int)(len); \
    }
    BR_LINK_MSG_TABLE(BR_LINK_MSG_ROW)
#undef BR_LINK_MSG_ROW
    return -1;
}

br_status_t br_link_cmd_decode(const br_link_frame_t *f, br_link_cmd_t *cmd)
{
    if (f == NULL || cmd == NULL) {
        return BR_E_NULL;
    }
    memset(cmd, 0, sizeof *cmd);
    cmd->seq = f->seq;
    br_link_cmd_kind_t kind = BR_LINK_CMD_NONE;
    switch (f->id) {
    case BR_LINK_MSG_HELLO:
        kind = BR_LINK_CMD_HELLO;
        break;
    case BR_LINK_MSG_ARM:
        kind = BR_LINK_CMD_ARM;
        break;
    case BR_LINK_MSG_DISARM:
        kind = BR_LINK_CMD_DISARM;
        break;
    case BR_LINK_MSG_FAULT_RESET:
        kind = BR_LINK_CMD_FAULT_RESET;
        break;
    case BR_LINK_MSG_PARAM_READ:
        kind = BR_LINK_CMD_PARAM_READ;
        break;
    case BR_LINK_MSG_PARAM_WRITE:
        kind = BR_LINK_CMD_PARAM_WRITE;
        break;
    case BR_LINK_MSG_SETPOINT:
        kind = BR_LINK_CMD_SETPOINT;
        break;
    case BR_LINK_MSG_SEGMENT:
        kind = BR_LINK_CMD_SEGMENT;
        break;
    case BR_LINK_MSG_REC_ARM:
        kind = BR_LINK_CMD_REC_ARM;
        break;
    case BR_LINK_MSG_REC_TRIGGER:
        kind = BR_LINK_CMD_REC_TRIGGER;
        break;
    case BR_LINK_MSG_REC_DUMP:
        kind = BR_LINK_CMD_REC_DUMP;
        break;
    default:
        return BR_E_INPUT; /* not a request the target receives */
    }
    if ((int)f->len != br_link_msg_len(f->id, BR_LINK_TO_TARGET)) {
        return BR_E_INPUT;
    }
    if (kind == BR_LINK_CMD_PARAM_READ) {
        cmd->param = get_u16(&f->payload[BR_LINK_MSG_PARAM_READ_OFF_PARAM]);
    } else if (kind == BR_LINK_CMD_PARAM_WRITE) {
        cmd->param = get_u16(&f->payload[BR_LINK_MSG_PARAM_WRITE_OFF_PARAM]);
        cmd->value = get_f32(&f->payload[BR_LINK_MSG_PARAM_WRITE_OFF_VALUE]);
    } else if (kind == BR_LINK_CMD_SETPOINT) {
        get_setpoint(f->payload, &cmd->ref);
    } else if (kind == BR_LINK_CMD_SEGMENT) {
        get_segment(f->payload, &cmd->ref);
    } else if (kind == BR_LINK_CMD_HELLO) {
        cmd->session = get_u32(&f->payload[BR_LINK_MSG_HELLO_OFF_SESSION]);
    } else if (kind == BR_LINK_CMD_REC_DUMP) {
        cmd->first = get_u16(&f->payload[BR_LINK_MSG_REC_DUMP_OFF_FIRST]);
    }
    cmd->kind = kind;
    return BR_OK;
}
