/* SPDX-License-Identifier: Apache-2.0 */
/* One STM32 port test suite across boards (test_stm32_port.c, docs/porting.md
 * "Testing a port on fake registers"): the suite runs the shared driver and
 * the board bring-up over the board's clocks, and each board's file
 * (port_<part>.c) gives its row: the clocks, the register values they give,
 * and the part's own cases (clock enables, clock tree, the USART's DMA side)
 * on fake blocks of the part's register map. The suite is built once per
 * board with that board's file (tests/target/CMakeLists.txt). */
#ifndef PORT_BOARD_H
#define PORT_BOARD_H

#include <stdint.h>

#include "bristle/br_stm32_board.h"

typedef struct {
    const char *name;
    /* the board's clocks (its board/br_board.h) */
    uint32_t cpu_hz;
    uint32_t tim_hz;
    uint32_t deadtime_ticks;  /* 500 ns */
    uint32_t usart_hz;        /* the link's USART kernel clock */
    /* what they give on the registers */
    uint32_t arr_20k;         /* TIM1 ARR at 20 kHz centre-aligned: tim_hz / 40 000 */
    uint32_t ccr_quarter;     /* duty 0.25 rounded to the nearest compare step */
    uint32_t arr_1k;          /* at 1 kHz the prescaler is 1 (PSC = 1) and ARR this */
    uint32_t load_1ms;        /* SysTick LOAD for 1 ms */
    uint32_t load_1500us;     /* for the PF's 1.5 ms */
    uint32_t usart_brr_921600;
    /* inputs at the guards' edges for these clocks */
    uint32_t pwm_hz_100_steps;   /* exactly BR_STM32_PWM_MIN_STEPS: accepted */
    uint32_t pwm_hz_too_fast;    /* fewer steps: refused */
    uint32_t tick_hz_500_cycles; /* a whole tick below BR_STM32_TICK_MIN_CYCLES */
    uint32_t tick_hz_over_2p24;  /* a whole tick above SysTick's 24 bits */
    uint32_t period_ns_over_2p24;
    /* the USART's DMA side over the part's fake DMA blocks (held by the
     * board's file), as a board table's usart_dma does over the real ones */
    br_status_t (*usart_dma)(br_stm32_usart_cfg_t *cfg);
    /* the part's own cases */
    void (*test_rcc_enable)(void **st);
    void (*test_clock_tree)(void **st);
    void (*test_usart_dma)(void **st);
} port_board_t;

extern const port_board_t port_board;

#endif
