/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32 driver every STM32 port of bristle shares (docs/porting.md,
 * docs/modules/hal.md): quadrature encoder on a timer in encoder mode 3,
 * sign-magnitude H-bridge PWM on an advanced timer (centre-aligned,
 * complementary outputs with dead time), the control tick from SysTick
 * polled through COUNTFLAG (no interrupt), the deadline, the br_hal_t
 * adapters, pins to alternate functions and the independent watchdog. The
 * registers it writes have the same layout and bits on the STM32H7 and the
 * STM32G4 (br_stm32_regs.h); a part's port (hal/stm32h7, hal/stm32g4) adds
 * its clock tree, its clock enables and its addresses.
 *
 * The driver never names a fixed address: the configuration carries pointers
 * to the register blocks, so the same code runs on the target and in host
 * tests against fake register blocks.
 *
 * Encoder: the timer counts in encoder mode 3 (SMCR.SMS = 0b011, both edges
 * of TI1 and TI2, x4). The counter is extended to a free-running int32 (wraps
 * modulo 2^32) by the core's br_count_ext_t (bristle/br_port.h), so a 16-bit
 * timer works as well as a 32-bit one: read at least once per half counter
 * range of motion (32768 counts for 16 bits).
 *
 * PWM: sign-magnitude on two complementary half-bridge legs. Channel 1 drives
 * leg A, channel 2 leg B, each with its complementary output (CHxN) and the
 * BDTR dead time. duty >= 0: CCR1 = round(duty ARR), CCR2 = 0; duty < 0:
 * CCR1 = 0, CCR2 = round(|duty| ARR) (the core's br_duty_split). A leg at
 * CCR = 0 holds its low-side switch on, so duty 0 brakes the motor terminals
 * to the same potential. |duty| > 1 is clamped to 1; a non-finite duty gives
 * BR_E_INPUT and duty 0.
 *
 * Tick: SysTick runs from the processor clock with reload = cycles - 1, the
 * cycles exact from the core's br_tick_cycles; tick_wait polls CTRL.COUNTFLAG
 * (cleared by the read). A flag already set when tick_wait is entered means
 * the previous period overran; it is counted in br_stm32_t.overruns. */
#ifndef BR_STM32_H
#define BR_STM32_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_port.h"
#include "bristle/br_status.h"
#include "bristle/br_stm32_regs.h"

#define BR_STM32_PWM_MIN_STEPS    100u      /* ARR >= 100: duty resolution <= 1 % */
#define BR_STM32_PWM_ARR_MAX      0xFFFFu   /* TIM1 is a 16-bit timer */
#define BR_STM32_TICK_MIN_CYCLES  1000u     /* processor cycles per control tick, minimum */
#define BR_STM32_DEADTIME_MAX     127u      /* BDTR.DTG with DTG[7] = 0: DT = DTG t_CK */
#define BR_STM32_ENC_FILTER_MAX   15u

typedef struct {
    br_stm32_tim_t *pwm_tim;      /* advanced timer driving the H-bridge (TIM1) */
    br_stm32_tim_t *enc_tim;      /* timer in encoder mode (TIM2) */
    br_stm32_systick_t *systick;  /* SysTick (0xE000E010) */
    uint32_t cpu_clock_hz;          /* SysTick source = processor clock, > 0 */
    uint32_t tim_clock_hz;          /* kernel clock of pwm_tim, > 0 */
    uint32_t pwm_hz;                /* PWM (switching) frequency, > 0 */
    uint32_t control_hz;            /* control rate; must divide cpu_clock_hz */
    uint32_t enc_counter_bits;      /* 32 (TIM2, TIM5) or 16 (other timers) */
    uint32_t enc_filter;            /* IC1F/IC2F input filter code, 0..15 */
    uint32_t deadtime_ticks;        /* dead time in tim_clock ticks, 0..127 */
    uint32_t control_period_ns;     /* instead of control_hz (then 0) for a period that is no whole
                                       frequency (the PF's 1.5 ms): cpu_clock_hz * period exact in
                                       cycles; 0: control_hz sets the tick */
} br_stm32_cfg_t;

typedef struct {
    br_stm32_cfg_t cfg;
    br_count_ext_t enc;     /* the encoder counter extended to int32 (bristle/br_port.h) */
    uint32_t pwm_psc;       /* TIM1 prescaler value (PSC register) */
    uint32_t pwm_arr;       /* TIM1 ARR: duty 1 <-> CCR = ARR */
    uint32_t tick_reload;   /* SysTick LOAD */
    uint32_t next_tick;     /* index returned by the next tick_wait */
    uint32_t overruns;      /* ticks that had already elapsed on entry to tick_wait */
    uint32_t overruns_armed;/* overruns at the last pwm_enable: the deadline counts from there */
    int ready;
} br_stm32_t;

/* Validates cfg (pointers, clocks, ranges) before touching any register, then
 * programs the encoder timer, the PWM timer (duty 0, outputs off) and
 * SysTick. The timer clocks must already be enabled (the port's rcc_enable). */
br_status_t br_stm32_init(br_stm32_t *port, const br_stm32_cfg_t *cfg);

/* Fills a br_hal_t whose ctx is port. */
br_status_t br_stm32_hal(br_stm32_t *port, br_hal_t *hal);

br_status_t br_stm32_encoder_read(br_stm32_t *port, int32_t *counts);
br_status_t br_stm32_pwm_write(br_stm32_t *port, float duty);

/* Safe stop: duty 0, main output disable (BDTR.MOE = 0, outputs idle) and
 * the channel outputs off (CCER = 0). Init leaves the outputs in this state. */
br_status_t br_stm32_pwm_disable(br_stm32_t *port);

/* Outputs on at duty 0 (CCER: CC1E, CC1NE, CC2E, CC2NE; BDTR.MOE): the arm
 * (br_app_arm through hal.pwm_enable). Restarts the deadline count. */
br_status_t br_stm32_pwm_enable(br_stm32_t *port);

/* Deadline: more than max_missed ticks missed (overruns) since the last
 * pwm_enable disables the outputs (br_stm32_pwm_disable) and returns
 * BR_E_FAULT; else BR_OK. Called once per period after tick_wait. */
br_status_t br_stm32_deadline_check(br_stm32_t *port, uint32_t max_missed);

/* Polls COUNTFLAG for at most LOAD + 1 reads (longer than one period at any
 * poll speed); BR_E_STATE if SysTick never wraps. *tick = 0, 1, 2, ... */
br_status_t br_stm32_tick_wait(br_stm32_t *port, uint32_t *tick);

/* A pin to alternate function af (high speed, push-pull, no pull); the AF
 * number is written before the mode. BR_E_NULL, BR_E_PARAM (pin, af > 15). */
br_status_t br_stm32_gpio_af(br_stm32_gpio_t *gpio, uint32_t pin, uint32_t af);

/* Bounded wait for a register condition: 1 when (*reg & mask) == want within
 * BR_STM32_WAIT_POLLS reads, else 0. For the ports' clock trees. */
#define BR_STM32_WAIT_POLLS 1000000u
int br_stm32_wait(const volatile uint32_t *reg, uint32_t mask, uint32_t want);

/* Independent watchdog (LSI 32 kHz): start (0xCCCC), unlock (0x5555),
 * prescaler pr (0..6: /4../256), reload rlr (1..0xFFF), wait SR = 0 (bounded),
 * first refresh (0xAAAA). Timeout = 4 * 2^pr * (rlr + 1) / f_LSI. Once started
 * it cannot be stopped: only a refresh within the timeout avoids a reset.
 * BR_E_NULL, BR_E_PARAM (pr, rlr), BR_E_STATE (SR never cleared). */
br_status_t br_stm32_iwdg_start(br_stm32_iwdg_t *iwdg, uint32_t pr, uint32_t rlr);

/* Refresh (0xAAAA): call only from a healthy control period. */
void br_stm32_iwdg_refresh(br_stm32_iwdg_t *iwdg);

#endif
