/* SPDX-License-Identifier: Apache-2.0 */
/* Reading a measured log's columns in a host tool by the diagnosis's rules
 * (python/bristle/diagnose/logreader.py, docs/diagnose.md "Reading a log"):
 *
 * - a regular file (a device, a FIFO or a folder refused before it is read);
 * - a header naming the wanted columns, any case, spaces and one level of
 *   quotes around a name, a UTF-8 byte-order mark; a wanted name given twice
 *   refused; further columns ignored;
 * - every row with the header's number of fields (an empty cell is a field:
 *   it never shifts the columns); blank lines skipped;
 * - a cell is [+-]digits[.digits][e[+-]digits] (or .digits), ASCII, spaces
 *   around allowed, optionally in double quotes; an empty cell, "0.001abc",
 *   hexadecimal, NaN, infinity, a decimal comma and |v| > 1e9 refused;
 * - the time strictly increases at one period (1 % tolerance), and the whole
 *   log lasts at most BR_TOOL_DURATION_MAX_S;
 * - at least min_rows rows; a line longer than BR_LOGCSV_LINE_MAX refused.
 *
 * What it does not take that the diagnosis takes: a quoted field holding a
 * comma, a quote or a line end (a number never does). Every problem is one
 * line "tool: file:line: problem" on stderr and -1; nothing is kept then. */
#ifndef BR_LOGCSV_H
#define BR_LOGCSV_H

#define BR_LOGCSV_MAX_COLS 4
#define BR_LOGCSV_LINE_MAX 4096
#define BR_LOGCSV_MAX_ABS 1e9
#define BR_LOGCSV_UNIFORM_TOL 0.01

typedef struct {
    double *col[BR_LOGCSV_MAX_COLS]; /* the wanted columns, in the order asked; col[0] is the time */
    long n;                          /* rows */
    double t0, dt;                   /* first time, period (mean step) */
} br_logcsv_t;

/* Reads the columns names[0..ncols-1] (names[0] the time) of path into lg
 * (malloc'd; br_logcsv_free). 0, or -1 with the message (lg emptied). */
int br_logcsv_read(const char *tool, const char *path, const char *const *names, int ncols, long min_rows,
                   br_logcsv_t *lg);

/* Frees the columns; safe on an emptied or zeroed lg. */
void br_logcsv_free(br_logcsv_t *lg);

#endif
