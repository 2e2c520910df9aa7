/* SPDX-License-Identifier: Apache-2.0 */
/* The estimators' state on the circle, for reading why a filter lost lock and
 * what its posterior looks like (docs/presliding-plants.md): a br_circle_sink_t
 * that writes one row per period and axis of the PF's cloud beside the plant's
 * truth (trace), and the PF's particles or the UKF's mean and sigma at chosen
 * times (posterior). Host simulator only. */
#ifndef BR_CIRCLE_PFTRACE_H
#define BR_CIRCLE_PFTRACE_H

#include <stdio.h>

#include "circle/br_circle.h"

#define BR_PFTRACE_MAX_AT 16

typedef struct {
    FILE *trace;      /* per-step rows (the PF's runs), or NULL */
    FILE *posterior;  /* particles / UKF moments at the times at_s, or NULL */
    double at_s[BR_PFTRACE_MAX_AT]; /* ascending; each dumped at the first period at or after it */
    int n_at;
    int axis;         /* the axis the posterior is dumped for (0 x, 1 y) */
    long label;       /* written in each row's first column (a plant's number) */
    const br_plant_cfg_t *plant; /* the plant's Stribeck curve, for the truth's g(v) */
    /* the sink's own */
    int next_at;
} br_pftrace_t;

/* The cloud of pf after its step: the particles' mean and standard deviation of each
 * state (theta relative to the filter's origin), and the best predicted particle's
 * signed miss in counts (a resampled copy of it against the measurement; NaN when none). */
void br_pftrace_cloud(const br_pf_t *pf, double mean[BR_NX], double sd[BR_NX], double *miss_counts);

/* The header lines of the files set in tr (those not NULL). */
void br_pftrace_headers(const br_pftrace_t *tr);

/* The sink: user is a br_pftrace_t. */
void br_pftrace_sink(void *user, const br_circle_sample_t *s);

/* "T1,T2,..." (at most BR_PFTRACE_MAX_AT ascending times in [0, 1e4] s) into tr; 0, or -1
 * with a message on stderr naming tool. */
int br_pftrace_parse_at(const char *tool, const char *val, br_pftrace_t *tr);

#endif
