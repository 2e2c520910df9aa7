/* SPDX-License-Identifier: Apache-2.0 */
/* Runs br_nm_minimize on three standard test functions and prints, per
 * function, the minimiser, the minimum and the evaluation count as JSON, for
 * nm_compare.py to hold against scipy.optimize. */
#include <stdio.h>
#include <string.h>

#include "nm/br_nm.h"

/* Rosenbrock, 2-D: minimum 0 at (1, 1) */
static double rosen(void *u, const double *x, int n)
{
    (void)u;
    (void)n;
    return 100.0 * (x[1] - x[0] * x[0]) * (x[1] - x[0] * x[0]) + (1.0 - x[0]) * (1.0 - x[0]);
}

/* Beale: minimum 0 at (3, 0.5) */
static double beale(void *u, const double *x, int n)
{
    (void)u;
    (void)n;
    double a = 1.5 - x[0] + x[0] * x[1], b = 2.25 - x[0] + x[0] * x[1] * x[1],
           c = 2.625 - x[0] + x[0] * x[1] * x[1] * x[1];
    return a * a + b * b + c * c;
}

/* Powell's singular function, 4-D: minimum 0 at the origin */
static double powell(void *u, const double *x, int n)
{
    (void)u;
    (void)n;
    double a = x[0] + 10.0 * x[1], b = x[2] - x[3], c = x[1] - 2.0 * x[2], d = x[0] - x[3];
    return a * a + 5.0 * b * b + c * c * c * c + 10.0 * d * d * d * d;
}

static void run(const char *name, br_nm_fn fn, int n, const double *x0, int last)
{
    br_nm_cfg_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.n = n;
    cfg.xatol = 1e-4; /* scipy's defaults */
    cfg.fatol = 1e-4;
    cfg.max_fev = 200 * n;
    br_nm_result_t r;
    if (br_nm_minimize(&cfg, fn, NULL, x0, &r) != 0) return;
    printf("  \"%s\": {\"x\": [", name);
    for (int i = 0; i < n; i++) printf("%s%.10g", i ? ", " : "", r.x[i]);
    printf("], \"f\": %.10g, \"nfev\": %d, \"converged\": %d}%s\n", r.f, r.nfev, r.converged, last ? "" : ",");
}

int main(void)
{
    const double r0[2] = {-1.2, 1.0}, b0[2] = {1.0, 1.0}, p0[4] = {3.0, -1.0, 0.0, 1.0};
    printf("{\n");
    run("rosenbrock", rosen, 2, r0, 0);
    run("beale", beale, 2, b0, 0);
    run("powell", powell, 4, p0, 1);
    printf("}\n");
    return 0;
}
