/* SPDX-License-Identifier: Apache-2.0 */
/* The command service (bristle/br_svc.h, docs/modules/svc.md). */
#include "bristle/br_svc.h"

#include <stddef.h>

#include "bristle/br_param.h"
#include "bristle/br_version.h"

/* the firmware version hello_reply carries: major << 16 | minor << 8 | patch */
#define BR_SVC_FW_VERSION (((uint32_t)BR_VERSION_MAJOR << 16) | ((uint32_t)BR_VERSION_MINOR << 8) | (uint32_t)BR_VERSION_PATCH)

/* the link's param_write hook: the machine file's range, the estimators' own
 * check on the RAM copy it would make, and the armed rule */
static br_status_t svc_param_check(void *ctx, uint16_t param, float value)
{
    const br_svc_t *s = ctx;
    br_status_t st = br_param_check(param, s->est_mask, value);
    if (st != BR_OK) {
        return st;
    }
    if (s->app->fault == BR_APP_FAULT_NONE && !br_param_live(param)) {
        return BR_E_STATE;
    }
    br_est_cfg_t cand = s->pend;
    return br_param_set(&cand, param, s->est_mask, value);
}

br_status_t br_svc_init(br_svc_t *s, const br_svc_cfg_t *cfg, br_app_t *app, const br_app_cfg_t *app_cfg,
                        const br_app_mem_t *mem, const br_byte_chan_t *chan)
{
    if (s == NULL || cfg == NULL || app == NULL || app_cfg == NULL || chan == NULL) {
        return BR_E_NULL;
    }
    s->ready = 0;
    if (!app->ready) {
        return BR_E_STATE;
    }
    if (cfg->status_periods < 1u || cfg->status_periods > (1u << 24)) {
        return BR_E_PARAM;
    }
    s->cfg = *cfg;
    s->app = app;
    const br_link_cfg_t lc = {cfg->rx_budget_bytes, cfg->tx_budget_bytes, svc_param_check, s};
    br_status_t st = br_link_init(&s->link, &lc, chan);
    if (st != BR_OK) {
        return st;
    }
    st = br_refq_init(&s->ref, &cfg->ref);
    if (st != BR_OK) {
        return st;
    }
    /* the filter's own configuration: where the parameters go at an arm */
    s->est_live = NULL;
    s->est_mask = 0u;
    if (app_cfg->est == BR_APP_EST_PF && mem != NULL && mem->pf != NULL) {
        s->est_live = &mem->pf->cfg.est;
        s->est_mask = BR_LINK_PARAM_EST_PF;
    } else if (app_cfg->est == BR_APP_EST_UKF && mem != NULL && mem->ukf != NULL) {
        s->est_live = &mem->ukf->cfg.est;
        s->est_mask = BR_LINK_PARAM_EST_UKF;
    }
    if (s->est_live != NULL) {
        s->pend = *s->est_live;
        s->good = *s->est_live;
    }
    s->tick = 0u;
    s->fault_tick = 0u;
    s->armed = 0u;
    s->fault = (uint8_t)app->fault;
    s->fault_reset = 1u; /* DISARMED is no fault to reset */
    s->fault_cause = 0u;
    s->send_fault = 0u;
    s->send_status = 1u; /* the first state */
    s->cmd.kind = BR_LINK_CMD_NONE;
    s->enable_last = cfg->enable != NULL ? (cfg->enable(cfg->enable_ctx) != 0) : 0;
    s->cnt = (br_svc_counters_t){0u, 0u, 0u};
    s->ready = 1;
    return BR_OK;
}

/* An arm (a request, the enable's rising edge): the parameters written since
 * go into the filter, which the arm re-initialises from them. */
