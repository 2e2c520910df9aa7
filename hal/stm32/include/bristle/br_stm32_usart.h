/* SPDX-License-Identifier: Apache-2.0 */
/* A USART as the link's byte channel (br_byte_chan_t, bristle/br_link.h) on
 * every STM32 port (docs/porting.md, "The USART channel"; docs/link.md):
 * 8N1, oversampling 16, both directions by DMA, no interrupt.
 *
 * Receive: a DMA stream/channel in circular mode copies each byte from RDR
 * into rx_buf; the DMA's write position is rx_len - NDTR. read() copies the
 * bytes between the driver's read position and the write position, so it
 * never waits and never touches the USART's data register. rx_len must hold
 * at least twice the bytes the line brings between two reads
 * (poll_period_ns at baud), so that the DMA never laps the reader; init
 * refuses a smaller buffer.
 *
 * Transmit: write() copies up to tx_len bytes into tx_buf and starts one DMA
 * transfer of them (normal mode); while a transfer runs a write takes
 * nothing (returns 0). A write of more than tx_len bytes takes tx_len and
 * says so (returns fewer than offered): the caller keeps the rest (the link
 * keeps it in its transmit queue and offers it at its next step).
 *
 * Errors: an overrun (ISR.ORE: a byte came before the last left RDR) and
 * framing / noise errors are counted at each read and their flags cleared.
 *
 * The DMA registers differ between the parts past their first four
 * (br_stm32_dma_ch_t); the part's port gives the configuration words of the
 * two streams/channels, the register and mask that clear the TX one's flags,
 * and routes the requests (the H7's and G4's DMAMUX). Buffers must be in RAM
 * the DMA reaches (not the H7's DTCM) and not cached (the images leave the
 * D-cache off). */
#ifndef BR_STM32_USART_H
#define BR_STM32_USART_H

#include <stddef.h>
#include <stdint.h>

#include "bristle/br_link.h"
#include "bristle/br_status.h"
#include "bristle/br_stm32_regs.h"

/* 2 % baud-rate error at most (the receiver's tolerance at oversampling 16 is
 * about 3.75 % for both ends together). */
#define BR_STM32_USART_BAUD_TOL_PCT 2u

typedef struct {
    br_stm32_usart_t *usart;
    br_stm32_dma_ch_t *rx_dma;        /* circular: RDR -> rx_buf */
    br_stm32_dma_ch_t *tx_dma;        /* normal: tx_buf -> TDR */
    volatile uint32_t *tx_dma_ifcr;   /* the register clearing the TX stream's/channel's flags */
    uint32_t tx_dma_ifcr_mask;        /* its flags' clear bits there */
    uint32_t rx_dma_cr;               /* the part's CR word for RX: peripheral to memory, circular,
                                         memory increment, bytes; EN clear */
    uint32_t tx_dma_cr;               /* for TX: memory to peripheral, memory increment, bytes; EN clear */
    uint8_t *rx_buf;                  /* the circular buffer, rx_len bytes */
    uint32_t rx_len;                  /* 2..BR_DMA_NDTR_MAX */
    uint8_t *tx_buf;                  /* one transfer's bytes, tx_len */
    uint32_t tx_len;                  /* 1..BR_DMA_NDTR_MAX */
    uint32_t kernel_clock_hz;         /* the USART's kernel clock */
    uint32_t baud;                    /* > 0; BRR = round(kernel / baud) within the tolerance */
    uint32_t poll_period_ns;          /* the longest time between two reads, > 0 */
} br_stm32_usart_cfg_t;

/* what the line and the caller did (each wraps modulo 2^32) */
typedef struct {
    uint32_t rx_bytes;     /* bytes read() returned */
    uint32_t rx_overruns;  /* ISR.ORE seen: at least one byte lost on the line */
    uint32_t rx_errors;    /* ISR.FE or ISR.NE seen: a framing or noise error */
    uint32_t tx_bytes;     /* bytes write() took */
    uint32_t tx_busy;      /* writes that found a transfer running (took nothing) */
    uint32_t tx_short;     /* writes that took fewer bytes than offered (more than tx_len) */
} br_stm32_usart_counters_t;

typedef struct {
    br_stm32_usart_cfg_t cfg;
    uint32_t rx_pos;       /* the next byte read() returns, index in rx_buf */
    br_stm32_usart_counters_t cnt;
    int ready;
} br_stm32_usart_chan_t;

/* Validates cfg before writing any register (BR_E_NULL: a pointer; BR_E_PARAM:
 * a length, a clock, a baud rate whose BRR is out of range or misses it by
 * more than BR_STM32_USART_BAUD_TOL_PCT, rx_len below twice the bytes of
 * poll_period_ns, EN set in a CR word); then stops the USART and both
 * streams, programs the baud rate, starts the RX stream (circular over
 * rx_buf), prepares the TX stream and enables the USART (RE, TE, DMAR, DMAT).
 * BR_E_STATE when a stream does not stop (BR_STM32_WAIT_POLLS). The clocks
 * and the request routing must already be set (the part's port). */
br_status_t br_stm32_usart_init(br_stm32_usart_chan_t *u, const br_stm32_usart_cfg_t *cfg);

/* The received bytes not read yet, up to n, into buf (above); 0 when none, for
 * a NULL argument, before init, or when the stream's count is out of range. */
size_t br_stm32_usart_read(br_stm32_usart_chan_t *u, uint8_t *buf, size_t n);

/* Up to min(n, tx_len) bytes of buf sent by DMA; 0 while a transfer runs, for
 * a NULL argument or before init (above). */
size_t br_stm32_usart_write(br_stm32_usart_chan_t *u, const uint8_t *buf, size_t n);

/* Fills a br_byte_chan_t over u (BR_E_NULL; BR_E_STATE before init). */
br_status_t br_stm32_usart_chan(br_stm32_usart_chan_t *u, br_byte_chan_t *chan);

#endif
