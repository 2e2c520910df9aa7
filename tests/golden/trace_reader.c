/* SPDX-License-Identifier: Apache-2.0 */
/* Golden trace reader; see trace_reader.h. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "trace_reader.h"

#ifndef BR_GOLDEN_TRACE_DIR
#error "BR_GOLDEN_TRACE_DIR must be defined (tests/golden/CMakeLists.txt)"
#endif

static char *dup_str(const char *s, size_t n)
{
    char *p = malloc(n + 1);
    assert_non_null(p);
    memcpy(p, s, n);
    p[n] = '\0';
    return p;
}

static const char *skip_ws(const char *s)
{
    while (*s == ' ' || *s == '\t') {
        s++;
    }
    return s;
}

static size_t trim_len(const char *s, size_t n)
{
    while (n > 0 && isspace((unsigned char)s[n - 1])) {
        n--;
    }
    return n;
}

void br_trace_path(char *buf, size_t n, const char *name)
{
    const char *dir = getenv("BR_GOLDEN_TRACE_DIR");
    if (dir == NULL || dir[0] == '\0') {
        dir = BR_GOLDEN_TRACE_DIR;
    }
    int w = snprintf(buf, n, "%s/%s.csv", dir, name);
    if (w < 0 || (size_t)w >= n) {
        fail_msg("trace path too long for %s", name);
    }
}

/* "# key: value" -> metadata; any other comment is ignored. */
static void parse_comment(br_trace_t *t, const char *s, int lineno)
{
    const char *k = skip_ws(s + 1);
    const char *e = k;
    while (isalnum((unsigned char)*e) || *e == '_') {
        e++;
    }
    if (e == k || *e != ':') {
        return;
    }
    const char *v = skip_ws(e + 1);
    size_t vn = trim_len(v, strlen(v));
    if (t->nmeta >= BR_TRACE_MAX_META) {
        fail_msg("%s:%d: too many metadata lines (max %d)", t->path, lineno, BR_TRACE_MAX_META);
    }
    t->meta_key[t->nmeta] = dup_str(k, (size_t)(e - k));
    t->meta_val[t->nmeta] = dup_str(v, vn);
    t->nmeta++;
    if ((size_t)(e - k) == 7 && strncmp(k, "columns", 7) == 0) {
        if (t->ncols != 0) {
            fail_msg("%s:%d: second '# columns:' line", t->path, lineno);
        }
        const char *c = v;
        const char *end = v + vn;
        while (c < end) {
            const char *comma = memchr(c, ',', (size_t)(end - c));
            const char *ce = comma ? comma : end;
            const char *cs = skip_ws(c);
            size_t cn = trim_len(cs, (size_t)(ce - cs));
            if (cn == 0) {
                fail_msg("%s:%d: empty column name", t->path, lineno);
            }
            if (t->ncols >= BR_TRACE_MAX_COLS) {
                fail_msg("%s:%d: too many columns (max %d)", t->path, lineno, BR_TRACE_MAX_COLS);
            }
            t->cols[t->ncols++] = dup_str(cs, cn);
            c = comma ? comma + 1 : end;
        }
        if (t->ncols == 0) {
            fail_msg("%s:%d: '# columns:' names no column", t->path, lineno);
        }
    }
}

static void parse_row(br_trace_t *t, char *s, int lineno, int *cap)
{
    if (t->ncols == 0) {
        fail_msg("%s:%d: data row before the '# columns:' line", t->path, lineno);
    }
    if (t->nrows == *cap) {
        *cap = *cap ? 2 * *cap : 1024;
        t->data = realloc(t->data, (size_t)*cap * (size_t)t->ncols * sizeof(double));
        t->line = realloc(t->line, (size_t)*cap * sizeof(int));
        assert_non_null(t->data);
        assert_non_null(t->line);
    }
    double *row = t->data + (size_t)t->nrows * (size_t)t->ncols;
    const char *p = s;
    for (int c = 0; c < t->ncols; c++) {
        char *end = NULL;
        p = skip_ws(p);
        double v = strtod(p, &end);
        if (end == p) {
            fail_msg("%s:%d: malformed row: field %d (%s) is not a number: '%s'",
                     t->path, lineno, c + 1, t->cols[c], s);
        }
        row[c] = v;
        p = skip_ws(end);
        if (c + 1 < t->ncols) {
            if (*p != ',') {
                fail_msg("%s:%d: malformed row: %d fields, %d columns expected: '%s'",
                         t->path, lineno, c + 1, t->ncols, s);
            }
            p++;
        }
    }
    if (*p != '\0') {
        fail_msg("%s:%d: malformed row: trailing text '%s' (more than %d fields?)",
                 t->path, lineno, p, t->ncols);
    }
    t->line[t->nrows] = lineno;
    t->nrows++;
}

