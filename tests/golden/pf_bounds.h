/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's golden tests (test_golden_pf, test_golden_pf_load):
 * the configuration from a trace header and the propagated bound on the
 * error of every particle (docs/golden.md, "pf"). */
#ifndef BR_GOLDEN_PF_BOUNDS_H
#define BR_GOLDEN_PF_BOUNDS_H

#include <stdint.h>

#include "bristle/br_pf.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

/* Rounding-chain factors (docs/golden.md): one prediction step as the model
 * golden test (32 u, 64 u for z), the noise addition and clamp of g_p, a
 * log-weight (a difference, a square, a product), one f_nl evaluation, and a
 * float32 sum of m terms (<= m u of the largest). */
#define C_THETA 32.0
#define C_OMEGA 32.0
#define C_Z 64.0
#define C_GP 2.0
#define C_L 8.0
#define C_FNL 32.0
#define C_SUM 2.0
/* br_exp_neg: relative error < 5e-6 over [-87, 0] (br_math.h) */
#define EXP_REL 5.0e-6

/* Model constants for the error bounds (double, from the trace header). */
typedef struct {
    double h, L, Jeff, s0, s1, s2, R, sig_R, gp_max;
    double m;
} pf_consts_t;

/* Bound on |x_C - x_ref| of every particle, per state, n steps after the C
 * set was last re-synchronised to the reference (docs/golden.md). */
typedef struct {
    double d[BR_NX];
    int n;
} drift_t;

/* The filter's configuration from a PF trace's header (the ROM table the
 * trace names must be the linked one: checked); cfg.load off. */
br_pf_cfg_t pf_golden_cfg(const br_trace_t *t);

/* The bounds' constants of configuration cfg (model values from t's header) */
pf_consts_t pf_golden_consts(const br_trace_t *t, const br_pf_cfg_t *cfg);

/* FNV-1a of a float table's bytes (the trace's noise_fnv1a) */
uint32_t pf_fnv1a_table(const float *t, uint32_t n);

/* Scales of one prediction step, from the reference's mean state (before, xa,
 * and after, xb, the step: the larger), the torque and the origin shift. */
void step_scales(const pf_consts_t *c, const double *xa, const double *xb, double u, double shift,
                 double S[BR_NX]);

/* Rounding of a float32 copy of the reference set (and of priming). */
void drift_seed(drift_t *d, const double S[BR_NX]);

/* One prediction step: the model step's own rounding (the constants of the
 * model golden test), the noise addition, and the propagation of the
 * previous errors (theta integrates omega; z follows L omega). */
void drift_advance(drift_t *d, const pf_consts_t *c, const double S[BR_NX]);

/* Bound on the error of a log-weight l = -e^2 / (2R) whose particle's theta
 * is off by at most dth: |e| dth / R + dth^2 / (2R), plus its own rounding. */
double dlog_bound(const pf_consts_t *c, double l, double dth);

/* Bound on |f_nl(x_C) - f_nl(x_ref)| for a particle x, given the state bounds d:
 * the partial derivatives of f_nl times the bounds, plus the rounding of the
 * evaluation (model test). */
double dfnl_bound(const pf_consts_t *c, const float *x, const double *d);

/* The one-step PF golden tests' end: prints every statistic of all[0..n-1],
 * frees the two traces and fails the test when a step's exact values were
 * wrong (bad_exact, what: their names) or a comparison was outside its
 * tolerance. */
void pf_golden_report(br_errstat_t *const *all, int n, br_trace_t *t, br_trace_t *x, const char *trace,
                      long bad_exact, const char *what);

#endif
