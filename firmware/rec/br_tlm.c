/* SPDX-License-Identifier: Apache-2.0 */
/* Telemetry: the period's sample every N periods, dropped and counted when
 * the link has no room (bristle/br_tlm.h, docs/link.md, "Telemetry"). */
#include "bristle/br_tlm.h"

br_status_t br_tlm_init(br_tlm_t *t, const br_tlm_cfg_t *cfg)
{
    if (t == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    t->ready = 0;
    if (cfg->every_n_periods < 1u) {
        return BR_E_PARAM;
    }
    t->cfg = *cfg;
    /* the first period's sample is due */
    t->k = cfg->every_n_periods - 1u;
    t->n_sent = 0u;
    t->n_dropped = 0u;
    t->ready = 1;
    return BR_OK;
}

br_status_t br_tlm_step(br_tlm_t *t, br_link_t *link, const br_rec_sample_t *s)
{
    if (t == NULL || link == NULL || s == NULL) {
        return BR_E_NULL;
    }
    if (!t->ready) {
        return BR_E_STATE;
    }
    if (++t->k < t->cfg.every_n_periods) {
        return BR_OK;
    }
    t->k = 0u;
    uint8_t p[BR_REC_SAMPLE_BYTES];
    br_rec_sample_pack(s, p);
    /* one send: queued whole, or refused (never waited for) */
    const br_status_t st = br_link_send(link, BR_LINK_MSG_TLM_SAMPLE, p, sizeof p);
    if (st != BR_OK) {
        ++t->n_dropped;
        return st;
    }
    ++t->n_sent;
    return BR_OK;
}
