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
    /* a cause is set when a field that switches it on differs from the reference machine's
     * (the registry's rows, bristle_gen/model/br_causes.h) */
#define CAUSE_FLAG(cause, hook) int cause;
    struct {
        BR_CAUSE_NAMES(CAUSE_FLAG)
    } set = {0};
#undef CAUSE_FLAG
#define CAUSE_SET(field, cause, hook, on) \
    if ((on) && causes->field != ref.field) set.cause = 1;
    BR_CAUSE_FIELDS(CAUSE_SET)
#undef CAUSE_SET
    /* then every field of a set cause replaces plant's */
#define CAUSE_COPY(field, cause, hook, on) \
    if (set.cause) plant->field = causes->field;
    BR_CAUSE_FIELDS(CAUSE_COPY)
#undef CAUSE_COPY
}

/* the column where a usage line's cause name starts */
#define USAGE_CAUSE_COL 62

void br_cause_usage(FILE *to, const char *note)
{
    static const struct {
        const char *name, *cause, *option;
        int req;
    } rows[] = {
#define USAGE_ROW(json, fld, unit, lo, hi, cause, option, req) {json, cause, option, req},
        BR_CAUSE_PARAMS(USAGE_ROW)
#undef USAGE_ROW
    };
    fprintf(to,
            "  cause options       switch a cause on in the plant (docs/simlog.md), the values its\n"
            "                      model.json parameters in order (docs/diagnose.md, \"Parameters\")\n");
    if (note[0] != '\0') fprintf(to, "                      %s\n", note);
    /* one line per option: its rows' names, the optional ones in brackets, then its cause */
    int col = 0, open = 0;
    for (int i = 0; i < N_CAUSE_PARAMS; i++) {
        const int first = i == 0 || strcmp(rows[i].option, rows[i - 1].option) != 0;
        const int last = i == N_CAUSE_PARAMS - 1 || strcmp(rows[i].option, rows[i + 1].option) != 0;
        if (first) {
            col = fprintf(to, "    %s %s", rows[i].option, rows[i].name);
            open = 0;
        } else {
            col += fprintf(to, "%s%s", rows[i].req ? "," : "[,", rows[i].name);
            open += !rows[i].req;
        }
        if (last) {
            for (; open > 0; open--) col += fprintf(to, "]");
            fprintf(to, "%*s%s\n", col < USAGE_CAUSE_COL ? USAGE_CAUSE_COL - col : 1, "", rows[i].cause);
        }
    }
}
