/* SPDX-License-Identifier: Apache-2.0 */
/* The bounds of the host tools' options (sim/apps), in one place; a value
 * outside them is refused before any file is touched. docs/tools.md lists
 * them with the reasons.
 *
 * Duration: simulated time of one run. At 1 ms a row of br_simlog is about
 * 60 bytes, so the longest run writes about 3.6e6 rows (about 220 MB). */
#ifndef BR_TOOL_LIMITS_H
#define BR_TOOL_LIMITS_H

#include "bristle/br_pf.h"

#define BR_TOOL_DURATION_MIN_S 0.1
#define BR_TOOL_DURATION_MAX_S 3600.0

/* control period: the thesis runs 1 and 1.5 ms, the sampling-time study 0.5 to 3 ms */
#define BR_TOOL_DT_MIN_S 1e-4
#define BR_TOOL_DT_MAX_S 0.01

/* br_simlog --cycles: identification cycles of 9.32 s (400: 3728 s, about the duration bound) */
#define BR_TOOL_CYCLES_MAX 400

/* --gms: a Maxwell-slip element's breakaway displacement at most 10 mm (presliding is micrometres) */
#define BR_TOOL_GMS_D_MAX_M 1e-2

/* --gms-zeta: the damping ratio of each Maxwell-slip element's mode, from a mode
 * practically undamped to critical damping */
#define BR_TOOL_GMS_ZETA_MIN 1e-3
#define BR_TOOL_GMS_ZETA_MAX 1.0

/* plant substeps per control period */
#define BR_TOOL_NSUB_MAX 1000

/* particles of the PF */
#define BR_TOOL_PARTICLES_MAX BR_PF_MAX_PARTICLES

/* br_pf_study --table: float32 samples (64 MiB) */
#define BR_TOOL_TABLE_MAX_SAMPLES (1L << 24)

/* br_tune_est --max-fev: circle runs of the tuning */
#define BR_TOOL_MAX_FEV 10000

/* br_demo_circle --gains: magnitude of each H-inf gain */
#define BR_TOOL_GAIN_MAX 1e9

/* the circle (br_circle_args.h: --radius-m, --feed-mm-min): the radius up to half
 * the reference machine's travel (0.3 m, the circle centred on the axes' zero),
 * the feed up to half its top speed (0.1 m/s: the loop's overshoot stays under
 * the speed guard); a revolution must last BR_TOOL_DURATION_MIN_S .. _MAX_S */
#define BR_TOOL_RADIUS_MIN_M 1e-6
#define BR_TOOL_RADIUS_MAX_M 0.15
#define BR_TOOL_FEED_MIN_MM_MIN 0.01
#define BR_TOOL_FEED_MAX_MM_MIN 3000.0

/* --pf-gate (a study of the PF's outlier gate, docs/presliding-plants.md): standard
 * deviations; the firmware refuses a gate <= 0 or above BR_EST_GATE_MAX_SIGMA, a study
 * needs neither end */
#define BR_TOOL_GATE_MIN_SIGMA 1.0
#define BR_TOOL_GATE_MAX_SIGMA 1000.0

/* br_simlog --force-noise: standard deviation, N */
#define BR_TOOL_NOISE_MAX_N 1e4

#endif
