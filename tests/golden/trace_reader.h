/* SPDX-License-Identifier: Apache-2.0 */
/* Reader of the golden traces (golden/traces/NAME.csv, written by
 * golden/gen_traces.py) for the cmocka golden tests, plus a small per-signal
 * error accumulator.
 *
 * Format: lines starting with '#' are comments; a comment of the form
 * "# key: value" (key made of [A-Za-z0-9_]) is metadata. "# columns: a,b,c"
 * names the columns and "# rows: N" gives the row count. Every other line is
 * a row of comma-separated numbers (strtod syntax, so nan/inf are allowed).
 * Any malformed line fails the running test with the file and line number. */
#ifndef BR_TRACE_READER_H
#define BR_TRACE_READER_H

#include <stddef.h>
#include <stdint.h>

#include "bristle/br_est.h"
#include "bristle/br_model.h"

#define BR_TRACE_MAX_COLS 64
#define BR_TRACE_MAX_META 64

typedef struct {
    char path[512];
    int ncols;
    char *cols[BR_TRACE_MAX_COLS];
    int nmeta;
    char *meta_key[BR_TRACE_MAX_META];
    char *meta_val[BR_TRACE_MAX_META];
    int nrows;
    double *data;  /* nrows x ncols, row-major */
    int *line;     /* source line number of each row */
} br_trace_t;

/* Path of a trace file by name ("lugre" -> <BR_GOLDEN_TRACE_DIR>/lugre.csv). */
void br_trace_path(char *buf, size_t n, const char *name);

/* Loads a whole trace; fails the current test on any error. */
void br_trace_load(br_trace_t *t, const char *name);
void br_trace_free(br_trace_t *t);

/* Column index by name; fails the test when absent. */
int br_trace_col(const br_trace_t *t, const char *name);
double br_trace_get(const br_trace_t *t, int row, int col);

/* Metadata value by key; fails the test when absent. */
const char *br_trace_meta(const br_trace_t *t, const char *key);
double br_trace_meta_num(const br_trace_t *t, const char *key);
/* A comma-separated list of exactly n numbers. */
void br_trace_meta_nums(const br_trace_t *t, const char *key, double *out, int n);

/* Largest error of one signal over a trace, and the tolerance check. */
typedef struct {
    const char *name;
    const char *unit;
    double max_err;   /* largest |actual - expected| */
    int max_row;
    double max_ratio; /* largest |actual - expected| / tol */
    int ratio_row;
    long n;
    long n_fail;
    int first_fail_row;
} br_errstat_t;

void br_errstat_init(br_errstat_t *s, const char *name, const char *unit);
/* Records one comparison; returns 1 when |actual - expected| <= tol. Both
 * non-finite and equal (nan/nan, inf/inf) counts as an exact match. */
int br_errstat_add(br_errstat_t *s, const br_trace_t *t, int row, double actual,
                   double expected, double tol);
/* Prints "golden <trace>: <name> max |err| = ... (row, line), max err/tol = ...". */
void br_errstat_print(const br_errstat_t *s, const br_trace_t *t, const char *trace);

/* The eq. 6 model configuration recorded in a trace's metadata (J_kgm2, M_kg,
 * L_mprad, sigma2_Nspm, sigma0_Npm, sigma1_Nspm, Fc_N, Fs_N, vs_mps, dt_s). */
br_model_cfg_t br_trace_model_cfg(const br_trace_t *t);

/* The configuration the PF and the UKF share (br_est_cfg_t: the model above
 * and the noise, g_p range and gates), from a trace's metadata. */
br_est_cfg_t br_trace_est_cfg(const br_trace_t *t);

#endif
