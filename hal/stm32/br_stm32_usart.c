/* SPDX-License-Identifier: Apache-2.0 */
/* The USART byte channel every STM32 port shares (bristle/br_stm32_usart.h).
 * Pure C99 on register-block pointers: it builds for the target and for host
 * tests against fake register blocks. */
#include "bristle/br_stm32_usart.h"

#include <stddef.h>
#include <string.h>

#include "bristle/br_stm32.h"

/* Layout checks against the RM0433 / RM0440 register maps (the
 * USART alike on both; the DMA's first four registers alike, see
 * br_stm32_regs.h). */
BR_STM32_LAYOUT_CHECK(usart_brr, offsetof(br_stm32_usart_t, BRR) == 0x0Cu);
BR_STM32_LAYOUT_CHECK(usart_isr, offsetof(br_stm32_usart_t, ISR) == 0x1Cu);
BR_STM32_LAYOUT_CHECK(usart_rdr, offsetof(br_stm32_usart_t, RDR) == 0x24u);
BR_STM32_LAYOUT_CHECK(usart_presc, offsetof(br_stm32_usart_t, PRESC) == 0x2Cu);
BR_STM32_LAYOUT_CHECK(dma_mar, offsetof(br_stm32_dma_ch_t, MAR) == 0x0Cu);

/* A bus address as the DMA's 32-bit register holds it (on the host, a fake
 * register keeps the low 32 bits: a test compares them the same way). */
static uint32_t bus_addr(const volatile void *p)
{
    return (uint32_t)(uintptr_t)p;
}

/* BRR at oversampling 16: round(kernel / baud), within the tolerance. */
static br_status_t usart_brr(uint32_t kernel_hz, uint32_t baud, uint32_t *brr)
{
    if (kernel_hz == 0u || baud == 0u) {
        return BR_E_PARAM;
    }
    const uint64_t b = ((uint64_t)kernel_hz + baud / 2u) / baud;
    if (b < BR_USART_BRR_MIN || b > BR_USART_BRR_MAX) {
        return BR_E_PARAM;
    }
    /* |kernel / b - baud| <= tol % of baud, multiplied through by b */
    const uint64_t want = b * baud;
    const uint64_t err = (want > kernel_hz) ? want - kernel_hz : kernel_hz - want;
    if (err * 100u > (uint64_t)BR_STM32_USART_BAUD_TOL_PCT * want) {
        return BR_E_PARAM;
    }
    *brr = (uint32_t)b;
    return BR_OK;
}

static br_status_t usart_cfg_check(const br_stm32_usart_cfg_t *c, uint32_t *brr)
{
    if (c->usart == NULL || c->rx_dma == NULL || c->tx_dma == NULL || c->tx_dma_ifcr == NULL ||
        c->rx_buf == NULL || c->tx_buf == NULL) {
        return BR_E_NULL;
    }
    if (c->rx_dma == c->tx_dma || c->rx_len < 2u || c->rx_len > BR_DMA_NDTR_MAX || c->tx_len < 1u ||
        c->tx_len > BR_DMA_NDTR_MAX || c->poll_period_ns == 0u) {
        return BR_E_PARAM;
    }
    if (((c->rx_dma_cr | c->tx_dma_cr) & BR_DMA_CR_EN) != 0u) {
        return BR_E_PARAM; /* the driver starts the streams itself */
    }
    /* 10 bits per byte (8N1); the bytes of one poll period, rounded up */
    const uint64_t per_poll = ((uint64_t)c->baud * c->poll_period_ns + 9999999999u) / 10000000000u;
    if ((uint64_t)c->rx_len < 2u * per_poll) {
        return BR_E_PARAM;
    }
    return usart_brr(c->kernel_clock_hz, c->baud, brr);
}

