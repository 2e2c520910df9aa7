/* SPDX-License-Identifier: Apache-2.0 */
/* A measured log's columns by the diagnosis's rules (br_logcsv.h). */
#define _POSIX_C_SOURCE 200809L
#include "br_logcsv.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "br_tool_limits.h"

/* rows at most: 2^24 (the longest br_simlog run writes 3.6e6) */
#define MAX_ROWS (1L << 24)
#define MAX_FIELDS 256

typedef struct {
    const char *tool, *path;
    FILE *f;
    long lineno;
} reader_t;

static int fail(const reader_t *r, long line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "%s: %s:%ld: ", r->tool, r->path, line);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return -1;
}

/* the next line without its end into buf: 1, 0 at the end, -1 (reported) too long */
static int next_line(reader_t *r, char *buf, size_t size)
{
    if (!fgets(buf, (int)size, r->f)) return 0;
    r->lineno++;
    size_t n = strlen(buf);
    if (n > 0 && buf[n - 1] == '\n') buf[--n] = '\0';
    else if (!feof(r->f)) return fail(r, r->lineno, "a line longer than %d characters, not a log row", BR_LOGCSV_LINE_MAX);
    if (n > 0 && buf[n - 1] == '\r') buf[--n] = '\0';
    return 1;
}

/* the fields of a line, split at every comma (an empty field is a field),
 * trimmed and unquoted in place; the count, or -1 (reported) */
static int split(const reader_t *r, char *line, char **field)
{
    int n = 0;
    for (char *s = line;; n++) {
        if (n == MAX_FIELDS) return fail(r, r->lineno, "more than %d fields", MAX_FIELDS);
        char *comma = strchr(s, ',');
        if (comma) *comma = '\0';
        while (isspace((unsigned char)*s)) s++;
        char *e = s + strlen(s);
        while (e > s && isspace((unsigned char)e[-1])) *--e = '\0';
        if (*s == '"') {
            if (e - s < 2 || e[-1] != '"' || memchr(s + 1, '"', (size_t)(e - s - 2)))
                return fail(r, r->lineno, "malformed quoting, or a quoted field holding a comma or a quote "
                                          "(a number never does)");
            e[-1] = '\0';
            s++;
        }
        field[n] = s;
        if (!comma) return n + 1;
        s = comma + 1;
    }
}

/* [+-]digits[.digits][e[+-]digits] or [+-].digits[...]: the diagnosis's NUMBER */
static int is_number(const char *s)
{
    if (*s == '+' || *s == '-') s++;
    int digits = 0;
    while (isdigit((unsigned char)*s)) s++, digits++;
    if (*s == '.') {
        s++;
        while (isdigit((unsigned char)*s)) s++, digits++;
    }
    if (!digits) return 0;
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-') s++;
        if (!isdigit((unsigned char)*s)) return 0;
        while (isdigit((unsigned char)*s)) s++;
    }
    return *s == '\0';
}

static int cell(const reader_t *r, const char *name, const char *s, double *v)
{
    if (!*s) return fail(r, r->lineno, "column '%s' is empty", name);
    if (!is_number(s)) return fail(r, r->lineno, "column '%s': '%.40s' is not a number", name, s);
    *v = strtod(s, NULL);
    if (!(fabs(*v) <= BR_LOGCSV_MAX_ABS)) return fail(r, r->lineno, "column '%s': %.40s is beyond +-%g", name, s,
                                                      BR_LOGCSV_MAX_ABS);
    return 0;
}

/* the header: each wanted name's field, and the number of fields; -1 (reported) */
static int header(const reader_t *r, char *line, const char *const *names, int ncols, int *idx, int *nfields)
{
    if ((unsigned char)line[0] == 0xEF && (unsigned char)line[1] == 0xBB && (unsigned char)line[2] == 0xBF) line += 3;
    char *field[MAX_FIELDS];
    const int n = split(r, line, field);
    if (n < 0) return -1;
    for (int c = 0; c < ncols; c++) {
        idx[c] = -1;
        for (int i = 0; i < n; i++) {
            for (char *p = field[i]; *p; p++) *p = (char)tolower((unsigned char)*p);
            if (strcmp(field[i], names[c]) != 0) continue;
            if (idx[c] >= 0) return fail(r, r->lineno, "header names column %s twice", names[c]);
            idx[c] = i;
        }
        if (idx[c] < 0) return fail(r, r->lineno, "header lacks column %s", names[c]);
    }
    *nfields = n;
    return 0;
}

