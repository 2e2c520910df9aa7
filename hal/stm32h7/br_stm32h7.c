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
BR_LAYOUT_CHECK(rcc_cfgr, offsetof(br_stm32h7_rcc_t, CFGR) == 0x010u);
BR_LAYOUT_CHECK(rcc_d1cfgr, offsetof(br_stm32h7_rcc_t, D1CFGR) == 0x018u);
BR_LAYOUT_CHECK(rcc_d3cfgr, offsetof(br_stm32h7_rcc_t, D3CFGR) == 0x020u);
BR_LAYOUT_CHECK(rcc_pllckselr, offsetof(br_stm32h7_rcc_t, PLLCKSELR) == 0x028u);
BR_LAYOUT_CHECK(rcc_pll1divr, offsetof(br_stm32h7_rcc_t, PLL1DIVR) == 0x030u);
BR_LAYOUT_CHECK(rcc_rsr, offsetof(br_stm32h7_rcc_t, RSR) == 0x0D0u);
BR_LAYOUT_CHECK(rcc_apb4enr, offsetof(br_stm32h7_rcc_t, APB4ENR) == 0x0F4u);
BR_LAYOUT_CHECK(pwr_cr3, offsetof(br_stm32h7_pwr_t, CR3) == 0x0Cu);
BR_LAYOUT_CHECK(pwr_d3cr, offsetof(br_stm32h7_pwr_t, D3CR) == 0x18u);
BR_LAYOUT_CHECK(syscfg_pwrcr, offsetof(br_stm32h7_syscfg_t, PWRCR) == 0x2Cu);
BR_LAYOUT_CHECK(iwdg_sr, offsetof(br_stm32h7_iwdg_t, SR) == 0x0Cu);
BR_LAYOUT_CHECK(iwdg_winr, offsetof(br_stm32h7_iwdg_t, WINR) == 0x10u);

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
        (cfg->control_hz == 0u) == (cfg->control_period_ns == 0u)) {
        return BR_E_PARAM; /* exactly one of control_hz and control_period_ns */
    }
    if (cfg->enc_counter_bits != 16u && cfg->enc_counter_bits != 32u) {
        return BR_E_PARAM;
    }
    if (cfg->enc_filter > BR_STM32H7_ENC_FILTER_MAX || cfg->deadtime_ticks > BR_STM32H7_DEADTIME_MAX) {
        return BR_E_PARAM;
    }
    /* The tick must be exact (the controller's dt is the nominal period). */
    if (cfg->control_period_ns != 0u) {
        const uint64_t c_ns = (uint64_t)cfg->cpu_clock_hz * (uint64_t)cfg->control_period_ns;
        if (c_ns % 1000000000u != 0u || c_ns / 1000000000u > (uint64_t)UINT32_MAX) {
            return BR_E_PARAM;
        }
        cycles = (uint32_t)(c_ns / 1000000000u);
    } else {
        if (cfg->cpu_clock_hz % cfg->control_hz != 0u) {
            return BR_E_PARAM;
        }
        cycles = cfg->cpu_clock_hz / cfg->control_hz;
    }
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
    /* outputs off until the arm (br_stm32h7_pwm_enable): channels and MOE cleared */
    t->CCER = 0u;
    t->BDTR = BR_TIM_BDTR_OSSR | BR_TIM_BDTR_OSSI | (cfg->deadtime_ticks & BR_TIM_BDTR_DTG_Msk);
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
    port->overruns_armed = 0u;

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

/* The run-time calls' common check: a port (and an output pointer, where the
 * call has one: out_ok 0 when it is NULL), initialised. */
static br_status_t port_usable(const br_stm32h7_t *port, int out_ok)
{
    if (port == NULL || !out_ok) {
        return BR_E_NULL;
    }
    return port->ready ? BR_OK : BR_E_STATE;
}

br_status_t br_stm32h7_encoder_read(br_stm32h7_t *port, int32_t *counts)
{
    const br_status_t use = port_usable(port, counts != NULL);
    if (use != BR_OK) {
        return use;
    }
    *counts = br_stm32h7_count_ext_update(&port->enc, port->cfg.enc_tim->CNT);
    return BR_OK;
}

br_status_t br_stm32h7_pwm_write(br_stm32h7_t *port, float duty)
{
    br_stm32h7_tim_t *t;
    float mag;
    uint32_t ccr;

    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
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

    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    t = port->cfg.pwm_tim;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->BDTR &= ~BR_TIM_BDTR_MOE;
    t->CCER = 0u;
    return BR_OK;
}

