/* SPDX-License-Identifier: Apache-2.0 */
/* Range checks every module's init shares (private to the firmware). */
#ifndef BR_CHECK_H
#define BR_CHECK_H

#include <math.h>

/* finite and > 0 */
static inline int br_finite_pos(float v) { return isfinite(v) && v > 0.0f; }

/* finite and >= 0 */
static inline int br_finite_nonneg(float v) { return isfinite(v) && v >= 0.0f; }

/* v limited to [lo, hi] */
static inline float br_clampf(float v, float lo, float hi) { return fminf(fmaxf(v, lo), hi); }

#endif