void br_trace_load(br_trace_t *t, const char *name)
{
    memset(t, 0, sizeof(*t));
    br_trace_path(t->path, sizeof(t->path), name);
    FILE *f = fopen(t->path, "r");
    if (f == NULL) {
        fail_msg("cannot open golden trace %s (regenerate with golden/gen_traces.py)", t->path);
    }
    char buf[4096];
    int lineno = 0;
    int cap = 0;
    while (fgets(buf, sizeof(buf), f) != NULL) {
        lineno++;
        size_t n = strlen(buf);
        if (n == sizeof(buf) - 1 && buf[n - 1] != '\n') {
            fclose(f);
            fail_msg("%s:%d: line longer than %d characters", t->path, lineno, (int)sizeof(buf) - 2);
        }
        buf[trim_len(buf, n)] = '\0';
        if (buf[0] == '#') {
            parse_comment(t, buf, lineno);
        } else if (buf[0] == '\0') {
            fclose(f);
            fail_msg("%s:%d: empty line", t->path, lineno);
        } else {
            parse_row(t, buf, lineno, &cap);
        }
    }
    fclose(f);
    if (t->ncols == 0) {
        fail_msg("%s: no '# columns:' line", t->path);
    }
    double rows = br_trace_meta_num(t, "rows");
    if (rows != (double)t->nrows) {
        fail_msg("%s: '# rows: %.0f' but %d rows read (truncated file?)", t->path, rows, t->nrows);
    }
    if (t->nrows == 0) {
        fail_msg("%s: no data rows", t->path);
    }
}

void br_trace_free(br_trace_t *t)
{
    for (int i = 0; i < t->ncols; i++) {
        free(t->cols[i]);
    }
    for (int i = 0; i < t->nmeta; i++) {
        free(t->meta_key[i]);
        free(t->meta_val[i]);
    }
    free(t->data);
    free(t->line);
    memset(t, 0, sizeof(*t));
}

int br_trace_col(const br_trace_t *t, const char *name)
{
    for (int i = 0; i < t->ncols; i++) {
        if (strcmp(t->cols[i], name) == 0) {
            return i;
        }
    }
    fail_msg("%s: no column '%s'", t->path, name);
    return -1;
}

double br_trace_get(const br_trace_t *t, int row, int col)
{
    assert_true(row >= 0 && row < t->nrows && col >= 0 && col < t->ncols);
    return t->data[(size_t)row * (size_t)t->ncols + (size_t)col];
}

const char *br_trace_meta(const br_trace_t *t, const char *key)
{
    for (int i = 0; i < t->nmeta; i++) {
        if (strcmp(t->meta_key[i], key) == 0) {
            return t->meta_val[i];
        }
    }
    fail_msg("%s: no '# %s:' header line", t->path, key);
    return NULL;
}

double br_trace_meta_num(const br_trace_t *t, const char *key)
{
    double v;
    br_trace_meta_nums(t, key, &v, 1);
    return v;
}

void br_trace_meta_nums(const br_trace_t *t, const char *key, double *out, int n)
{
    const char *s = br_trace_meta(t, key);
    const char *p = s;
    for (int i = 0; i < n; i++) {
        char *end = NULL;
        out[i] = strtod(p, &end);
        if (end == p) {
            fail_msg("%s: header '%s: %s': value %d is not a number", t->path, key, s, i + 1);
        }
        p = skip_ws(end);
        if (i + 1 < n) {
            if (*p != ',') {
                fail_msg("%s: header '%s: %s': %d values expected", t->path, key, s, n);
            }
            p++;
        }
    }
    if (*p != '\0') {
        fail_msg("%s: header '%s: %s': %d values expected", t->path, key, s, n);
    }
}

