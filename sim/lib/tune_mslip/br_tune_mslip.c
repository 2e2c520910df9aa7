/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's Maxwell-slip guard plants (br_tune_mslip.h, docs/tuning.md). */
#include "br_tune_mslip.h"

#include <math.h>
#include <stdio.h>

/* plant 1: the draw of docs/tuning.md ("Presliding that is not LuGre"),
 * rounded: 4 elements, breakaway at Fs 0.58, 1.26, 23.7, 23.9 um, shares
 * 0.219, 0.315, 0.216, 0.250, each element damped by 320 N s/m; initial
 * stiffness 1.2e7 N/m, three times the machine's sigma0 */
#define DRAW_N 4
#define DRAW_SIGMA1_NSPM 320.0
static const double draw_d_m[DRAW_N] = {0.58e-6, 1.26e-6, 23.7e-6, 23.9e-6};
static const double draw_share[DRAW_N] = {0.219, 0.315, 0.216, 0.250};

/* the guard plant k for the controller ctrl */
static br_circle_cfg_t guard_plant(int k, br_circle_ctrl_t ctrl)
{
    br_circle_cfg_t c = br_circle_cfg_hardware_like(ctrl);
    if (k == 1) {
        /* the same law, C and Stribeck curve as the hardware-like plant; other elements */
        br_gms_from_breakaway(&c.plant.gms, DRAW_N, draw_d_m, draw_share, c.plant.Fs_N, DRAW_SIGMA1_NSPM);
    }
    return c;
}

int br_tune_mslip_init(br_tune_mslip_t *g, br_circle_ctrl_t ctrl)
{
    for (int k = 0; k < BR_TUNE_MSLIP_N; k++) {
        g->plant[k] = guard_plant(k, ctrl);
        const br_circle_cfg_t h = guard_plant(k, BR_CTRL_HINF_ONLY);
        br_circle_result_t r;
        if (br_circle_run(&h, NULL, NULL, &r) != 0 || r.fault_status != 0) {
            fprintf(stderr, "br_tune_mslip: H-inf only on Maxwell-slip guard plant %d did not run to the end\n", k);
            return -1;
        }
        g->hinf_only_m[k] = r.contour_rms_m;
    }
    return 0;
}

double br_tune_mslip_worst(const br_tune_mslip_t *g, const br_circle_cfg_t *c, double *failed)
{
    double worst = 0.0;
    *failed = 0.0;
    for (int k = 0; k < BR_TUNE_MSLIP_N; k++) {
        br_circle_cfg_t p = g->plant[k];
        p.pf = c->pf;
        p.ukf = c->ukf;
        br_circle_result_t r;
        /* 1: the firmware stopped the axis (a fault, its time in r.fault_t_s) */
        if (br_circle_run(&p, NULL, NULL, &r) < 0) return INFINITY;
        if (r.fault_status != 0) {
            *failed += 1.0 + (p.duration_s - r.fault_t_s) / p.duration_s;
        } else {
            worst = fmax(worst, r.contour_rms_m / g->hinf_only_m[k]);
        }
    }
    return worst;
}
