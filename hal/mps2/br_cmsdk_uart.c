/* SPDX-License-Identifier: Apache-2.0 */
/* The CMSDK APB UART as a byte channel (bristle/br_cmsdk_uart.h). */
#include "bristle/br_cmsdk_uart.h"

void br_cmsdk_uart_poll(br_cmsdk_uart_t *u)
{
    br_cmsdk_uart_regs_t *r = u->cfg.regs;
    const uint32_t state = r->STATE;
    const uint32_t ovr = state & (BR_CMSDK_UART_STATE_RXOVR | BR_CMSDK_UART_STATE_TXOVR);
    if (ovr != 0u) {
        u->cnt.rx_overruns += (ovr & BR_CMSDK_UART_STATE_RXOVR) != 0u ? 1u : 0u;
        u->cnt.tx_overruns += (ovr & BR_CMSDK_UART_STATE_TXOVR) != 0u ? 1u : 0u;
        r->STATE = ovr; /* write 1 to clear */
    }
    if ((state & BR_CMSDK_UART_STATE_RXFULL) != 0u && u->rx_n < u->cfg.rx_len) {
        u->cfg.rx_buf[(u->rx_head + u->rx_n) % u->cfg.rx_len] = (uint8_t)(r->DATA & 0xFFu);
        ++u->rx_n;
        ++u->cnt.rx_bytes;
    }
    if ((state & BR_CMSDK_UART_STATE_TXFULL) == 0u && u->tx_n > 0u) {
        r->DATA = u->cfg.tx_buf[u->tx_head];
        u->tx_head = (u->tx_head + 1u) % u->cfg.tx_len;
        --u->tx_n;
        ++u->cnt.tx_bytes;
    }
}

static size_t uart_read(void *ctx, uint8_t *buf, size_t n)
{
    br_cmsdk_uart_t *u = ctx;
    br_cmsdk_uart_poll(u);
    size_t k = 0u;
    for (; k < n && u->rx_n > 0u; ++k) {
        buf[k] = u->cfg.rx_buf[u->rx_head];
        u->rx_head = (u->rx_head + 1u) % u->cfg.rx_len;
        --u->rx_n;
    }
    return k;
}

static size_t uart_write(void *ctx, const uint8_t *buf, size_t n)
{
    br_cmsdk_uart_t *u = ctx;
    size_t k = 0u;
    for (; k < n && u->tx_n < u->cfg.tx_len; ++k) {
        u->cfg.tx_buf[(u->tx_head + u->tx_n) % u->cfg.tx_len] = buf[k];
        ++u->tx_n;
    }
    if (k < n) {
        ++u->cnt.tx_short;
    }
    br_cmsdk_uart_poll(u);
    return k;
}

br_status_t br_cmsdk_uart_init(br_cmsdk_uart_t *u, const br_cmsdk_uart_cfg_t *cfg, br_byte_chan_t *chan)
{
    if (u == NULL || cfg == NULL || chan == NULL || cfg->regs == NULL || cfg->rx_buf == NULL || cfg->tx_buf == NULL) {
        return BR_E_NULL;
    }
    u->ready = 0;
    if (cfg->rx_len < 1u || cfg->rx_len > BR_CMSDK_UART_RING_MAX || cfg->tx_len < 1u ||
        cfg->tx_len > BR_CMSDK_UART_RING_MAX || cfg->bauddiv < BR_CMSDK_UART_BAUDDIV_MIN) {
        return BR_E_PARAM;
    }
    u->cfg = *cfg;
    u->rx_head = u->rx_n = u->tx_head = u->tx_n = 0u;
    u->cnt = (br_cmsdk_uart_counters_t){0u, 0u, 0u, 0u, 0u};
    br_cmsdk_uart_regs_t *r = cfg->regs;
    r->CTRL = 0u;
    r->BAUDDIV = cfg->bauddiv;
    r->STATE = BR_CMSDK_UART_STATE_RXOVR | BR_CMSDK_UART_STATE_TXOVR;
    r->CTRL = BR_CMSDK_UART_CTRL_TXEN | BR_CMSDK_UART_CTRL_RXEN;
    *chan = (br_byte_chan_t){u, uart_read, uart_write};
    u->ready = 1;
    return BR_OK;
}
