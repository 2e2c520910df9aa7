/* SPDX-License-Identifier: Apache-2.0 */
/* Nelder-Mead simplex minimiser (thesis section 3.2), host side, double.
 *
 * Reflection, expansion, outside/inside contraction and shrink with the
 * standard coefficients (1, 2, 1/2, 1/2), the initial simplex and the stopping
 * rule of scipy.optimize.minimize(method="Nelder-Mead"): vertex i moves
 * coordinate i by 5 % (0.00025 when it is zero; or by init_step); stop when
 * max |x_i - x_best| <= xatol and max |f_i - f_best| <= fatol, or at max_fev.
 * Box bounds by a change of variables: x = lo + (hi - lo) (1 + sin u) / 2, so
 * the simplex moves freely in u and every evaluated x lies in [lo, hi].
 * Deterministic: no randomness, ties broken by vertex order.
 * See docs/modules/nm.md. */
#ifndef BR_NM_H
#define BR_NM_H

#define BR_NM_MAX_DIM 8

typedef double (*br_nm_fn)(void *user, const double *x, int n);

/* Called after each iteration (may be NULL): iteration number, evaluations so
 * far, best point and value. */
typedef void (*br_nm_progress_fn)(void *user, int iter, int nfev, const double *x_best, double f_best, int n);

typedef struct {
    int n;                       /* dimension, 1..BR_NM_MAX_DIM */
    double xatol, fatol;         /* stopping tolerances (in x, after the change of variables) */
    int max_fev;                 /* evaluation budget */
    const double *lo, *hi;       /* optional bounds (both NULL, or both given with lo < hi) */
    double init_step;            /* > 0: initial simplex step in u for every coordinate;
                                    0: scipy's rule (5 %, 0.00025 at zero) */
    br_nm_progress_fn progress;
} br_nm_cfg_t;

typedef struct {
    double x[BR_NM_MAX_DIM];
    double f;
    int nfev, nit;
    int converged;               /* 1 if the tolerances were met before max_fev */
} br_nm_result_t;

/* Minimises fn from x0. Returns 0, or -1 on an invalid configuration (message
 * on stderr). A non-finite f is treated as +infinity (the simplex moves away). */
int br_nm_minimize(const br_nm_cfg_t *cfg, br_nm_fn fn, void *user, const double *x0, br_nm_result_t *res);

#endif