static void svc_arm(br_svc_t *s)
{
    br_app_t *app = s->app;
    if (app->fault == BR_APP_FAULT_NONE) {
        return; /* armed already */
    }
    int32_t counts = 0;
    if (!s->fault_reset || (s->cfg.enable != NULL && !s->cfg.enable(s->cfg.enable_ctx)) ||
        app->hal->encoder_read(app->hal->ctx, &counts) != BR_OK) {
        ++s->cnt.arm_refused;
        return;
    }
    if (s->est_live != NULL) {
        *s->est_live = s->pend;
    }
    if (br_app_arm(app) != BR_OK) {
        /* the filter refused them: the ones it last took back, for the next arm */
        if (s->est_live != NULL) {
            *s->est_live = s->good;
            s->pend = s->good;
            ++s->cnt.arm_failed;
        }
        ++s->cnt.arm_refused;
        return;
    }
    s->good = s->pend;
    (void)br_refq_start(&s->ref, counts); /* idle where the axis stands; the queue is kept */
    s->armed = 1u;
    s->fault = (uint8_t)BR_APP_FAULT_NONE;
    s->send_status = 1u;
}

static void svc_disarm(br_svc_t *s)
{
    if (s->app->fault != BR_APP_FAULT_NONE) {
        return; /* off already, or braking from a fault (that keeps its cause) */
    }
    (void)br_app_fault(s->app, BR_APP_FAULT_DISARMED);
    (void)br_refq_clear(&s->ref);
    s->armed = 0u;
    s->fault = (uint8_t)BR_APP_FAULT_DISARMED;
    s->send_status = 1u;
}

/* param_read, and an accepted param_write: the value in force answered */
static void svc_param(br_svc_t *s, const br_link_cmd_t *cmd)
{
    float v = 0.0f;
    br_status_t st = BR_E_INPUT;
    if (s->est_live != NULL) {
        st = BR_OK;
        if (cmd->kind == BR_LINK_CMD_PARAM_WRITE) {
            st = br_param_set(&s->pend, cmd->param, s->est_mask, cmd->value);
            if (st == BR_OK && br_param_live(cmd->param)) {
                /* read every period: into the filter now, and into the copy it last took */
                (void)br_param_set(s->est_live, cmd->param, s->est_mask, cmd->value);
                (void)br_param_set(&s->good, cmd->param, s->est_mask, cmd->value);
            }
        }
        if (st == BR_OK) {
            st = br_param_get(&s->pend, cmd->param, s->est_mask, &v);
        }
    }
    if (BR_FAILED(st) && cmd->kind == BR_LINK_CMD_PARAM_WRITE) {
        v = cmd->value; /* a refused write: the value asked for */
    }
    if (br_link_send_param_value(&s->link, cmd->param, v, st) == BR_E_BUSY) {
        ++s->cnt.tx_deferred;
    }
}

/* queues one report; 1 when it found no room (to retry) */
static int svc_sent(br_svc_t *s, br_status_t st)
{
    if (st == BR_E_BUSY) {
        ++s->cnt.tx_deferred;
        return 1;
    }
    return 0;
}

static void svc_command(br_svc_t *s, const br_link_cmd_t *cmd)
{
    switch (cmd->kind) {
    case BR_LINK_CMD_HELLO:
        /* the link restarted its window at the hello; a reply that finds no room
         * waits for it (svc_reports), answering the newest hello */
        s->hello_session = cmd->session;
        s->send_hello = (uint8_t)svc_sent(s, br_link_send_hello_reply(&s->link, cmd->session, BR_SVC_FW_VERSION,
                                                                      s->cfg.machine));
        break;
    case BR_LINK_CMD_ARM:
        svc_arm(s);
        break;
    case BR_LINK_CMD_DISARM:
        svc_disarm(s);
        break;
    case BR_LINK_CMD_FAULT_RESET:
        if (s->app->fault != BR_APP_FAULT_NONE && !s->fault_reset) {
            s->fault_reset = 1u;
            s->fault = (uint8_t)BR_APP_FAULT_DISARMED;
            s->send_status = 1u;
        }
        break;
    case BR_LINK_CMD_PARAM_READ:
    case BR_LINK_CMD_PARAM_WRITE:
        svc_param(s, cmd);
        break;
    case BR_LINK_CMD_SETPOINT:
    case BR_LINK_CMD_SEGMENT:
        (void)br_refq_push(&s->ref, &cmd->ref); /* a refusal is counted (ref_status) */
        break;
    default:
        break;
    }
}

