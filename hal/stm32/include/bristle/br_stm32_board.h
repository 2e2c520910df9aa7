/* SPDX-License-Identifier: Apache-2.0 */
/* A board as a table (docs/porting.md, "Adding a board"): what differs from
 * one STM32 board to the next is data and two part functions (the clock
 * tree, the USART's DMA routing), so the bring-up, the link's USART channel
 * and the watchdog are written once here, over the shared driver
 * (bristle/br_stm32.h, bristle/br_stm32_usart.h). A board's table
 * (hal/<part>/board/) holds the fixed addresses of its part; a host test
 * holds pointers to fake register blocks instead. */
#ifndef BR_STM32_BOARD_H
#define BR_STM32_BOARD_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_status.h"
#include "bristle/br_stm32.h"
#include "bristle/br_stm32_usart.h"

/* the timers' pins: encoder CH1/CH2, PWM CH1/CH2/CH1N/CH2N (and room for
 * a board with more) */
#define BR_STM32_BOARD_PINS_MAX 8u

/* a pin on its alternate function */
typedef struct {
    br_stm32_gpio_t *gpio;
    uint32_t pin;  /* 0..15 */
    uint32_t af;   /* 0..15 */
} br_stm32_pin_t;

typedef struct {
    /* the clock tree from the reset clock, then the clock enables of the
     * timers and of the pins' ports; the first failing status */
    br_status_t (*clocks)(void);
    /* the port: timer blocks, SysTick, clocks, PWM, encoder; the control
     * period is br_stm32_board_init's (control_hz and control_period_ns 0 here) */
    br_stm32_cfg_t port;
    br_stm32_pin_t pins[BR_STM32_BOARD_PINS_MAX];
    uint32_t n_pins;
    /* the link's USART: its clock enables and DMA request routing, filling
     * cfg's DMA fields (the part's br_stm32<part>_usart_dma) */
    br_status_t (*usart_dma)(br_stm32_usart_cfg_t *cfg);
    br_stm32_usart_t *usart;
    uint32_t usart_clock_hz;
    uint32_t baud;
    br_stm32_pin_t usart_pins[2]; /* TX, RX */
    /* the independent watchdog: block, prescaler and reload (br_stm32_iwdg_start) */
    br_stm32_iwdg_t *iwdg;
    uint32_t iwdg_pr;
    uint32_t iwdg_rlr;
    /* 1 when the last reset came from the watchdog; clears the reset flags */
    int (*reset_by_watchdog)(void);
} br_stm32_board_t;

/* Brings the board up: b->clocks, the pins to their timers, then the port
 * (outputs off until the arm; br_stm32_init validates before writing a timer
 * register) at control_period_ns and its br_hal_t. BR_E_NULL for a NULL
 * argument or function, BR_E_PARAM for more than BR_STM32_BOARD_PINS_MAX
 * pins; else the first failing status. */
br_status_t br_stm32_board_init(const br_stm32_board_t *b, uint32_t control_period_ns, br_stm32_t *port,
                                br_hal_t *hal);

/* The link's byte channel: b->usart_dma, the USART's pins, then
 * br_stm32_usart_init over rx (rx_len bytes, circular) and tx (tx_len), both
 * in RAM the DMA reaches, read at least every poll_period_ns. BR_E_NULL for a
 * NULL board or function; else the first failing status. */
br_status_t br_stm32_board_usart_init(const br_stm32_board_t *b, br_stm32_usart_chan_t *u, uint8_t *rx,
                                      uint32_t rx_len, uint8_t *tx, uint32_t tx_len, uint32_t poll_period_ns);

/* Starts the board's watchdog (br_stm32_iwdg_start) / refreshes it. */
br_status_t br_stm32_board_watchdog_start(const br_stm32_board_t *b);
void br_stm32_board_watchdog_refresh(const br_stm32_board_t *b);

#endif
