/* SPDX-License-Identifier: Apache-2.0 */
/* The Arm CMSDK APB UART (the MPS2 boards' UARTs, which QEMU's mps2-an500
 * models) as the link's byte channel (br_byte_chan_t, bristle/br_link.h;
 * docs/link.md, "The image in the loop"). Polled, no interrupt.
 *
 * The UART holds one byte each way (STATE.RXFULL, STATE.TXFULL), so the
 * driver keeps two rings the caller owns: br_cmsdk_uart_poll moves at most
 * one received byte from DATA into the RX ring (only when the ring has room:
 * a full ring leaves the byte in the UART, so the line's flow control, not
 * the driver, decides what waits) and at most one byte of the TX ring into
 * DATA (only when TXFULL is clear). read() polls once, then copies from the
 * RX ring; write() copies into the TX ring (what fits), then polls once.
 * Neither waits. The caller polls between periods (the image in the loop
 * does while it waits for its tick) to keep both directions moving.
 * An overrun (STATE.RXOVR / TXOVR: a byte lost in the UART) is counted and
 * its flag cleared (write 1). */
#ifndef BR_CMSDK_UART_H
#define BR_CMSDK_UART_H

#include <stddef.h>
#include <stdint.h>

#include "bristle/br_link.h"
#include "bristle/br_status.h"

/* the register block (ARM DDI 0479, CMSDK APB UART) */
typedef struct {
    volatile uint32_t DATA;      /* 0x00 received / to send, bits 7:0 */
    volatile uint32_t STATE;     /* 0x04 bit 0 TX full, 1 RX full, 2 TX overrun, 3 RX overrun (write 1 clears) */
    volatile uint32_t CTRL;      /* 0x08 bit 0 TX enable, 1 RX enable (2-5 interrupts, unused) */
    volatile uint32_t INTSTATUS; /* 0x0C */
    volatile uint32_t BAUDDIV;   /* 0x10 >= 16 */
} br_cmsdk_uart_regs_t;

#define BR_CMSDK_UART_STATE_TXFULL 0x1u
#define BR_CMSDK_UART_STATE_RXFULL 0x2u
#define BR_CMSDK_UART_STATE_TXOVR 0x4u
#define BR_CMSDK_UART_STATE_RXOVR 0x8u
#define BR_CMSDK_UART_CTRL_TXEN 0x1u
#define BR_CMSDK_UART_CTRL_RXEN 0x2u
#define BR_CMSDK_UART_BAUDDIV_MIN 16u

typedef struct {
    br_cmsdk_uart_regs_t *regs;
    uint8_t *rx_buf; /* the RX ring, rx_len bytes (1..65536) */
    uint32_t rx_len;
    uint8_t *tx_buf; /* the TX ring, tx_len bytes (1..65536) */
    uint32_t tx_len;
    uint32_t bauddiv; /* the APB clock / baud, >= 16 */
} br_cmsdk_uart_cfg_t;

typedef struct {
    uint32_t rx_bytes;    /* bytes moved from DATA into the RX ring */
    uint32_t tx_bytes;    /* bytes written to DATA */
    uint32_t rx_overruns; /* STATE.RXOVR seen */
    uint32_t tx_overruns; /* STATE.TXOVR seen */
    uint32_t tx_short;    /* writes that found the TX ring too full for all they offered */
} br_cmsdk_uart_counters_t;

typedef struct {
    br_cmsdk_uart_cfg_t cfg;
    uint32_t rx_head, rx_n; /* the RX ring: oldest byte at rx_head, rx_n bytes */
    uint32_t tx_head, tx_n;
    br_cmsdk_uart_counters_t cnt;
    int ready;
} br_cmsdk_uart_t;

#define BR_CMSDK_UART_RING_MAX 65536u

/* Checks cfg (BR_E_NULL, BR_E_PARAM: a ring of 0 or more than 65536 bytes, a
 * BAUDDIV below 16), sets BAUDDIV, clears the overrun flags, enables TX and
 * RX with the interrupts off, and fills *chan. */
br_status_t br_cmsdk_uart_init(br_cmsdk_uart_t *u, const br_cmsdk_uart_cfg_t *cfg, br_byte_chan_t *chan);

/* At most one byte each way between the UART and the rings (see above). */
void br_cmsdk_uart_poll(br_cmsdk_uart_t *u);

#endif