br_status_t br_stm32h7_pwm_enable(br_stm32h7_t *port)
{
    br_stm32h7_tim_t *t;

    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    t = port->cfg.pwm_tim;
    t->CCR1 = 0u;
    t->CCR2 = 0u;
    t->CCER = BR_TIM_CCER_CC1E | BR_TIM_CCER_CC1NE | BR_TIM_CCER_CC2E | BR_TIM_CCER_CC2NE;
    t->BDTR |= BR_TIM_BDTR_MOE;
    port->overruns_armed = port->overruns;
    return BR_OK;
}

br_status_t br_stm32h7_deadline_check(br_stm32h7_t *port, uint32_t max_missed)
{
    const br_status_t use = port_usable(port, 1);
    if (use != BR_OK) {
        return use;
    }
    if (port->overruns - port->overruns_armed > max_missed) {
        (void)br_stm32h7_pwm_disable(port);
        return BR_E_FAULT;
    }
    return BR_OK;
}

br_status_t br_stm32h7_tick_wait(br_stm32h7_t *port, uint32_t *tick)
{
    br_stm32h7_systick_t *st;
    uint32_t polls;
    int seen = 0;

    const br_status_t use = port_usable(port, tick != NULL);
    if (use != BR_OK) {
        return use;
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

static br_status_t br_stm32h7_hal_pwm_disable(void *ctx)
{
    return br_stm32h7_pwm_disable((br_stm32h7_t *)ctx);
}

static br_status_t br_stm32h7_hal_pwm_enable(void *ctx)
{
    return br_stm32h7_pwm_enable((br_stm32h7_t *)ctx);
}

br_status_t br_stm32h7_hal(br_stm32h7_t *port, br_hal_t *hal)
{
    const br_status_t use = port_usable(port, hal != NULL);
    if (use != BR_OK) {
        return use;
    }
    hal->ctx = port;
    hal->encoder_read = br_stm32h7_hal_encoder_read;
    hal->pwm_write = br_stm32h7_hal_pwm_write;
    hal->tick_wait = br_stm32h7_hal_tick_wait;
    hal->pwm_disable = br_stm32h7_hal_pwm_disable;
    hal->pwm_enable = br_stm32h7_hal_pwm_enable;
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

/* ---- clocks and watchdog (docs/modules/hal.md, "Clocks", "Watchdog") ------ */

/* 1 when (*reg & mask) == want within BR_STM32H7_WAIT_POLLS reads. */
static int br_stm32h7_wait(const volatile uint32_t *reg, uint32_t mask, uint32_t want)
{
    uint32_t polls;

    for (polls = 0u; polls < BR_STM32H7_WAIT_POLLS; ++polls) {
        if ((*reg & mask) == want) {
            return 1;
        }
    }
    return 0;
}

br_status_t br_stm32h7_clock_480(const br_stm32h7_clock_regs_t *r)
{
    br_stm32h7_rcc_t *rcc;
    br_stm32h7_pwr_t *pwr;
    uint32_t readback;

    if (r == NULL || r->rcc == NULL || r->pwr == NULL || r->syscfg == NULL || r->flash == NULL) {
        return BR_E_NULL;
    }
    rcc = r->rcc;
    pwr = r->pwr;
    /* 1. supply: LDO (the part has no SMPS); the configuration is taken once
     *    after reset, then wait until the voltage levels are ready */
    pwr->CR3 = (pwr->CR3 & ~(BR_PWR_CR3_SCUEN | BR_PWR_CR3_LDOEN | BR_PWR_CR3_BYPASS)) | BR_PWR_CR3_LDOEN;
    if (!br_stm32h7_wait(&pwr->CSR1, BR_PWR_CSR1_ACTVOSRDY, BR_PWR_CSR1_ACTVOSRDY)) {
        return BR_E_STATE;
    }
    /* 2. VOS1, then the overdrive (SYSCFG ODEN) for VOS0 */
    pwr->D3CR = (pwr->D3CR & ~BR_PWR_D3CR_VOS_Msk) | BR_PWR_D3CR_VOS_SCALE1;
    if (!br_stm32h7_wait(&pwr->D3CR, BR_PWR_D3CR_VOSRDY, BR_PWR_D3CR_VOSRDY)) {
        return BR_E_STATE;
    }
    rcc->APB4ENR |= BR_RCC_APB4ENR_SYSCFGEN;
    readback = rcc->APB4ENR;
    (void)readback;
    r->syscfg->PWRCR |= BR_SYSCFG_PWRCR_ODEN;
    if (!br_stm32h7_wait(&pwr->D3CR, BR_PWR_D3CR_VOSRDY, BR_PWR_D3CR_VOSRDY)) {
        return BR_E_STATE;
    }
    /* 3. flash: 4 wait states, programming delay 2, before the clock rises;
     *    read back (the new latency must be in effect) */
    r->flash->ACR = (r->flash->ACR & ~(BR_FLASH_ACR_LATENCY_Msk | BR_FLASH_ACR_WRHIGHFREQ_Msk)) |
                    BR_STM32H7_FLASH_WS | (BR_STM32H7_FLASH_WRHIGHFREQ << BR_FLASH_ACR_WRHIGHFREQ_Pos);
    if (!br_stm32h7_wait(&r->flash->ACR, BR_FLASH_ACR_LATENCY_Msk, BR_STM32H7_FLASH_WS)) {
        return BR_E_STATE;
    }
    /* 4. PLL1 from HSI: DIVM1 = 4 (16 MHz), range 8..16 MHz, wide VCO,
     *    N = 60 (960 MHz), P = 2 (480 MHz), Q = R = 4 and off */
    if (!br_stm32h7_wait(&rcc->CR, BR_RCC_CR_HSIRDY, BR_RCC_CR_HSIRDY)) {
        return BR_E_STATE;
    }
    rcc->PLLCKSELR = (rcc->PLLCKSELR & ~(BR_RCC_PLLCKSELR_PLLSRC_Msk | BR_RCC_PLLCKSELR_DIVM1_Msk)) |
                     (BR_STM32H7_PLL1_DIVM << BR_RCC_PLLCKSELR_DIVM1_Pos);
    rcc->PLLCFGR = (rcc->PLLCFGR & ~(BR_RCC_PLLCFGR_PLL1_Msk | BR_RCC_PLLCFGR_DIVQ1EN | BR_RCC_PLLCFGR_DIVR1EN)) |
                   BR_RCC_PLLCFGR_PLL1RGE_8_16 | BR_RCC_PLLCFGR_DIVP1EN;
    rcc->PLL1DIVR = ((BR_STM32H7_PLL1_DIVN - 1u) << BR_RCC_PLL1DIVR_DIVN1_Pos) |
                    ((BR_STM32H7_PLL1_DIVP - 1u) << BR_RCC_PLL1DIVR_DIVP1_Pos) |
                    (3u << BR_RCC_PLL1DIVR_DIVQ1_Pos) | (3u << BR_RCC_PLL1DIVR_DIVR1_Pos);
    rcc->CR |= BR_RCC_CR_PLL1ON;
    if (!br_stm32h7_wait(&rcc->CR, BR_RCC_CR_PLL1RDY, BR_RCC_CR_PLL1RDY)) {
        return BR_E_STATE;
    }
    /* 5. bus prescalers before the switch: D1CPRE /1, HPRE /2, APB3 /2,
     *    APB1 /2, APB2 /2, APB4 /2; TIMPRE = 0: timers at 2 x APB */
    rcc->D1CFGR = (rcc->D1CFGR & ~BR_RCC_D1CFGR_Msk) | BR_RCC_D1CFGR_D1CPRE_DIV1 | BR_RCC_D1CFGR_HPRE_DIV2 |
                  BR_RCC_D1CFGR_D1PPRE_DIV2;
    rcc->D2CFGR = (rcc->D2CFGR & ~BR_RCC_D2CFGR_Msk) | BR_RCC_D2CFGR_D2PPRE1_DIV2 | BR_RCC_D2CFGR_D2PPRE2_DIV2;
    rcc->D3CFGR = (rcc->D3CFGR & ~BR_RCC_D3CFGR_Msk) | BR_RCC_D3CFGR_D3PPRE_DIV2;
    /* 6. system clock = PLL1 */
    rcc->CFGR = (rcc->CFGR & ~(BR_RCC_CFGR_SW_Msk | BR_RCC_CFGR_TIMPRE)) | BR_RCC_CFGR_SW_PLL1;
    if (!br_stm32h7_wait(&rcc->CFGR, BR_RCC_CFGR_SWS_Msk, BR_RCC_CFGR_SWS_PLL1)) {
        return BR_E_STATE;
    }
    return BR_OK;
}

br_status_t br_stm32h7_iwdg_start(br_stm32h7_iwdg_t *iwdg, uint32_t pr, uint32_t rlr)
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
    if (!br_stm32h7_wait(&iwdg->SR, 0x7u, 0u)) {
        return BR_E_STATE;
    }
    iwdg->KR = BR_IWDG_KEY_REFRESH;
    return BR_OK;
}

void br_stm32h7_iwdg_refresh(br_stm32h7_iwdg_t *iwdg)
{
    iwdg->KR = BR_IWDG_KEY_REFRESH;
}
