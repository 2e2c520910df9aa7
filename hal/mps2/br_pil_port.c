/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's HAL port (bristle/br_pil_port.h). */
#include "bristle/br_pil_port.h"

#include <math.h>
#include <stddef.h>

static br_status_t pil_encoder_read(void *ctx, int32_t *counts)
{
    const br_pil_port_t *p = ctx;
    if (counts == NULL) {
        return BR_E_NULL;
    }
    *counts = p->tick.counts;
    return BR_OK;
}

static br_status_t pil_pwm_write(void *ctx, float duty)
{
    br_pil_port_t *p = ctx;
    if (!isfinite(duty)) {
        p->duty = 0.0f;
        return BR_E_INPUT;
    }
    p->duty = fminf(fmaxf(duty, -1.0f), 1.0f);
    return BR_OK;
}

static br_status_t pil_pwm_disable(void *ctx)
{
    br_pil_port_t *p = ctx;
    p->duty = 0.0f;
    p->on = 0u;
    return BR_OK;
}

static br_status_t pil_pwm_enable(void *ctx)
{
    br_pil_port_t *p = ctx;
    p->duty = 0.0f;
    p->on = 1u;
    return BR_OK;
}

/* one received byte of the plant port through the decoder: 1 when it ends a pil_tick */
static int take_byte(br_pil_port_t *p, uint8_t b)
{
    br_link_frame_t f;
    if (!br_link_dec_push(&p->dec, b, &f)) {
        return 0;
    }
    if (br_link_pil_tick_unpack(&f, &p->tick) != BR_OK) {
        ++p->n_unexpected;
        return 0;
    }
    return 1;
}

static br_status_t pil_tick_wait(void *ctx, uint32_t *tick)
{
    br_pil_port_t *p = ctx;
    for (uint32_t i = 0u; i < p->cfg.wait_polls; ++i) {
        br_cmsdk_uart_poll(p->cfg.link);
        uint8_t b;
        /* the plant port's bytes up to the tick's frame (the host sends no more before our answer) */
        while (!p->have_tick && p->cfg.plant_chan.read(p->cfg.plant_chan.ctx, &b, 1u) == 1u) {
            p->have_tick = (uint8_t)take_byte(p, b);
        }
        if (!p->have_tick) {
            continue;
        }
        /* every link byte the host wrote before the tick is in */
        if ((int32_t)(p->cfg.link->cnt.rx_bytes - p->tick.link_bytes) >= 0) {
            ++p->n_ticks;
            p->have_tick = 0u;
            if (tick != NULL) {
                *tick = p->tick.tick;
            }
            return BR_OK;
        }
    }
    return BR_E_STATE;
}

br_status_t br_pil_port_init(br_pil_port_t *p, const br_pil_port_cfg_t *cfg, br_hal_t *hal)
{
    if (p == NULL || cfg == NULL || hal == NULL || cfg->plant == NULL || cfg->link == NULL ||
        cfg->plant_chan.read == NULL || cfg->plant_chan.write == NULL) {
        return BR_E_NULL;
    }
    p->ready = 0;
    if (cfg->wait_polls < 1u) {
        return BR_E_PARAM;
    }
    p->cfg = *cfg;
    br_link_dec_init(&p->dec);
    p->tick = (br_link_pil_tick_t){0u, 0, 0u};
    p->duty = 0.0f;
    p->on = 0u;
    p->have_tick = 0u;
    p->seq = 1u;
    p->n_ticks = p->n_unexpected = p->n_report_short = 0u;
    *hal = (br_hal_t){p, pil_encoder_read, pil_pwm_write, pil_tick_wait, pil_pwm_disable, pil_pwm_enable};
    p->ready = 1;
    return BR_OK;
}

br_status_t br_pil_port_report(br_pil_port_t *p, const br_rec_sample_t *s)
{
    if (p == NULL || s == NULL) {
        return BR_E_NULL;
    }
    const br_link_pil_out_t o = {p->duty, p->on, *s};
    uint8_t pay[BR_LINK_MSG_PIL_OUT_LEN];
    uint8_t frame[BR_LINK_FRAME_MAX];
    size_t n = 0u;
    br_link_pil_out_pack(pay, &o);
    const br_status_t st = br_link_encode(frame, sizeof frame, BR_LINK_MSG_PIL_OUT, p->seq, pay, sizeof pay, &n);
    if (st != BR_OK) {
        return st;
    }
    ++p->seq;
    if (p->cfg.plant_chan.write(p->cfg.plant_chan.ctx, frame, n) != n) {
        ++p->n_report_short;
        return BR_E_BUSY;
    }
    return BR_OK;
}
