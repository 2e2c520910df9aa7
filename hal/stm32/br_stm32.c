/* SPDX-License-Identifier: Apache-2.0 */
/* The shared STM32 driver (bristle/br_stm32.h): encoder, sign-magnitude
 * H-bridge PWM, SysTick tick, deadline, br_hal_t adapters, GPIO alternate
 * functions, IWDG. Pure C99 on register-block pointers: it builds for the
 * target and for host tests against fake register blocks. */
#include "bristle/br_stm32.h"

#include "br_stm32_access.h"

#include <stddef.h>

/* Layout checks against the RM0433 / RM0440 register maps (the same offsets
 * on both). */
BR_STM32_LAYOUT_CHECK(tim_cnt, offsetof(br_stm32_tim_t, CNT) == 0x24u);
BR_STM32_LAYOUT_CHECK(tim_rcr, offsetof(br_stm32_tim_t, RCR) == 0x30u);
BR_STM32_LAYOUT_CHECK(tim_ccr1, offsetof(br_stm32_tim_t, CCR1) == 0x34u);
BR_STM32_LAYOUT_CHECK(tim_bdtr, offsetof(br_stm32_tim_t, BDTR) == 0x44u);
BR_STM32_LAYOUT_CHECK(gpio_afr, offsetof(br_stm32_gpio_t, AFR) == 0x20u);
BR_STM32_LAYOUT_CHECK(systick_val, offsetof(br_stm32_systick_t, VAL) == 0x08u);
BR_STM32_LAYOUT_CHECK(iwdg_sr, offsetof(br_stm32_iwdg_t, SR) == 0x0Cu);
BR_STM32_LAYOUT_CHECK(iwdg_winr, offsetof(br_stm32_iwdg_t, WINR) == 0x10u);

/* ---- configuration ------------------------------------------------------ */

/* Centre-aligned: one PWM period is 2 (PSC + 1) ARR timer-clock ticks. */
static br_status_t br_stm32_pwm_timing(const br_stm32_cfg_t *cfg, uint32_t *psc, uint32_t *arr)
{
    if (cfg->pwm_hz > cfg->tim_clock_hz) {
        return BR_E_PARAM;
    }
    const uint32_t half_period_ticks = (cfg->tim_clock_hz / cfg->pwm_hz) / 2u;
    const uint32_t div = half_period_ticks / (BR_STM32_PWM_ARR_MAX + 1u) + 1u; /* PSC + 1 */
    *psc = div - 1u;
    *arr = half_period_ticks / div;
    if (*arr < BR_STM32_PWM_MIN_STEPS) {
        return BR_E_PARAM; /* PWM frequency too high for the timer clock */
    }
    return BR_OK;
}

static br_status_t br_stm32_cfg_check(const br_stm32_cfg_t *cfg, uint32_t *psc, uint32_t *arr,
                                        uint32_t *reload)
{
    if (cfg->pwm_tim == NULL || cfg->enc_tim == NULL || cfg->systick == NULL) {
        return BR_E_NULL;
    }
    if (cfg->pwm_tim == cfg->enc_tim) {
        return BR_E_PARAM;
    }
    if (cfg->tim_clock_hz == 0u || cfg->pwm_hz == 0u) {
        return BR_E_PARAM;
    }
    if (cfg->enc_counter_bits != 16u && cfg->enc_counter_bits != 32u) {
        return BR_E_PARAM;
    }
    if (cfg->enc_filter > BR_STM32_ENC_FILTER_MAX || cfg->deadtime_ticks > BR_STM32_DEADTIME_MAX) {
        return BR_E_PARAM;
    }
    /* exact tick, exactly one of control_hz and control_period_ns (bristle/br_port.h) */
    uint32_t cycles;
    if (br_tick_cycles(cfg->cpu_clock_hz, cfg->control_hz, cfg->control_period_ns, BR_STM32_TICK_MIN_CYCLES,
                       BR_SYSTICK_LOAD_MAX + 1u, &cycles) != BR_OK) {
        return BR_E_PARAM;
    }
    *reload = cycles - 1u;
    return br_stm32_pwm_timing(cfg, psc, arr);
}

