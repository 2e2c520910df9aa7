/* HAL port for the STM32H743 (Cortex-M7): quadrature encoder on a timer in
 * encoder mode, H-bridge PWM on an advanced timer (centre-aligned), and the
 * control tick from SysTick, polled through COUNTFLAG (no interrupt).
 *
 * The port never names a fixed address: the configuration carries pointers to
 * the register blocks, so the same code runs on the target (real addresses,
 * see br_stm32h7_regs.h) and in host tests (fake register blocks in RAM).
 *
 * Encoder: the timer counts in encoder mode 3 (SMCR.SMS = 0b011, both edges
 * of TI1 and TI2, x4). The port extends the counter to a free-running int32
 * (wraps modulo 2^32) by accumulating wrap-safe deltas of the raw counter, so
 * a 16-bit timer works as well as the 32-bit TIM2: the encoder must be read
 * at least once per half counter range of motion (32768 counts for 16 bits).
 *
 * PWM: sign-magnitude on two complementary half-bridge legs. Channel 1 drives
 * leg A, channel 2 leg B, each with its complementary output (CHxN) and the
 * BDTR dead time. duty >= 0: CCR1 = round(duty ARR), CCR2 = 0; duty < 0:
 * CCR1 = 0, CCR2 = round(|duty| ARR). A leg at CCR = 0 holds its low-side
 * switch on, so duty 0 brakes the motor terminals to the same potential.
 * |duty| > 1 is clamped to 1; a non-finite duty gives BR_E_INPUT and duty 0.
 *
 * Tick: SysTick runs from the processor clock with reload
 * cpu_clock_hz / control_hz - 1; tick_wait polls CTRL.COUNTFLAG (cleared by
 * the read). A flag already set when tick_wait is entered means the previous
 * period overran; it is counted in br_stm32h7_t.overruns.
 * See docs/modules/hal.md. */
#ifndef BR_STM32H7_H
#define BR_STM32H7_H

#include <stdint.h>
#include "bristle/br_hal.h"
#include "bristle/br_status.h"
#include "bristle/br_stm32h7_regs.h"

#define BR_STM32H7_PWM_MIN_STEPS    100u      /* ARR >= 100: duty resolution <= 1 % */
#define BR_STM32H7_PWM_ARR_MAX      0xFFFFu   /* TIM1 is a 16-bit timer */
#define BR_STM32H7_TICK_MIN_CYCLES  1000u     /* processor cycles per control tick, minimum */
#define BR_STM32H7_DEADTIME_MAX     127u      /* BDTR.DTG with DTG[7] = 0: DT = DTG t_CK */
#define BR_STM32H7_ENC_FILTER_MAX   15u

/* Extension of an n-bit hardware counter (2 <= n <= 32) to a free-running
 * 32-bit count: each update adds the raw difference read as a signed n-bit
 * value. Correct while the counter moves less than 2^(n-1) between updates. */
typedef struct {
    uint32_t mask;      /* 2^n - 1 */
    uint32_t half;      /* 2^(n-1): sign bit of an n-bit difference */
    uint32_t last_raw;  /* raw counter at the previous update */
    uint32_t ext;       /* extended count modulo 2^32 */
} br_stm32h7_count_ext_t;

br_status_t br_stm32h7_count_ext_init(br_stm32h7_count_ext_t *e, uint32_t counter_bits, uint32_t raw);

/* Folds in a new raw reading (bits above n are ignored); returns the extended
 * count as int32 (two's complement of ext). */
int32_t br_stm32h7_count_ext_update(br_stm32h7_count_ext_t *e, uint32_t raw);

typedef struct {
    br_stm32h7_tim_t *pwm_tim;      /* advanced timer driving the H-bridge (TIM1) */
    br_stm32h7_tim_t *enc_tim;      /* timer in encoder mode (TIM2) */
    br_stm32h7_systick_t *systick;  /* SysTick (0xE000E010) */
    uint32_t cpu_clock_hz;          /* SysTick source = processor clock, > 0 */
    uint32_t tim_clock_hz;          /* kernel clock of pwm_tim, > 0 */
    uint32_t pwm_hz;                /* PWM (switching) frequency, > 0 */
    uint32_t control_hz;            /* control rate; must divide cpu_clock_hz */
    uint32_t enc_counter_bits;      /* 32 (TIM2, TIM5) or 16 (other timers) */
    uint32_t enc_filter;            /* IC1F/IC2F input filter code, 0..15 */
    uint32_t deadtime_ticks;        /* dead time in tim_clock ticks, 0..127 */
} br_stm32h7_cfg_t;

typedef struct {
    br_stm32h7_cfg_t cfg;
    br_stm32h7_count_ext_t enc;
    uint32_t pwm_psc;       /* TIM1 prescaler value (PSC register) */
    uint32_t pwm_arr;       /* TIM1 ARR: duty 1 <-> CCR = ARR */
    uint32_t tick_reload;   /* SysTick LOAD */
    uint32_t next_tick;     /* index returned by the next tick_wait */
    uint32_t overruns;      /* ticks that had already elapsed on entry to tick_wait */
    int ready;
} br_stm32h7_t;

/* Validates cfg (pointers, clocks, ranges) before touching any register, then
 * programs the encoder timer, the PWM timer (duty 0, outputs enabled) and
 * SysTick. The timer clocks must already be enabled (br_stm32h7_rcc_enable). */
br_status_t br_stm32h7_init(br_stm32h7_t *port, const br_stm32h7_cfg_t *cfg);

/* Fills a br_hal_t whose ctx is port. */
br_status_t br_stm32h7_hal(br_stm32h7_t *port, br_hal_t *hal);

br_status_t br_stm32h7_encoder_read(br_stm32h7_t *port, int32_t *counts);
br_status_t br_stm32h7_pwm_write(br_stm32h7_t *port, float duty);

/* Safe stop: duty 0 and main output disable (BDTR.MOE = 0, outputs idle). */
br_status_t br_stm32h7_pwm_disable(br_stm32h7_t *port);

/* Polls COUNTFLAG for at most LOAD + 1 reads (longer than one period at any
 * poll speed); BR_E_STATE if SysTick never wraps. *tick = 0, 1, 2, ... */
br_status_t br_stm32h7_tick_wait(br_stm32h7_t *port, uint32_t *tick);

/* Board helpers (used by the image): clock enables for GPIOA, GPIOB, TIM1,
 * TIM2, and a pin to alternate function af (high speed, no pull). */
br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc);
br_status_t br_stm32h7_gpio_af(br_stm32h7_gpio_t *gpio, uint32_t pin, uint32_t af);

#endif