void br_errstat_init(br_errstat_t *s, const char *name, const char *unit)
{
    memset(s, 0, sizeof(*s));
    s->name = name;
    s->unit = unit;
    s->max_row = -1;
    s->ratio_row = -1;
    s->first_fail_row = -1;
}

int br_errstat_add(br_errstat_t *s, const br_trace_t *t, int row, double actual,
                   double expected, double tol)
{
    (void)t;
    s->n++;
    double err;
    if (!isfinite(actual) || !isfinite(expected)) {
        int same = (isnan(actual) && isnan(expected)) || actual == expected;
        err = same ? 0.0 : INFINITY;
    } else {
        err = fabs(actual - expected);
    }
    if (err > s->max_err || s->max_row < 0) {
        s->max_err = err;
        s->max_row = row;
    }
    double ratio = (tol > 0.0) ? err / tol : (err == 0.0 ? 0.0 : INFINITY);
    if (ratio > s->max_ratio || s->ratio_row < 0) {
        s->max_ratio = ratio;
        s->ratio_row = row;
    }
    if (!(err <= tol)) {
        if (s->n_fail == 0) {
            s->first_fail_row = row;
        }
        s->n_fail++;
        if (s->n_fail <= 5) {
            print_error("%s:%d: %s = %.17g, expected %.17g, |err| = %.3e > tol %.3e %s\n",
                        t->path, t->line[row], s->name, actual, expected, err, tol, s->unit);
        }
        return 0;
    }
    return 1;
}

void br_errstat_print(const br_errstat_t *s, const br_trace_t *t, const char *trace)
{
    int ml = s->max_row >= 0 ? t->line[s->max_row] : 0;
    int rl = s->ratio_row >= 0 ? t->line[s->ratio_row] : 0;
    print_message("golden %-10s %-8s max |err| = %.3e %-5s (line %d)   max err/tol = %.3g (line %d)   "
                  "n = %ld, fails = %ld\n",
                  trace, s->name, s->max_err, s->unit, ml, s->max_ratio, rl, s->n, s->n_fail);
}

br_model_cfg_t br_trace_model_cfg(const br_trace_t *t)
{
    br_model_cfg_t m = {0}; /* no causes: the thesis model */
    m.J_kgm2 = (float)br_trace_meta_num(t, "J_kgm2");
    m.M_kg = (float)br_trace_meta_num(t, "M_kg");
    m.lead_mprad = (float)br_trace_meta_num(t, "L_mprad");
    m.sigma2_Nspm = (float)br_trace_meta_num(t, "sigma2_Nspm");
    m.lugre.sigma0_Npm = (float)br_trace_meta_num(t, "sigma0_Npm");
    m.lugre.sigma1_Nspm = (float)br_trace_meta_num(t, "sigma1_Nspm");
    m.lugre.Fc_N = (float)br_trace_meta_num(t, "Fc_N");
    m.lugre.Fs_N = (float)br_trace_meta_num(t, "Fs_N");
    m.lugre.vs_mps = (float)br_trace_meta_num(t, "vs_mps");
    m.dt_s = (float)br_trace_meta_num(t, "dt_s");
    return m;
}

br_est_cfg_t br_trace_est_cfg(const br_trace_t *t)
{
    br_est_cfg_t e;
    double q[4];
    /* what the trace does not name is off: no compensation lead, no delay identification */
    memset(&e, 0, sizeof e);
    e.model = br_trace_model_cfg(t);
    br_trace_meta_nums(t, "q_var", q, 4);
    for (int i = 0; i < 4; i++) e.q_var[i] = (float)q[i];
    e.r_var_rad2 = (float)br_trace_meta_num(t, "r_var_rad2");
    e.gp0_N = (float)br_trace_meta_num(t, "gp0_N");
    e.gp_min_N = (float)br_trace_meta_num(t, "gp_min_N");
    e.gp_max_N = (float)br_trace_meta_num(t, "gp_max_N");
    e.outlier_sigma = (float)br_trace_meta_num(t, "outlier_sigma");
    e.reanchor_after = (uint32_t)br_trace_meta_num(t, "reanchor_after");
    e.rad_per_count = (float)br_trace_meta_num(t, "rad_per_count");
    return e;
}
