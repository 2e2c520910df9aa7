/* SPDX-License-Identifier: Apache-2.0 */
/* Cause options (br_cause_args.h), by the table of br_model_params.h. */
#include "br_cause_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plant/br_model_params.h"

int br_parse_numbers(const char *s, double *v, int n)
{
    int k = 0;
    const char *p = s;
    while (k < n) {
        char *end;
        errno = 0;
        v[k] = strtod(p, &end);
        if (end == p || errno == ERANGE || !isfinite(v[k])) return -1;
        k++;
        if (*end == '\0') return k;
        if (*end != ',') return -1;
        p = end + 1;
    }
    return -1;
}

/* one row of the table that the option sets */
typedef struct {
    const char *name;
    double *field;
    double lo, hi;
} row_t;

#define COUNT_ROW(...) +1
enum { N_CAUSE_PARAMS = 0 BR_CAUSE_PARAMS(COUNT_ROW) };
#undef COUNT_ROW

int br_cause_arg(const char *opt, const char *val, br_plant_cfg_t *c)
{
    row_t rows[N_CAUSE_PARAMS];
    int n = 0, required = 0;
#define MATCH_ROW(json, fld, unit, lo_, hi_, cause, option, req) \
    if (strcmp(opt, option) == 0) {                              \
        rows[n] = (row_t){json, &c->fld, lo_, hi_};              \
        n++;                                                     \
        required += req;                                         \
    }
    BR_CAUSE_PARAMS(MATCH_ROW)
#undef MATCH_ROW
    if (n == 0) return 0;
    double v[N_CAUSE_PARAMS];
    const int k = br_parse_numbers(val, v, n);
    if (k < required) {
        fprintf(stderr, "bad value for %s: %s (%d to %d numbers: ", opt, val, required, n);
        for (int i = 0; i < n; i++) fprintf(stderr, "%s%s", i ? "," : "", rows[i].name);
        fprintf(stderr, ")\n");
        return -1;
    }
    for (int i = k; i < n; i++) v[i] = 0.0; /* optional values left out */
    for (int i = 0; i < n; i++) {
        if (!br_param_in_bounds(v[i], rows[i].lo, rows[i].hi)) {
            char bounds[64];
            br_param_bounds_text(rows[i].lo, rows[i].hi, bounds, sizeof bounds);
            fprintf(stderr, "bad value for %s: %s (%s %s)\n", opt, val, rows[i].name, bounds);
            return -1;
        }
    }
    for (int i = 0; i < n; i++) *rows[i].field = v[i];
    return 1;
}

void br_causes_apply(br_plant_cfg_t *plant, const br_plant_cfg_t *causes)
{
    const br_plant_cfg_t ref = br_plant_cfg_reference();
    if (causes->offset_N != 0.0) plant->offset_N = causes->offset_N;
    if (causes->dFc_neg_N != ref.dFc_neg_N || causes->dsigma2_neg_Nspm != ref.dsigma2_neg_Nspm) {
        plant->dFc_neg_N = causes->dFc_neg_N;
        plant->dsigma2_neg_Nspm = causes->dsigma2_neg_Nspm;
    }
    if (causes->ripple_amp_N != 0.0) {
        plant->ripple_amp_N = causes->ripple_amp_N;
        plant->ripple_period_m = causes->ripple_period_m;
        plant->ripple_phase_rad = causes->ripple_phase_rad;
    }
    if (causes->grad_per_m != 0.0) plant->grad_per_m = causes->grad_per_m;
    if (causes->delay_s != 0.0) plant->delay_s = causes->delay_s;
    if (causes->drift_per_s != 0.0) plant->drift_per_s = causes->drift_per_s;
}
