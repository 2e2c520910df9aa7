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
    uint32_t control_period_ns;     /* instead of control_hz (then 0) for a period that is no whole
                                       frequency (the PF's 1.5 ms): cpu_clock_hz * period exact in
                                       cycles; 0: control_hz sets the tick */
} br_stm32h7_cfg_t;

typedef struct {
    br_stm32h7_cfg_t cfg;
    br_stm32h7_count_ext_t enc;
    uint32_t pwm_psc;       /* TIM1 prescaler value (PSC register) */
    uint32_t pwm_arr;       /* TIM1 ARR: duty 1 <-> CCR = ARR */
    uint32_t tick_reload;   /* SysTick LOAD */
    uint32_t next_tick;     /* index returned by the next tick_wait */
    uint32_t overruns;      /* ticks that had already elapsed on entry to tick_wait */
    uint32_t overruns_armed;/* overruns at the last pwm_enable: the deadline counts from there */
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

/* Safe stop: duty 0, main output disable (BDTR.MOE = 0, outputs idle) and
 * the channel outputs off (CCER = 0). Init leaves the outputs in this state. */
br_status_t br_stm32h7_pwm_disable(br_stm32h7_t *port);

/* Outputs on at duty 0 (CCER: CC1E, CC1NE, CC2E, CC2NE; BDTR.MOE): the arm
 * (br_app_arm through hal.pwm_enable). Restarts the deadline count. */
br_status_t br_stm32h7_pwm_enable(br_stm32h7_t *port);

/* Deadline: more than max_missed ticks missed (overruns) since the last
 * pwm_enable disables the outputs (br_stm32h7_pwm_disable) and returns
 * BR_E_FAULT; else BR_OK. Called once per period after tick_wait. */
br_status_t br_stm32h7_deadline_check(br_stm32h7_t *port, uint32_t max_missed);

/* Polls COUNTFLAG for at most LOAD + 1 reads (longer than one period at any
 * poll speed); BR_E_STATE if SysTick never wraps. *tick = 0, 1, 2, ... */
br_status_t br_stm32h7_tick_wait(br_stm32h7_t *port, uint32_t *tick);

/* Board helpers (used by the image): clock enables for GPIOA, GPIOB, TIM1,
 * TIM2, and a pin to alternate function af (high speed, no pull). */
br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc);
br_status_t br_stm32h7_gpio_af(br_stm32h7_gpio_t *gpio, uint32_t pin, uint32_t af);

/* Bounded wait for a register condition: polls at most this many times. */
#define BR_STM32H7_WAIT_POLLS 1000000u

/* Clock tree from the reset clock (HSI 64 MHz) to 480 MHz (docs/modules/hal.md,
 * "Clocks"): LDO supply, VOS1 then VOS0 (SYSCFG ODEN), flash 4 wait states
 * (WRHIGHFREQ 2), PLL1 = HSI / 4 * 60 / 2 (ref 16 MHz, VCO 960 MHz), D1CPRE /1,
 * HPRE /2 (AXI/AHB 240 MHz), APB1..4 /2 (120 MHz; timers 240 MHz), then
 * SYSCLK = PLL1. Each wait is bounded (BR_STM32H7_WAIT_POLLS): BR_E_STATE if a
 * ready flag never comes (the system clock is then not switched), BR_E_NULL
 * for a NULL block. */
typedef struct {
    br_stm32h7_rcc_t *rcc;
    br_stm32h7_pwr_t *pwr;
    br_stm32h7_syscfg_t *syscfg;
    br_stm32h7_flash_t *flash;
} br_stm32h7_clock_regs_t;

#define BR_STM32H7_SYSCLK_HZ 480000000u
#define BR_STM32H7_HCLK_HZ   240000000u
#define BR_STM32H7_APB_HZ    120000000u
#define BR_STM32H7_TIMCLK_HZ 240000000u
#define BR_STM32H7_PLL1_DIVM 4u
#define BR_STM32H7_PLL1_DIVN 60u
#define BR_STM32H7_PLL1_DIVP 2u
#define BR_STM32H7_FLASH_WS  4u
#define BR_STM32H7_FLASH_WRHIGHFREQ 2u

br_status_t br_stm32h7_clock_480(const br_stm32h7_clock_regs_t *r);

/* Independent watchdog IWDG1 (LSI 32 kHz): start (0xCCCC), unlock (0x5555),
 * prescaler pr (0..6: /4../256), reload rlr (1..0xFFF), wait SR = 0 (bounded),
 * first refresh (0xAAAA). Timeout = 4 * 2^pr * (rlr + 1) / f_LSI. Once started
 * it cannot be stopped: only a refresh within the timeout avoids a reset.
 * BR_E_NULL, BR_E_PARAM (pr, rlr), BR_E_STATE (SR never cleared). */
br_status_t br_stm32h7_iwdg_start(br_stm32h7_iwdg_t *iwdg, uint32_t pr, uint32_t rlr);

/* Refresh (0xAAAA): call only from a healthy control period. */
void br_stm32h7_iwdg_refresh(br_stm32h7_iwdg_t *iwdg);

#endif
