/* STM32H743 HAL port: encoder (timer in encoder mode 3), sign-magnitude
 * H-bridge PWM (advanced timer, centre-aligned), SysTick tick polled through
 * COUNTFLAG. Pure C99 on register-block pointers: it builds for the target
 * and for host tests against fake register blocks. See br_stm32h7.h. */
#include "bristle/br_stm32h7.h"

#include <math.h>
#include <stddef.h>

/* Compile-time layout checks against the RM0433 register maps (C99 has no
 * static_assert: a negative array size fails the build). */
#define BR_LAYOUT_CHECK(name, cond) typedef char br_layout_##name[(cond) ? 1 : -1]
BR_LAYOUT_CHECK(tim_cnt, offsetof(br_stm32h7_tim_t, CNT) == 0x24u);
BR_LAYOUT_CHECK(tim_rcr, offsetof(br_stm32h7_tim_t, RCR) == 0x30u);
BR_LAYOUT_CHECK(tim_ccr1, offsetof(br_stm32h7_tim_t, CCR1) == 0x34u);
BR_LAYOUT_CHECK(tim_bdtr, offsetof(br_stm32h7_tim_t, BDTR) == 0x44u);
BR_LAYOUT_CHECK(tim_ccmr3, offsetof(br_stm32h7_tim_t, CCMR3) == 0x54u);
BR_LAYOUT_CHECK(tim_tisel, offsetof(br_stm32h7_tim_t, TISEL) == 0x68u);
BR_LAYOUT_CHECK(rcc_ahb4enr, offsetof(br_stm32h7_rcc_t, AHB4ENR) == 0x0E0u);
BR_LAYOUT_CHECK(rcc_apb1lenr, offsetof(br_stm32h7_rcc_t, APB1LENR) == 0x0E8u);
BR_LAYOUT_CHECK(rcc_apb2enr, offsetof(br_stm32h7_rcc_t, APB2ENR) == 0x0F0u);
BR_LAYOUT_CHECK(gpio_afr, offsetof(br_stm32h7_gpio_t, AFR) == 0x20u);
BR_LAYOUT_CHECK(systick_val, offsetof(br_stm32h7_systick_t, VAL) == 0x08u);

/* uint32 -> int32 two's complement without implementation-defined casts. */
static int32_t br_u32_to_i32(uint32_t u)
{
    return (u <= (uint32_t)INT32_MAX) ? (int32_t)u : -(int32_t)(~u) - 1;
}

br_status_t br_stm32h7_count_ext_init(br_stm32h7_count_ext_t *e, uint32_t counter_bits, uint32_t raw)
{
    if (e == NULL) {
        return BR_E_NULL;
    }
    if (counter_bits < 2u || counter_bits > 32u) {
        return BR_E_PARAM;
    }
    e->mask = (counter_bits == 32u) ? 0xFFFFFFFFu : ((1u << counter_bits) - 1u);
    e->half = 1u << (counter_bits - 1u);
    e->last_raw = raw & e->mask;
    e->ext = e->last_raw;
    return BR_OK;
}

int32_t br_stm32h7_count_ext_update(br_stm32h7_count_ext_t *e, uint32_t raw)
{
    uint32_t now = raw & e->mask;
    uint32_t d = (now - e->last_raw) & e->mask; /* difference modulo 2^n */
    if ((d & e->half) != 0u) {
        d |= ~e->mask;                           /* negative: sign-extend to 32 bits */
    }
    e->last_raw = now;
    e->ext += d;                                 /* modulo 2^32 */
    return br_u32_to_i32(e->ext);
}

/* ---- configuration ------------------------------------------------------ */

/* Centre-aligned: one PWM period is 2 (PSC + 1) ARR timer-clock ticks. */
static br_status_t br_stm32h7_pwm_timing(const br_stm32h7_cfg_t *cfg, uint32_t *psc, uint32_t *arr)
{
    uint32_t half_period_ticks;
    uint32_t div;

    if (cfg->pwm_hz > cfg->tim_clock_hz) {
        return BR_E_PARAM;
    }
    half_period_ticks = (cfg->tim_clock_hz / cfg->pwm_hz) / 2u;
    div = half_period_ticks / (BR_STM32H7_PWM_ARR_MAX + 1u) + 1u; /* PSC + 1 */
    *psc = div - 1u;
    *arr = half_period_ticks / div;
    if (*arr < BR_STM32H7_PWM_MIN_STEPS) {
        return BR_E_PARAM; /* PWM frequency too high for the timer clock */
    }
    return BR_OK;
}