/* 1 for a request that feeds the reference queue */
static int svc_is_ref(br_link_cmd_kind_t kind)
{
    return kind == BR_LINK_CMD_SETPOINT || kind == BR_LINK_CMD_SEGMENT;
}

/* the enable input: its rising edge arms, low disarms */
static void svc_enable(br_svc_t *s)
{
    if (s->cfg.enable == NULL) {
        return;
    }
    const int e = s->cfg.enable(s->cfg.enable_ctx) != 0;
    if (e && !s->enable_last) {
        svc_arm(s);
    } else if (!e) {
        svc_disarm(s);
    }
    s->enable_last = e;
}

static void svc_reports(br_svc_t *s)
{
    if (s->send_hello) {
        s->send_hello = (uint8_t)svc_sent(
            s, br_link_send_hello_reply(&s->link, s->hello_session, BR_SVC_FW_VERSION, s->cfg.machine));
    }
    if (s->send_fault) {
        s->send_fault = (uint8_t)svc_sent(s, br_link_send_fault(&s->link, s->fault_cause, s->fault_tick));
    }
    const int periodic = (s->tick % s->cfg.status_periods) == 0u;
    if (s->send_status || periodic) {
        const br_link_status_t st = {s->tick, s->fault_tick, s->armed, s->fault};
        s->send_status = (uint8_t)(svc_sent(s, br_link_send_status(&s->link, &st)) && s->send_status);
    }
    if (periodic) {
        const br_refq_t *q = &s->ref;
        const br_link_ref_status_t r = {s->tick, (uint8_t)q->n, (uint8_t)(q->cfg.queue_len - q->n), (uint8_t)q->state,
                                        q->cnt.dropped, q->cnt.late, q->cnt.underruns};
        (void)svc_sent(s, br_link_send_ref_status(&s->link, &r));
    }
}

br_status_t br_svc_step(br_svc_t *s)
{
    if (s == NULL) {
        return BR_E_NULL;
    }
    if (!s->ready) {
        return BR_E_STATE;
    }
    br_status_t lst = br_link_step(&s->link, &s->cmd);
    svc_command(s, &s->cmd);
    /* after a setpoint or segment, the period's next request within its K
     * bytes (up to BR_SVC_REQUESTS_MAX): a stream refills the queue after a
     * host's gap; at most one other request a period */
    for (unsigned n = 1u; n < BR_SVC_REQUESTS_MAX && svc_is_ref(s->cmd.kind); ++n) {
        br_link_cmd_t next;
        if (br_link_next(&s->link, &next) == BR_E_INPUT) {
            lst = BR_E_INPUT;
        }
        if (next.kind == BR_LINK_CMD_NONE) {
            break;
        }
        s->cmd = next;
        svc_command(s, &s->cmd);
    }
    svc_enable(s);
    br_app_t *app = s->app;
    br_ref_t r = {s->ref.pos_counts, s->ref.pos_frac, 0.0f};
    if (s->armed && br_refq_step(&s->ref, s->tick, &r) == BR_E_FAULT) {
        (void)br_app_fault(app, BR_APP_FAULT_REF_UNDERRUN);
    }
    const br_status_t ast = br_app_step(app, &r);
    if (s->armed && app->fault != BR_APP_FAULT_NONE) {
        /* a fault latched in this period: reported once, the stream abandoned */
        s->armed = 0u;
        s->fault = (uint8_t)app->fault;
        s->fault_cause = s->fault;
        s->fault_tick = s->tick;
        s->fault_reset = 0u;
        s->send_fault = 1u;
        s->send_status = 1u;
        (void)br_refq_clear(&s->ref);
    }
    svc_reports(s);
    ++s->tick;
    return lst == BR_E_INPUT ? BR_E_INPUT : ast;
}
