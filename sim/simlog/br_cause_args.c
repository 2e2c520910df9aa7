/* Cause options (br_cause_args.h). */
#include "br_cause_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

int br_cause_arg(const char *opt, const char *val, br_plant_cfg_t *c)
{
    double v[3];
    int ok;
    if (strcmp(opt, "--offset") == 0) {
        ok = br_parse_numbers(val, v, 1) == 1;
        if (ok) c->offset_N = v[0];
    } else if (strcmp(opt, "--gradient") == 0) {
        ok = br_parse_numbers(val, v, 1) == 1;
        if (ok) c->grad_per_m = v[0];
    } else if (strcmp(opt, "--delay") == 0) {
        ok = br_parse_numbers(val, v, 1) == 1;
        if (ok) c->delay_s = v[0];
    } else if (strcmp(opt, "--asym") == 0) {
        ok = br_parse_numbers(val, v, 2) == 2;
        if (ok) {
            c->dFc_neg_N = v[0];
            c->dsigma2_neg_Nspm = v[1];
        }
    } else if (strcmp(opt, "--ripple") == 0) {
        const int k = br_parse_numbers(val, v, 3);
        ok = k >= 2;
        if (ok) {
            c->ripple_amp_N = v[0];
            c->ripple_period_m = v[1];
            c->ripple_phase_rad = k == 3 ? v[2] : 0.0;
        }
    } else {
        return 0;
    }
    if (!ok) {
        fprintf(stderr, "bad value for %s: %s\n", opt, val);
        return -1;
    }
    return 1;
}