br_status_t br_stm32_usart_init(br_stm32_usart_chan_t *u, const br_stm32_usart_cfg_t *cfg)
{
    if (u == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    u->ready = 0;
    uint32_t brr = 0u;
    const br_status_t st = usart_cfg_check(cfg, &brr);
    if (st != BR_OK) {
        return st;
    }
    u->cfg = *cfg;
    u->rx_pos = 0u;
    memset(&u->cnt, 0, sizeof u->cnt);
    br_stm32_usart_t *const us = cfg->usart;

    /* everything stopped before it is reprogrammed */
    us->CR1 = 0u;
    cfg->rx_dma->CR = 0u;
    cfg->tx_dma->CR = 0u;
    if (!br_stm32_wait(&cfg->rx_dma->CR, BR_DMA_CR_EN, 0u) || !br_stm32_wait(&cfg->tx_dma->CR, BR_DMA_CR_EN, 0u)) {
        return BR_E_STATE;
    }
    us->PRESC = 0u;
    us->BRR = brr;
    us->CR2 = 0u; /* 1 stop bit */
    us->CR3 = BR_USART_CR3_DMAR | BR_USART_CR3_DMAT;
    us->ICR = BR_USART_ICR_ORECF | BR_USART_ICR_FECF | BR_USART_ICR_NECF;

    /* RX: circular over rx_buf, running from now on */
    cfg->rx_dma->PAR = bus_addr(&us->RDR);
    cfg->rx_dma->MAR = bus_addr(cfg->rx_buf);
    cfg->rx_dma->NDTR = cfg->rx_len;
    cfg->rx_dma->CR = cfg->rx_dma_cr | BR_DMA_CR_EN;
    /* TX: programmed, idle until the first write */
    cfg->tx_dma->PAR = bus_addr(&us->TDR);
    cfg->tx_dma->MAR = bus_addr(cfg->tx_buf);
    cfg->tx_dma->NDTR = 0u;
    cfg->tx_dma->CR = cfg->tx_dma_cr;
    *cfg->tx_dma_ifcr = cfg->tx_dma_ifcr_mask;

    us->CR1 = BR_USART_CR1_UE | BR_USART_CR1_RE | BR_USART_CR1_TE;
    u->ready = 1;
    return BR_OK;
}

/* the line's error flags: counted, then cleared */
static void usart_errors(br_stm32_usart_chan_t *u)
{
    br_stm32_usart_t *const us = u->cfg.usart;
    const uint32_t isr = us->ISR;

    if ((isr & BR_USART_ISR_ORE) != 0u) {
        u->cnt.rx_overruns++;
        us->ICR = BR_USART_ICR_ORECF;
    }
    if ((isr & (BR_USART_ISR_FE | BR_USART_ISR_NE)) != 0u) {
        u->cnt.rx_errors++;
        us->ICR = BR_USART_ICR_FECF | BR_USART_ICR_NECF;
    }
}

size_t br_stm32_usart_read(br_stm32_usart_chan_t *u, uint8_t *buf, size_t n)
{
    if (u == NULL || buf == NULL || !u->ready) {
        return 0u;
    }
    usart_errors(u);
    const uint32_t len = u->cfg.rx_len;
    const uint32_t left = u->cfg.rx_dma->NDTR;
    if (left == 0u || left > len) {
        return 0u; /* not a count a running circular stream shows */
    }
    /* the DMA's write position; the bytes from the read position up to it */
    const uint32_t wr = len - left;
    const uint32_t avail = (wr >= u->rx_pos) ? wr - u->rx_pos : len - u->rx_pos + wr;
    const uint32_t take = (n < (size_t)avail) ? (uint32_t)n : avail;
    uint32_t first = len - u->rx_pos; /* up to the buffer's end, then from its start */
    if (first > take) {
        first = take;
    }
    memcpy(buf, &u->cfg.rx_buf[u->rx_pos], first);
    memcpy(&buf[first], u->cfg.rx_buf, take - first);
    u->rx_pos = (u->rx_pos + take) % len;
    u->cnt.rx_bytes += take;
    return take;
}

size_t br_stm32_usart_write(br_stm32_usart_chan_t *u, const uint8_t *buf, size_t n)
{
    if (u == NULL || buf == NULL || !u->ready || n == 0u) {
        return 0u;
    }
    br_stm32_dma_ch_t *const d = u->cfg.tx_dma;
    /* a transfer running: EN set and items left (the H7 clears EN at the
     * end, the G4 leaves it set with NDTR 0) */
    if ((d->CR & BR_DMA_CR_EN) != 0u && d->NDTR != 0u) {
        u->cnt.tx_busy++;
        return 0u;
    }
    const uint32_t take = (n < (size_t)u->cfg.tx_len) ? (uint32_t)n : u->cfg.tx_len;
    if ((size_t)take < n) {
        u->cnt.tx_short++;
    }
    memcpy(u->cfg.tx_buf, buf, take);
    d->CR = u->cfg.tx_dma_cr; /* EN clear: NDTR and MAR writable */
    *u->cfg.tx_dma_ifcr = u->cfg.tx_dma_ifcr_mask;
    d->MAR = bus_addr(u->cfg.tx_buf);
    d->NDTR = take;
    d->CR = u->cfg.tx_dma_cr | BR_DMA_CR_EN;
    u->cnt.tx_bytes += take;
    return take;
}

static size_t usart_chan_read(void *ctx, uint8_t *buf, size_t n)
{
    return br_stm32_usart_read((br_stm32_usart_chan_t *)ctx, buf, n);
}

static size_t usart_chan_write(void *ctx, const uint8_t *buf, size_t n)
{
    return br_stm32_usart_write((br_stm32_usart_chan_t *)ctx, buf, n);
}

br_status_t br_stm32_usart_chan(br_stm32_usart_chan_t *u, br_byte_chan_t *chan)
{
    if (u == NULL || chan == NULL) {
        return BR_E_NULL;
    }
    if (!u->ready) {
        return BR_E_STATE;
    }
    chan->ctx = u;
    chan->read = usart_chan_read;
    chan->write = usart_chan_write;
    return BR_OK;
}
