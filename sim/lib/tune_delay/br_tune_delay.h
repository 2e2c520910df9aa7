/* SPDX-License-Identifier: Apache-2.0 */
/* The tuner's delayed guard plants (docs/tuning.md, "A plant with an actuator
 * delay"): the thesis circle with an actuator dead time on the plant and the
 * machine's delay identification on (docs/modules/dlyid.md), as ctest
 * test_circle's test_delay_identified runs it. The tuner tunes the variances
 * with the identification off and on plants without a delay; a setting that
 * stops the axis here (the UKF tuned with the Maxwell-slip guards alone lost
 * lock at 5.503 s at 2 ms) counts as a failure of the setting, never a figure. */
#ifndef BR_TUNE_DELAY_H
#define BR_TUNE_DELAY_H

#include "circle/br_circle.h"

/* the plant delays, s: test_delay_identified's 2 ms, where that UKF stopped,
 * and its longest, 3 ms */
#define BR_TUNE_DELAY_N 2
#define BR_TUNE_DELAY_S_LIST {2.0e-3, 3.0e-3}

typedef struct {
    br_circle_cfg_t plant[BR_TUNE_DELAY_N]; /* the circle on each, with the tuned estimator's controller */
} br_tune_delay_t;

/* The guard plants for the controller ctrl (BR_CTRL_HINF_UKF or BR_CTRL_HINF_PF). */
void br_tune_delay_init(br_tune_delay_t *g, br_circle_ctrl_t ctrl);

/* The run on guard plant k (0 .. BR_TUNE_DELAY_N - 1): the estimator
 * settings of c (its pf and ukf), their delay identification replaced by
 * the machine's. */
br_circle_cfg_t br_tune_delay_run_cfg(const br_tune_delay_t *g, const br_circle_cfg_t *c, int k);

/* That run on every guard plant: the sum over the plants that stopped of
 * 1 + the share of the run lost (0 when none stopped), INFINITY on an
 * invalid configuration. */
double br_tune_delay_failed(const br_tune_delay_t *g, const br_circle_cfg_t *c);

#endif