static int grow(br_logcsv_t *lg, int ncols, long *cap)
{
    const long want = *cap ? 2 * *cap : 65536;
    for (int c = 0; c < ncols; c++) {
        double *p = realloc(lg->col[c], (size_t)want * sizeof *p);
        if (!p) return -1;
        lg->col[c] = p;
    }
    *cap = want;
    return 0;
}

void br_logcsv_free(br_logcsv_t *lg)
{
    for (int c = 0; c < BR_LOGCSV_MAX_COLS; c++) {
        free(lg->col[c]);
        lg->col[c] = NULL;
    }
    lg->n = 0;
}

static int read_rows(reader_t *r, const char *const *names, int ncols, long min_rows, br_logcsv_t *lg)
{
    char line[BR_LOGCSV_LINE_MAX + 2], *field[MAX_FIELDS];
    int idx[BR_LOGCSV_MAX_COLS], nfields = 0, got;
    while ((got = next_line(r, line, sizeof line)) == 1 && line[strspn(line, " \t")] == '\0') {
    }
    if (got < 0) return -1;
    if (got == 0) return fail(r, r->lineno > 0 ? r->lineno : 1, "empty file: no header");
    if (header(r, line, names, ncols, idx, &nfields) != 0) return -1;
    long cap = 0;
    double step0 = 0.0;
    while ((got = next_line(r, line, sizeof line)) == 1) {
        if (line[strspn(line, " \t")] == '\0') continue;
        const int n = split(r, line, field);
        if (n < 0) return -1;
        if (n != nfields) return fail(r, r->lineno, "%d fields, the header has %d", n, nfields);
        if (lg->n == MAX_ROWS) return fail(r, r->lineno, "more than %ld rows", MAX_ROWS);
        if (lg->n == cap && grow(lg, ncols, &cap) != 0) return fail(r, r->lineno, "out of memory");
        for (int c = 0; c < ncols; c++)
            if (cell(r, names[c], field[idx[c]], &lg->col[c][lg->n]) != 0) return -1;
        const double t = lg->col[0][lg->n];
        if (lg->n > 0) {
            const double prev = lg->col[0][lg->n - 1], step = t - prev;
            if (!(step > 0.0)) return fail(r, r->lineno, "time %.9g s does not increase (previous %.9g s)", t, prev);
            if (lg->n == 1) step0 = step;
            else if (fabs(step - step0) > BR_LOGCSV_UNIFORM_TOL * step0)
                return fail(r, r->lineno, "time step %.6g s differs from the period %.6g s by more than %g %% "
                                          "(non-uniform sampling)", step, step0, 100.0 * BR_LOGCSV_UNIFORM_TOL);
            if (t - lg->col[0][0] > BR_TOOL_DURATION_MAX_S)
                return fail(r, r->lineno, "the log lasts more than %g s (docs/tools.md)", BR_TOOL_DURATION_MAX_S);
        }
        lg->n++;
    }
    if (got < 0) return -1;
    if (lg->n < min_rows) return fail(r, r->lineno, "only %ld rows; at least %ld are needed", lg->n, min_rows);
    lg->t0 = lg->col[0][0];
    lg->dt = (lg->col[0][lg->n - 1] - lg->t0) / (double)(lg->n - 1);
    return 0;
}

int br_logcsv_read(const char *tool, const char *path, const char *const *names, int ncols, long min_rows,
                   br_logcsv_t *lg)
{
    memset(lg, 0, sizeof *lg);
    reader_t r = {tool, path, NULL, 0};
    if (ncols < 1 || ncols > BR_LOGCSV_MAX_COLS || min_rows < 2) return fail(&r, 0, "bad reader call");
    struct stat st;
    if (stat(path, &st) != 0) return fail(&r, 0, "cannot read: %s", strerror(errno));
    if (!S_ISREG(st.st_mode)) return fail(&r, 0, "not a regular file (a device, a FIFO or a folder)");
    if ((r.f = fopen(path, "r")) == NULL) return fail(&r, 0, "cannot read: %s", strerror(errno));
    const int rc = read_rows(&r, names, ncols, min_rows, lg);
    fclose(r.f);
    if (rc != 0) br_logcsv_free(lg);
    return rc;
}