static br_status_t br_stm32h7_cfg_check(const br_stm32h7_cfg_t *cfg, uint32_t *psc, uint32_t *arr,
                                        uint32_t *reload)
{
    uint32_t cycles;

    if (cfg->pwm_tim == NULL || cfg->enc_tim == NULL || cfg->systick == NULL) {
        return BR_E_NULL;
    }
    if (cfg->pwm_tim == cfg->enc_tim) {
        return BR_E_PARAM;
    }
    if (cfg->cpu_clock_hz == 0u || cfg->tim_clock_hz == 0u || cfg->pwm_hz == 0u ||
        cfg->control_hz == 0u) {
        return BR_E_PARAM;
    }
    if (cfg->enc_counter_bits != 16u && cfg->enc_counter_bits != 32u) {
        return BR_E_PARAM;
    }
    if (cfg->enc_filter > BR_STM32H7_ENC_FILTER_MAX || cfg->deadtime_ticks > BR_STM32H7_DEADTIME_MAX) {
        return BR_E_PARAM;
    }
    /* The tick must be exact (the controller's dt is the nominal period). */
    if (cfg->cpu_clock_hz % cfg->control_hz != 0u) {
        return BR_E_PARAM;
    }
    cycles = cfg->cpu_clock_hz / cfg->control_hz;
    if (cycles < BR_STM32H7_TICK_MIN_CYCLES || cycles - 1u > BR_SYSTICK_LOAD_MAX) {
        return BR_E_PARAM;
    }
    *reload = cycles - 1u;
    return br_stm32h7_pwm_timing(cfg, psc, arr);
}

static void br_stm32h7_enc_setup(br_stm32h7_tim_t *t, const br_stm32h7_cfg_t *cfg, uint32_t mask)
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

static void br_stm32h7_pwm_setup(br_stm32h7_tim_t *t, const br_stm32h7_cfg_t *cfg, uint32_t psc,
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
    t->CCER = BR_TIM_CCER_CC1E | BR_TIM_CCER_CC1NE | BR_TIM_CCER_CC2E | BR_TIM_CCER_CC2NE;
    t->BDTR = BR_TIM_BDTR_MOE | BR_TIM_BDTR_OSSR | BR_TIM_BDTR_OSSI |
              (cfg->deadtime_ticks & BR_TIM_BDTR_DTG_Msk);
    t->CR1 = BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE;
    t->EGR = BR_TIM_EGR_UG; /* load PSC, ARR and the CCR preloads */
    t->CR1 = BR_TIM_CR1_CMS_CENTER1 | BR_TIM_CR1_ARPE | BR_TIM_CR1_CEN;
}

