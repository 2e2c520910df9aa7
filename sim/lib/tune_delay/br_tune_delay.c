/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's delayed guard plants (br_tune_delay.h, docs/tuning.md). */
#include "br_tune_delay.h"

#include <math.h>

void br_tune_delay_init(br_tune_delay_t *g, br_circle_ctrl_t ctrl)
{
    static const double delay_s[BR_TUNE_DELAY_N] = BR_TUNE_DELAY_S_LIST;
    for (int k = 0; k < BR_TUNE_DELAY_N; k++) {
        g->plant[k] = br_circle_cfg_thesis(ctrl);
        g->plant[k].plant.delay_s = delay_s[k];
    }
}

br_circle_cfg_t br_tune_delay_run_cfg(const br_tune_delay_t *g, const br_circle_cfg_t *c, int k)
{
    br_circle_cfg_t p = g->plant[k];
    p.pf = c->pf;
    p.ukf = c->ukf;
    /* the machine's delay identification, which the tuner's other runs leave off */
    p.pf.est.delay_id = g->plant[k].pf.est.delay_id;
    p.ukf.est.delay_id = g->plant[k].ukf.est.delay_id;
    return p;
}

double br_tune_delay_failed(const br_tune_delay_t *g, const br_circle_cfg_t *c)
{
    double failed = 0.0;
    for (int k = 0; k < BR_TUNE_DELAY_N; k++) {
        const br_circle_cfg_t p = br_tune_delay_run_cfg(g, c, k);
        br_circle_result_t r;
        /* 1: the firmware stopped the axis (a fault, its time in r.fault_t_s) */
        if (br_circle_run(&p, NULL, NULL, &r) < 0) return INFINITY;
        if (r.fault_status != 0) failed += 1.0 + (p.duration_s - r.fault_t_s) / p.duration_s;
    }
    return failed;
}
