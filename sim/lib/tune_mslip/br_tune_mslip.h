/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's Maxwell-slip guard plants (docs/tuning.md, "Presliding that is
 * not LuGre"): the thesis circle on plants whose presliding is a generalized
 * Maxwell-slip friction (sim/lib/plant/br_gms.h), which the estimators' LuGre
 * model does not contain. A setting is judged on each by its contour RMS over
 * H-inf only's on the same plant; a run that stops the axis is a failure of
 * the setting, never a figure.
 *   plant 0: the demo's hardware-like plant (br_circle_cfg_hardware_like);
 *   plant 1: one draw from issue 30's ranges (2-6 elements, breakaway
 *            0.3-30 um log-uniform, damping 300-4000 N s/m; docs/tuning.md). */
#ifndef BR_TUNE_MSLIP_H
#define BR_TUNE_MSLIP_H

#include "circle/br_circle.h"

#define BR_TUNE_MSLIP_N 2

typedef struct {
    br_circle_cfg_t plant[BR_TUNE_MSLIP_N]; /* the circle on each, with the tuned estimator's controller */
    double hinf_only_m[BR_TUNE_MSLIP_N];    /* H-inf only's contour RMS on each (the control period) */
} br_tune_mslip_t;

/* The guard plants for the controller ctrl (BR_CTRL_HINF_UKF or BR_CTRL_HINF_PF)
 * and H-inf only's figure on each. Returns 0, or -1 with a message on stderr
 * when an H-inf only run fails or stops (no reference to judge against). */
int br_tune_mslip_init(br_tune_mslip_t *g, br_circle_ctrl_t ctrl);

/* The estimator settings of c (its pf and ukf) on every guard plant: returns
 * the largest contour RMS / H-inf only's over the plants that ran to the end;
 * *failed gets the sum over the plants that stopped of 1 + the share of the
 * run lost (0 when none stopped), INFINITY on an invalid configuration. */
double br_tune_mslip_worst(const br_tune_mslip_t *g, const br_circle_cfg_t *c, double *failed);

#endif