static void br_stm32_enc_setup(br_stm32_tim_t *t, const br_stm32_cfg_t *cfg, uint32_t mask)
{
    t->CR1 = 0u; /* counter stopped while configuring */
    t->SMCR = (t->SMCR & ~BR_TIM_SMCR_SMS_Msk) | BR_TIM_SMCR_SMS_ENC3;
    t->CCMR1 = BR_TIM_CCMR1_CC1S_TI1 | (cfg->enc_filter << BR_TIM_CCMR1_IC1F_Pos) |
               BR_TIM_CCMR1_CC2S_TI2 | (cfg->enc_filter << BR_TIM_CCMR1_IC2F_Pos);
    t->CCER = BR_TIM_CCER_CC1E | BR_TIM_CCER_CC2E; /* both inputs, non-inverted */
    t->PSC = 0u;
    t->ARR = mask; /* full counter range: wraps at 2^n */
    t->CNT = 0u;
    t->EGR = BR_TIM_EGR_UG;
    t->CR1 = BR_TIM_CR1_CEN;
}

static void br_stm32_pwm_setup(br_stm32_tim_t *t, const br_stm32_cfg_t *cfg, uint32_t psc,
                                 uint32_t arr)
{
    t->CR1 = 0u; /* CMS can only be changed with the counter stopped */
    t->PSC = psc;
    t->ARR = arr;
    t->RCR = 0u;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->CCMR1 = (BR_TIM_OCM_PWM1 << BR_TIM_CCMR1_OC1M_Pos) | BR_TIM_CCMR1_OC1PE |
               (BR_TIM_OCM_PWM1 << BR_TIM_CCMR1_OC2M_Pos) | BR_TIM_CCMR1_OC2PE;
    /* outputs off until the arm (br_stm32_pwm_enable): channels and MOE cleared */
    t->CCER = 0u;
    t->BDTR = BR_TIM_BDTR_OSSR | BR_TIM_BDTR_OSSI | (cfg->deadtime_ticks & BR_TIM_BDTR_DTG_Msk);
    t->CR1 = BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE;
    t->EGR = BR_TIM_EGR_UG; /* load PSC, ARR and the CCR preloads */
    t->CR1 = BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE | BR_TIM_CR1_CEN;
}

