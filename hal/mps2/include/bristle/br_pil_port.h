/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's HAL port (docs/link.md, "The image in the loop"):
 * br_hal_t on a UART of its own, the plant port, with the host's plant
 * behind it. The host sends each period's tick and encoder count (pil_tick);
 * the port answers with the period's output (pil_out: the duty the PWM port
 * holds, the outputs' state, the period's sample).
 *
 * tick_wait is the lockstep: it polls both UARTs (the plant port and the
 * link's) until a pil_tick has come and the link's UART has received every
 * byte the host wrote on the link before it (pil_tick.link_bytes, counted
 * modulo 2^32 against the link UART's rx_bytes); so a period runs when the
 * host says so, never on the image's own clock, and sees the same link bytes
 * whatever the emulator's timing. It gives up after cfg.wait_polls polls
 * (BR_E_STATE: the host is gone). encoder_read returns the tick's count;
 * pwm_write holds the duty (clamped to [-1, 1]; a non-finite one holds 0,
 * BR_E_INPUT, as the simulator's port does); pwm_disable holds 0 with the
 * outputs off, pwm_enable turns them on at 0. br_pil_port_report queues the
 * period's pil_out on the plant port, after the period. */
#ifndef BR_PIL_PORT_H
#define BR_PIL_PORT_H

#include <stdint.h>

#include "bristle/br_cmsdk_uart.h"
#include "bristle/br_hal.h"
#include "bristle/br_link.h"
#include "bristle/br_link_pil.h"
#include "bristle/br_status.h"

typedef struct {
    br_cmsdk_uart_t *plant;  /* the plant port's UART (initialised) */
    br_byte_chan_t plant_chan;
    br_cmsdk_uart_t *link;   /* the link's UART: polled while waiting, its rx_bytes counted */
    uint32_t wait_polls;     /* the longest wait for a tick, in polls, >= 1 */
} br_pil_port_cfg_t;

typedef struct {
    br_pil_port_cfg_t cfg;
    br_link_dec_t dec;       /* the plant port's frames */
    br_link_pil_tick_t tick; /* the last tick */
    float duty;              /* the PWM port's duty */
    uint8_t on;              /* the outputs on */
    uint8_t have_tick;       /* a tick came and waits for its link bytes (kept across a wait that gave up) */
    uint16_t seq;            /* the next pil_out's sequence number */
    uint32_t n_ticks;        /* ticks taken */
    uint32_t n_unexpected;   /* frames on the plant port that were not a pil_tick (dropped) */
    uint32_t n_report_short; /* reports the plant port's TX ring could not take whole */
    int ready;
} br_pil_port_t;

/* Checks cfg (BR_E_NULL; BR_E_PARAM: wait_polls 0), the outputs off, and fills *hal. */
br_status_t br_pil_port_init(br_pil_port_t *p, const br_pil_port_cfg_t *cfg, br_hal_t *hal);

/* The period's pil_out (the port's duty and outputs, and s) queued on the
 * plant port; s->tick is the tick's. BR_E_BUSY when the TX ring could not
 * take the whole frame (counted). */
br_status_t br_pil_port_report(br_pil_port_t *p, const br_rec_sample_t *s);

#endif
