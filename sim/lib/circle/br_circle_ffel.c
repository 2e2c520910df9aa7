/* SPDX-License-Identifier: Apache-2.0 */
/* The feedforward's Maxwell-slip elements and the prediction on the circle
 * (br_circle.h; docs/modules/ff-pred.md). */
#include <math.h>

#include "br_circle.h"

/* the fit's breakaways at Fs relative to the first: a decade in three equal ratios */
#define FIT_N 4

void br_circle_use_ff_el(br_circle_cfg_t *c, int mode)
{
    br_mslip_cfg_t *ms = &c->ff.mslip;
    const br_gms_cfg_t *g = &c->plant.gms;
    *ms = (br_mslip_cfg_t){0};
    if (mode == BR_CIRCLE_FF_EL_OWN && g->n > 0) {
        /* the plant's own elements: its k_i and shares (its breakaways at Fs) */
        ms->n = g->n;
        for (int i = 0; i < g->n; i++) {
            ms->k_Npm[i] = (float)g->k_Npm[i];
            ms->share[i] = (float)g->alpha[i];
        }
    } else if (mode == BR_CIRCLE_FF_EL_OWN || mode == BR_CIRCLE_FF_EL_FIT) {
        /* the plant's initial stiffness: sum k_i, or LuGre's sigma0 */
        double k0 = 0.0;
        for (int i = 0; i < g->n; i++) k0 += g->k_Npm[i];
        if (g->n == 0) k0 = c->plant.sigma0_Npm;
        /* d_i = d 10^(i/3), share 1/4: sum_i k_i = (Fs / 4 d) sum_i 10^(-i/3) = k0 */
        double s = 0.0;
        for (int i = 0; i < FIT_N; i++) s += pow(10.0, -(double)i / 3.0);
        const double Fs = (double)c->ff.Fs_N, d = Fs * s / (FIT_N * k0);
        ms->n = FIT_N;
        for (int i = 0; i < FIT_N; i++) {
            ms->k_Npm[i] = (float)(Fs / (FIT_N * d * pow(10.0, (double)i / 3.0)));
            ms->share[i] = 1.0f / FIT_N;
        }
    }
    ms->sigma2_Nspm = 0.0f; /* the viscous term is the feedforward's sigma2 */
}

void br_circle_use_pred(br_circle_cfg_t *c, double ahead_s, int anchor)
{
    if (ahead_s > 0.0) {
        c->ff.pred_ahead_s = (float)ahead_s;
        c->pred = anchor == 2 ? 2 : 1;
    }
}
