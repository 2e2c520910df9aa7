/* SPDX-License-Identifier: Apache-2.0 */
/* A board's bring-up from its table (bristle/br_stm32_board.h). */
#include "bristle/br_stm32_board.h"

#include <stddef.h>

/* each pin to its alternate function; the first failing status */
static br_status_t pins_af(const br_stm32_pin_t *pins, uint32_t n)
{
    for (uint32_t i = 0u; i < n; ++i) {
        const br_status_t st = br_stm32_gpio_af(pins[i].gpio, pins[i].pin, pins[i].af);
        if (st != BR_OK) {
            return st;
        }
    }
    return BR_OK;
}

br_status_t br_stm32_board_init(const br_stm32_board_t *b, uint32_t control_period_ns, br_stm32_t *port,
                                br_hal_t *hal)
{
    if (b == NULL || b->clocks == NULL || port == NULL || hal == NULL) {
        return BR_E_NULL;
    }
    if (b->n_pins > BR_STM32_BOARD_PINS_MAX) {
        return BR_E_PARAM;
    }
    br_status_t st = b->clocks();
    if (st == BR_OK) {
        st = pins_af(b->pins, b->n_pins);
    }
    if (st == BR_OK) {
        br_stm32_cfg_t cfg = b->port;
        cfg.control_hz = 0u;
        cfg.control_period_ns = control_period_ns;
        st = br_stm32_init(port, &cfg);
    }
    return (st != BR_OK) ? st : br_stm32_hal(port, hal);
}

br_status_t br_stm32_board_usart_init(const br_stm32_board_t *b, br_stm32_usart_chan_t *u, uint8_t *rx,
                                      uint32_t rx_len, uint8_t *tx, uint32_t tx_len, uint32_t poll_period_ns)
{
    if (b == NULL || b->usart_dma == NULL) {
        return BR_E_NULL;
    }
    br_stm32_usart_cfg_t cfg = {
        .usart = b->usart,
        .rx_buf = rx,
        .rx_len = rx_len,
        .tx_buf = tx,
        .tx_len = tx_len,
        .kernel_clock_hz = b->usart_clock_hz,
        .baud = b->baud,
        .poll_period_ns = poll_period_ns,
    };
    br_status_t st = b->usart_dma(&cfg);
    if (st == BR_OK) {
        st = pins_af(b->usart_pins, 2u);
    }
    return (st != BR_OK) ? st : br_stm32_usart_init(u, &cfg);
}

br_status_t br_stm32_board_watchdog_start(const br_stm32_board_t *b)
{
    return (b == NULL) ? BR_E_NULL : br_stm32_iwdg_start(b->iwdg, b->iwdg_pr, b->iwdg_rlr);
}

void br_stm32_board_watchdog_refresh(const br_stm32_board_t *b)
{
    if (b != NULL && b->iwdg != NULL) {
        br_stm32_iwdg_refresh(b->iwdg);
    }
}
