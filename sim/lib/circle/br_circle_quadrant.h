/* SPDX-License-Identifier: Apache-2.0 */
/* The quadrant glitch of a circle (docs/modules/qec.md, "Tuning from a circle
 * test"): the RMS of the radial (contour) error over the windows that follow
 * the axes' velocity reversals, where a reversal compensation acts. On the
 * circle x = A sin(w t + phi_x), y = A cos(w t + phi_y) an axis reverses every
 * half revolution and the two axes alternate: the reversals are at the
 * quarter periods k T / 4, k = 1, 2, ... (the start, k = 0, is a start from
 * rest and not counted). Window: [k T / 4, k T / 4 + T / 16). */
#ifndef BR_CIRCLE_QUADRANT_H
#define BR_CIRCLE_QUADRANT_H

#include "br_circle.h"

/* the window after each reversal, in periods of the circle */
#define BR_QUADRANT_WINDOW_T 0.0625

typedef struct {
    double quadrant_rms_m; /* RMS of the radial error in the windows after the reversals */
    long n_quadrant;       /* samples in those windows */
    br_circle_result_t run; /* the whole run's figures (contour_rms_m, the fault) */
} br_quadrant_result_t;

/* Runs cfg's circle and measures its quadrant glitch. Returns br_circle_run's
 * status: 0, 1 (a fault: no result; quadrant_rms_m NAN), -1 (invalid). */
int br_circle_quadrant_run(const br_circle_cfg_t *cfg, br_quadrant_result_t *res);

#endif
