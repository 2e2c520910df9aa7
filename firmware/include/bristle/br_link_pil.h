/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's messages (docs/link.md, "The image in the loop"):
 * pil_tick (host to target: a period's tick and encoder count) and pil_out
 * (target to host: the period's duty), at the offsets of the generated table
 * (bristle_gen/link/br_link_msgs.h), both ways, so that the image and a C
 * host share one codec; and a setpoint request's payload, which a C host
 * sends on the link. They travel on the emulated board's plant port, not on
 * the link: br_link_step drops a pil_tick as an unknown request. */
#ifndef BR_LINK_PIL_H
#define BR_LINK_PIL_H

#include <stdint.h>

#include "bristle/br_link.h"
#include "bristle/br_rec.h"
#include "bristle/br_refq.h"
#include "bristle/br_status.h"

typedef struct {
    uint32_t tick;       /* the host's period index */
    int32_t counts;      /* the period's encoder count */
    uint32_t link_bytes; /* bytes the host wrote on the link since the start, modulo 2^32 */
} br_link_pil_tick_t;

typedef struct {
    float port_duty;    /* what the PWM port holds after the period, [-1, 1]: the amplifier's input */
    uint8_t on;         /* the outputs on */
    br_rec_sample_t s;  /* the period's sample (br_rec_sample_take; tick: the pil_tick's) */
} br_link_pil_out_t;

/* The payloads (BR_LINK_MSG_PIL_TICK_LEN, _PIL_OUT_LEN, _SETPOINT_LEN bytes at p). */
void br_link_pil_tick_pack(uint8_t *p, const br_link_pil_tick_t *t);
void br_link_pil_out_pack(uint8_t *p, const br_link_pil_out_t *o);
void br_link_setpoint_pack(uint8_t *p, const br_refq_item_t *sp);

/* A decoded frame as the message: BR_E_INPUT when its id or length is not
 * that message's (nothing written), BR_E_NULL. */
br_status_t br_link_pil_tick_unpack(const br_link_frame_t *f, br_link_pil_tick_t *t);
br_status_t br_link_pil_out_unpack(const br_link_frame_t *f, br_link_pil_out_t *o);

#endif
