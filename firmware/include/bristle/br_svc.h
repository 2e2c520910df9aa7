/* SPDX-License-Identifier: Apache-2.0 */
/* The command service: the link bound to one application (docs/link.md,
 * "The command service"; docs/modules/svc.md). One br_svc_step per control
 * period, after the tick, in place of br_app_step: it takes a request from
 * the link (arm, disarm, fault reset, a parameter, a setpoint or a segment),
 * and after a setpoint or segment the next one, up to BR_SVC_REQUESTS_MAX a
 * period within the link's K bytes (so a setpoint stream, one item a period,
 * refills the queue after a host's gap; at most one request of another kind
 * a period), reads the enable input, makes the period's reference
 * (br_refq), runs br_app_step with it and queues the reports (hello_reply
 * to a hello: the protocol and firmware versions, the machine's name) (status
 * periodically and on a change, fault once when one latches, ref_status with
 * the periodic status). Never waits: the link's work is bounded
 * (br_link_step), the rest is a fixed amount per period.
 *
 * The application starts disarmed (br_app_init: duty 0, outputs off) and
 * moves only when armed: by an arm request, or by the enable input's rising
 * edge. While an enable input is given, an arm needs it high and its falling
 * edge disarms. A fault that latched must be reset (fault_reset) before an
 * arm is accepted.
 *
 * Parameters: the estimator's configuration is const (in flash); the service
 * keeps a RAM copy (pend) that writes change, and puts it into the filter's
 * own configuration at the arm (the filter re-initialises from it there,
 * br_est_restart), the safe point. A live parameter (read every period) goes
 * into the filter at once. A write of another parameter while armed is
 * refused (BR_E_STATE). */
#ifndef BR_SVC_H
#define BR_SVC_H

#include <stdint.h>

#include "bristle/br_app.h"
#include "bristle/br_link.h"
#include "bristle/br_refq.h"

/* the most requests a period: the first, then more only after a setpoint or segment */
#define BR_SVC_REQUESTS_MAX 2u

/* The enable input, br_hal_t's style (optional): 1 high, 0 low; never waits. */
typedef int (*br_svc_enable_fn)(void *ctx);

typedef struct {
    size_t rx_budget_bytes;   /* br_link_cfg_t's budgets */
    size_t tx_budget_bytes;
    br_refq_cfg_t ref;        /* the reference queue */
    uint32_t status_periods;  /* a status (and ref_status) every so many periods, 1..2^24 */
    br_svc_enable_fn enable;  /* NULL: no enable input (arm by request only) */
    void *enable_ctx;
    const char *machine;      /* the machine's name hello_reply carries (BR_MACHINE_NAME); NULL: empty */
} br_svc_cfg_t;

/* what the service refused or could not send (wraps modulo 2^32) */
typedef struct {
    uint32_t arm_refused;   /* an arm with a fault not reset, the enable low, a failed encoder read or re-initialisation */
    uint32_t arm_failed;    /* the filter refused the parameters at the arm: the last ones it took were put back */
    uint32_t tx_deferred;   /* a report that found the transmit queue full (retried next period) */
} br_svc_counters_t;

typedef struct {
    br_link_t link;
    br_refq_t ref;
    br_app_t *app;
    br_svc_cfg_t cfg;
    br_est_cfg_t *est_live;   /* the filter's own configuration (PF / UKF), NULL without one */
    br_est_cfg_t pend;        /* the RAM copy the writes change */
    br_est_cfg_t good;        /* the copy the filter last initialised from */
    unsigned est_mask;        /* BR_LINK_PARAM_EST_PF / _UKF; 0: no parameters */
    uint32_t tick;            /* the period index (status, fault, the queue's time) */
    uint32_t fault_tick;      /* the period the last fault latched at */
    uint8_t armed;            /* the last period ended armed */
    uint8_t fault;            /* the fault reported (br_app_fault_t; DISARMED after a reset) */
    uint8_t fault_reset;      /* the latched fault was reset: an arm is accepted */
    uint8_t fault_cause;      /* the last fault latched (the fault report's cause) */
    uint8_t send_fault;       /* a fault report waiting for room */
    uint8_t send_status;      /* a status waiting for room (a change) */
    uint8_t send_hello;       /* a hello_reply waiting for room */
    uint32_t hello_session;   /* the session number it answers */
    int enable_last;          /* the enable input last period */
    br_link_cmd_t cmd;        /* the period's last request (kind NONE: none): after br_svc_step, the
                                 caller's to read; the recorder's (REC_ARM, REC_TRIGGER,
                                 REC_DUMP) are not acted on here but by br_rec_command */
    br_svc_counters_t cnt;
    int ready;
} br_svc_t;

/* Binds s to app, initialised and disarmed by br_app_init with app_cfg and
 * mem (the estimator's configuration is read from mem's filter), over chan.
 * BR_E_NULL, BR_E_STATE (app not initialised), BR_E_PARAM (status_periods,
 * the link's budgets, the queue's configuration), br_link_init's or
 * br_refq_init's status. */
br_status_t br_svc_init(br_svc_t *s, const br_svc_cfg_t *cfg, br_app_t *app, const br_app_cfg_t *app_cfg,
                        const br_app_mem_t *mem, const br_byte_chan_t *chan);

/* One control period (above). Returns br_app_step's status (BR_E_FAULT while
 * disarmed or faulted), or BR_E_NULL / BR_E_STATE; a link error (a channel
 * that claimed more bytes than asked) is BR_E_INPUT after the period ran. */
br_status_t br_svc_step(br_svc_t *s);

#endif