br_status_t br_stm32h7_init(br_stm32h7_t *port, const br_stm32h7_cfg_t *cfg)
{
    uint32_t psc = 0u;
    uint32_t arr = 0u;
    uint32_t reload = 0u;
    uint32_t enc_mask;
    br_status_t st;

    if (port == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    port->ready = 0;
    st = br_stm32h7_cfg_check(cfg, &psc, &arr, &reload);
    if (st != BR_OK) {
        return st;
    }
    port->cfg = *cfg;
    port->pwm_psc = psc;
    port->pwm_arr = arr;
    port->tick_reload = reload;
    port->next_tick = 0u;
    port->overruns = 0u;

    enc_mask = (cfg->enc_counter_bits == 32u) ? 0xFFFFFFFFu : 0xFFFFu;
    br_stm32h7_enc_setup(cfg->enc_tim, cfg, enc_mask);
    st = br_stm32h7_count_ext_init(&port->enc, cfg->enc_counter_bits, cfg->enc_tim->CNT);
    if (st != BR_OK) {
        return st;
    }

    br_stm32h7_pwm_setup(cfg->pwm_tim, cfg, psc, arr);

    cfg->systick->CTRL = 0u;
    cfg->systick->LOAD = reload;
    cfg->systick->VAL = 0u; /* clears the counter and COUNTFLAG */
    cfg->systick->CTRL = BR_SYSTICK_CTRL_CLKSOURCE | BR_SYSTICK_CTRL_ENABLE; /* no interrupt */

    port->ready = 1;
    return BR_OK;
}

/* ---- run time ----------------------------------------------------------- */

br_status_t br_stm32h7_encoder_read(br_stm32h7_t *port, int32_t *counts)
{
    if (port == NULL || counts == NULL) {
        return BR_E_NULL;
    }
    if (!port->ready) {
        return BR_E_STATE;
    }
    *counts = br_stm32h7_count_ext_update(&port->enc, port->cfg.enc_tim->CNT);
    return BR_OK;
}

br_status_t br_stm32h7_pwm_write(br_stm32h7_t *port, float duty)
{
    br_stm32h7_tim_t *t;
    float mag;
    uint32_t ccr;

    if (port == NULL) {
        return BR_E_NULL;
    }
    if (!port->ready) {
        return BR_E_STATE;
    }
    t = port->cfg.pwm_tim;
    if (!isfinite(duty)) {
        t->CCR1 = 0u;
        t->CCR2 = 0u;
        return BR_E_INPUT;
    }
    mag = fabsf(duty);
    if (mag > 1.0f) {
        mag = 1.0f;
    }
    /* ARR <= 65535 is exact in float; mag * ARR + 0.5 <= 65535.5. */
    ccr = (uint32_t)(mag * (float)port->pwm_arr + 0.5f);
    if (ccr > port->pwm_arr) {
        ccr = port->pwm_arr;
    }
    /* Release the idle leg first, then drive the active one. */
    if (duty >= 0.0f) {
        t->CCR2 = 0u;
        t->CCR1 = ccr;
    } else {
        t->CCR1 = 0u;
        t->CCR2 = ccr;
    }
    return BR_OK;
}

br_status_t br_stm32h7_pwm_disable(br_stm32h7_t *port)
{
    br_stm32h7_tim_t *t;

    if (port == NULL) {
        return BR_E_NULL;
    }
    if (!port->ready) {
        return BR_E_STATE;
    }
    t = port->cfg.pwm_tim;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->BDTR &= ~BR_TIM_BDTR_MOE;
    return BR_OK;
}

br_status_t br_stm32h7_tick_wait(br_stm32h7_t *port, uint32_t *tick)
{
    br_stm32h7_systick_t *st;
    uint32_t polls;
    int seen = 0;

    if (port == NULL || tick == NULL) {
        return BR_E_NULL;
    }
    if (!port->ready) {
        return BR_E_STATE;
    }
    st = port->cfg.systick;
    if ((st->CTRL & BR_SYSTICK_CTRL_COUNTFLAG) != 0u) {
        port->overruns++; /* the tick came while the last period was still running */
        seen = 1;
    }
    /* Each poll takes more than one processor cycle, so LOAD + 1 polls span
     * more than one period: a missing tick means SysTick is not running. */
    for (polls = 0u; !seen && polls <= port->tick_reload; ++polls) {
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

static br_status_t br_stm32h7_hal_encoder_read(void *ctx, int32_t *counts)
{
    return br_stm32h7_encoder_read((br_stm32h7_t *)ctx, counts);
}

static br_status_t br_stm32h7_hal_pwm_write(void *ctx, float duty)
{
    return br_stm32h7_pwm_write((br_stm32h7_t *)ctx, duty);
}

static br_status_t br_stm32h7_hal_tick_wait(void *ctx, uint32_t *tick)
{
    return br_stm32h7_tick_wait((br_stm32h7_t *)ctx, tick);
}

br_status_t br_stm32h7_hal(br_stm32h7_t *port, br_hal_t *hal)
{
    if (port == NULL || hal == NULL) {
        return BR_E_NULL;
    }
    if (!port->ready) {
        return BR_E_STATE;
    }
    hal->ctx = port;
    hal->encoder_read = br_stm32h7_hal_encoder_read;
    hal->pwm_write = br_stm32h7_hal_pwm_write;
    hal->tick_wait = br_stm32h7_hal_tick_wait;
    return BR_OK;
}

/* ---- board helpers -------------------------------------------------------- */

br_status_t br_stm32h7_rcc_enable(br_stm32h7_rcc_t *rcc)
{
    uint32_t readback;

    if (rcc == NULL) {
        return BR_E_NULL;
    }
    rcc->AHB4ENR |= BR_RCC_AHB4ENR_GPIOAEN | BR_RCC_AHB4ENR_GPIOBEN;
    rcc->APB1LENR |= BR_RCC_APB1LENR_TIM2EN;
    rcc->APB2ENR |= BR_RCC_APB2ENR_TIM1EN;
    /* Read back: the enable takes effect before the first peripheral access. */
    readback = rcc->APB2ENR;
    (void)readback;
    return BR_OK;
}

br_status_t br_stm32h7_gpio_af(br_stm32h7_gpio_t *gpio, uint32_t pin, uint32_t af)
{
    uint32_t sh2;
    uint32_t sh4;
    uint32_t idx;

    if (gpio == NULL) {
        return BR_E_NULL;
    }
    if (pin > 15u || af > 15u) {
        return BR_E_PARAM;
    }
    sh2 = 2u * pin;
    idx = pin / 8u;
    sh4 = 4u * (pin % 8u);
    /* AF number first, then the mode, so the pin never outputs another AF. */
    gpio->AFR[idx] = (gpio->AFR[idx] & ~(0xFu << sh4)) | (af << sh4);
    gpio->OSPEEDR = (gpio->OSPEEDR & ~(3u << sh2)) | (BR_GPIO_SPEED_HI << sh2);
    gpio->PUPDR &= ~(3u << sh2);
    gpio->OTYPER &= ~(1u << pin);
    gpio->MODER = (gpio->MODER & ~(3u << sh2)) | (BR_GPIO_MODE_AF << sh2);
    return BR_OK;
}