br_status_t br_stm32_init(br_stm32_t *port, const br_stm32_cfg_t *cfg)
{
    uint32_t psc = 0u;
    uint32_t arr = 0u;
    uint32_t reload = 0u;

    if (port == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    port->ready = 0;
    br_status_t st = br_stm32_cfg_check(cfg, &psc, &arr, &reload);
    if (st != BR_OK) {
        return st;
    }
    port->cfg = *cfg;
    port->pwm_psc = psc;
    port->pwm_arr = arr;
    port->tick_reload = reload;
    port->next_tick = 0u;
    port->overruns = 0u;
    port->overruns_armed = 0u;

    const uint32_t enc_mask = (cfg->enc_counter_bits == 32u) ? 0xFFFFFFFFu : 0xFFFFu;
    br_stm32_enc_setup(cfg->enc_tim, cfg, enc_mask);
    st = br_count_ext_init(&port->enc, cfg->enc_counter_bits, cfg->enc_tim->CNT);
    if (st != BR_OK) {
        return st;
    }

    br_stm32_pwm_setup(cfg->pwm_tim, cfg, psc, arr);

    cfg->systick->CTRL = 0u;
    cfg->systick->LOAD = reload;
    cfg->systick->VAL = 0u; /* clears the counter and COUNTFLAG */
    cfg->systick->CTRL = BR_SYSTICK_CTRL_CLKSOURCE | BR_SYSTICK_CTRL_ENABLE; /* no interrupt */

    port->ready = 1;
    return BR_OK;
}

/* ---- run time ----------------------------------------------------------- */

/* The run-time calls' common check: a port (and an output pointer, where the
 * call has one: out_ok 0 when it is NULL), initialised. */
static br_status_t port_usable(const br_stm32_t *port, int out_ok)
{
    if (port == NULL || !out_ok) {
        return BR_E_NULL;
    }
    return port->ready ? BR_OK : BR_E_STATE;
}

br_status_t br_stm32_encoder_read(br_stm32_t *port, int32_t *counts)
{
    const br_status_t use = port_usable(port, counts != NULL);
    if (use != BR_OK) {
        return use;
    }
    *counts = br_count_ext_update(&port->enc, port->cfg.enc_tim->CNT);
    return BR_OK;
}

br_status_t br_stm32_pwm_write(br_stm32_t *port, float duty)
{
    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    br_stm32_tim_t *const t = port->cfg.pwm_tim;
    /* the core's split: clamp, round, sign to leg A or B; both 0 on a NaN */
    uint32_t ccr_a;
    uint32_t ccr_b;
    const br_status_t st = br_duty_split(duty, port->pwm_arr, &ccr_a, &ccr_b);
    /* Release the idle leg first, then drive the active one. */
    if (ccr_a == 0u) {
        BR_STM32_REG_WRITE(t->CCR1, 0u);
        BR_STM32_REG_WRITE(t->CCR2, ccr_b);
    } else {
        BR_STM32_REG_WRITE(t->CCR2, 0u);
        BR_STM32_REG_WRITE(t->CCR1, ccr_a);
    }
    return st;
}

br_status_t br_stm32_pwm_disable(br_stm32_t *port)
{
    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    br_stm32_tim_t *const t = port->cfg.pwm_tim;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->BDTR &= ~BR_TIM_BDTR_MOE;
    t->CCER = 0u;
    return BR_OK;
}

br_status_t br_stm32_pwm_enable(br_stm32_t *port)
{
    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    br_stm32_tim_t *const t = port->cfg.pwm_tim;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->CCER = BR_TIM_CCER_CC1E | BR_TIM_CCER_CC1NE | BR_TIM_CCER_CC2E | BR_TIM_CCER_CC2NE;
    t->BDTR |= BR_TIM_BDTR_MOE;
    port->overruns_armed = port->overruns;
    return BR_OK;
}

br_status_t br_stm32_deadline_check(br_stm32_t *port, uint32_t max_missed)
{
    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    if (port->overruns - port->overruns_armed > max_missed) {
        (void)br_stm32_pwm_disable(port);
        return BR_E_FAULT;
    }
    return BR_OK;
}

br_status_t br_stm32_tick_wait(br_stm32_t *port, uint32_t *tick)
{
    const br_status_t use = port_usable(port, tick != NULL);
    if (use != BR_OK) {
        return use;
    }
    br_stm32_systick_t *const st = port->cfg.systick;
    int seen = 0;
    if ((st->CTRL & BR_SYSTICK_CTRL_COUNTFLAG) != 0u) {
        port->overruns++; /* the tick came while the last period was still running */
        seen = 1;
    }
    /* Each poll takes more than one processor cycle, so LOAD + 1 polls span
     * more than one period: a missing tick means SysTick is not running. */
    for (uint32_t polls = 0u; !seen && polls <= port->tick_reload; ++polls) {
        if ((st->CTRL & BR_SYSTICK_CTRL_COUNTFLAG) != 0u) {
            seen = 1;
        }
    }
    if (!seen) {
        return BR_E_STATE;
    }
    *tick = port->next_tick;
    port->next_tick++;
    return BR_OK;
}

/* ---- br_hal_t adapters ---------------------------------------------------- */

static br_status_t br_stm32_hal_encoder_read(void *ctx, int32_t *counts)
{
    return br_stm32_encoder_read((br_stm32_t *)ctx, counts);
}

static br_status_t br_stm32_hal_pwm_write(void *ctx, float duty)
{
    return br_stm32_pwm_write((br_stm32_t *)ctx, duty);
}

static br_status_t br_stm32_hal_tick_wait(void *ctx, uint32_t *tick)
{
    return br_stm32_tick_wait((br_stm32_t *)ctx, tick);
}

static br_status_t br_stm32_hal_pwm_disable(void *ctx)
{
    return br_stm32_pwm_disable((br_stm32_t *)ctx);
}

static br_status_t br_stm32_hal_pwm_enable(void *ctx)
{
    return br_stm32_pwm_enable((br_stm32_t *)ctx);
}

br_status_t br_stm32_hal(br_stm32_t *port, br_hal_t *hal)
{
    const br_status_t use = port_usable(port, hal != NULL);
    if (use != BR_OK) {
        return use;
    }
    hal->ctx = port;
    hal->encoder_read = br_stm32_hal_encoder_read;
    hal->pwm_write = br_stm32_hal_pwm_write;
    hal->tick_wait = br_stm32_hal_tick_wait;
    hal->pwm_disable = br_stm32_hal_pwm_disable;
    hal->pwm_enable = br_stm32_hal_pwm_enable;
    return BR_OK;
}

/* ---- pins, waits, watchdog ----------------------------------------------- */

br_status_t br_stm32_gpio_af(br_stm32_gpio_t *gpio, uint32_t pin, uint32_t af)
{
    if (gpio == NULL) {
        return BR_E_NULL;
    }
    if (pin > 15u || af > 15u) {
        return BR_E_PARAM;
    }
    const uint32_t sh2 = 2u * pin;
    const uint32_t idx = pin / 8u;
    const uint32_t sh4 = 4u * (pin % 8u);
    /* AF number first, then the mode, so the pin never outputs another AF. */
    gpio->AFR[idx] = (gpio->AFR[idx] & ~(0xFu << sh4)) | (af << sh4);
    gpio->OSPEEDR = (gpio->OSPEEDR & ~(3u << sh2)) | (BR_GPIO_SPEED_HI << sh2);
    gpio->PUPDR &= ~(3u << sh2);
    gpio->OTYPER &= ~(1u << pin);
    gpio->MODER = (gpio->MODER & ~(3u << sh2)) | (BR_GPIO_MODE_AF << sh2);
    return BR_OK;
}

/* 1 when (*reg & mask) == want within BR_STM32_WAIT_POLLS reads. */
int br_stm32_wait(const volatile uint32_t *reg, uint32_t mask, uint32_t want)
{
    for (uint32_t polls = 0u; polls < BR_STM32_WAIT_POLLS; ++polls) {
        if ((*reg & mask) == want) {
            return 1;
        }
    }
    return 0;
}

br_status_t br_stm32_iwdg_start(br_stm32_iwdg_t *iwdg, uint32_t pr, uint32_t rlr)
{
    if (iwdg == NULL) {
        return BR_E_NULL;
    }
    if (pr > BR_IWDG_PR_MAX || rlr < 1u || rlr > BR_IWDG_RLR_MAX) {
        return BR_E_PARAM;
    }
    iwdg->KR = BR_IWDG_KEY_START;
    iwdg->KR = BR_IWDG_KEY_ACCESS;
    iwdg->PR = pr;
    iwdg->RLR = rlr;
    if (!br_stm32_wait(&iwdg->SR, 0x7u, 0u)) {
        return BR_E_STATE;
    }
    iwdg->KR = BR_IWDG_KEY_REFRESH;
    return BR_OK;
}

void br_stm32_iwdg_refresh(br_stm32_iwdg_t *iwdg)
{
    iwdg->KR = BR_IWDG_KEY_REFRESH;
}
