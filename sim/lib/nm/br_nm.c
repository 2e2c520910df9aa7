/* SPDX-License-Identifier: Apache-2.0 */
/* Nelder-Mead simplex minimiser. See br_nm.h. */
#include "br_nm.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

typedef struct {
    const br_nm_cfg_t *cfg;
    br_nm_fn fn;
    void *user;
    int nfev;
} ctx_t;

/* change of variables: x = lo + (hi - lo) (1 + sin u) / 2 and its inverse */
static void to_x(const br_nm_cfg_t *c, const double *u, double *x)
{
    for (int i = 0; i < c->n; i++) {
        x[i] = c->lo ? c->lo[i] + (c->hi[i] - c->lo[i]) * 0.5 * (1.0 + sin(u[i])) : u[i];
    }
}

static void to_u(const br_nm_cfg_t *c, const double *x, double *u)
{
    for (int i = 0; i < c->n; i++) {
        if (c->lo) {
            double s = 2.0 * (x[i] - c->lo[i]) / (c->hi[i] - c->lo[i]) - 1.0;
            u[i] = asin(fmin(fmax(s, -1.0), 1.0));
        } else {
            u[i] = x[i];
        }
    }
}

static double eval(ctx_t *k, const double *u)
{
    double x[BR_NM_MAX_DIM];
    to_x(k->cfg, u, x);
    k->nfev++;
    double f = k->fn(k->user, x, k->cfg->n);
    return isfinite(f) ? f : INFINITY;
}

/* Sorts the n+1 vertices by f (stable insertion sort: ties keep their order). */
static void sort_simplex(int n, double s[][BR_NM_MAX_DIM], double *f)
{
    for (int i = 1; i <= n; i++) {
        double fi = f[i], si[BR_NM_MAX_DIM];
        memcpy(si, s[i], sizeof si);
        int j = i - 1;
        while (j >= 0 && f[j] > fi) {
            f[j + 1] = f[j];
            memcpy(s[j + 1], s[j], sizeof si);
            j--;
        }
        f[j + 1] = fi;
        memcpy(s[j + 1], si, sizeof si);
    }
}

int br_nm_minimize(const br_nm_cfg_t *cfg, br_nm_fn fn, void *user, const double *x0, br_nm_result_t *res)
{
    if (!cfg || !fn || !x0 || !res || cfg->n < 1 || cfg->n > BR_NM_MAX_DIM || cfg->max_fev < cfg->n + 1 ||
        !(cfg->xatol >= 0.0) || !(cfg->fatol >= 0.0) || !(cfg->init_step >= 0.0) || (!cfg->lo) != (!cfg->hi)) {
        fprintf(stderr, "br_nm_minimize: invalid configuration\n");
        return -1;
    }
    const int n = cfg->n;
    for (int i = 0; i < n; i++) {
        if (!isfinite(x0[i]) || (cfg->lo && !(cfg->lo[i] < cfg->hi[i] && x0[i] >= cfg->lo[i] && x0[i] <= cfg->hi[i]))) {
            fprintf(stderr, "br_nm_minimize: x0[%d] is not finite or outside its bounds\n", i);
            return -1;
        }
    }
    ctx_t k = {cfg, fn, user, 0};
    double s[BR_NM_MAX_DIM + 1][BR_NM_MAX_DIM], f[BR_NM_MAX_DIM + 1];
    /* initial simplex (in u): x0 and, per coordinate, a 5 % step (0.00025 at zero) */
    to_u(cfg, x0, s[0]);
    for (int i = 1; i <= n; i++) {
        memcpy(s[i], s[0], sizeof s[0]);
        if (cfg->init_step > 0.0) s[i][i - 1] += cfg->init_step;
        else s[i][i - 1] = (s[0][i - 1] != 0.0) ? 1.05 * s[0][i - 1] : 0.00025;
    }
    for (int i = 0; i <= n; i++) f[i] = eval(&k, s[i]);
    sort_simplex(n, s, f);
    int it = 0, converged = 0;
    while (k.nfev < cfg->max_fev) {
        /* stop: simplex small in x and in f */
        double dx = 0.0, df = 0.0;
        for (int i = 1; i <= n; i++) {
            df = fmax(df, fabs(f[i] - f[0]));
            for (int j = 0; j < n; j++) dx = fmax(dx, fabs(s[i][j] - s[0][j]));
        }
        if (dx <= cfg->xatol && df <= cfg->fatol) {
            converged = 1;
            break;
        }
        it++;
        /* centroid of all but the worst */
        double c[BR_NM_MAX_DIM] = {0}, xr[BR_NM_MAX_DIM], xe[BR_NM_MAX_DIM], xc[BR_NM_MAX_DIM];
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) c[j] += s[i][j] / n;
        /* reflection: xr = c + (c - x_worst) */
        for (int j = 0; j < n; j++) xr[j] = 2.0 * c[j] - s[n][j];
        double fr = eval(&k, xr);
        int shrink = 0;
        if (fr < f[0]) {
            /* expansion: xe = c + 2 (c - x_worst) */
            for (int j = 0; j < n; j++) xe[j] = 3.0 * c[j] - 2.0 * s[n][j];
            double fe = eval(&k, xe);
            if (fe < fr) {
                memcpy(s[n], xe, sizeof xe);
                f[n] = fe;
            } else {
                memcpy(s[n], xr, sizeof xr);
                f[n] = fr;
            }
        } else if (fr < f[n - 1]) {
            memcpy(s[n], xr, sizeof xr);
            f[n] = fr;
        } else if (fr < f[n]) {
            /* outside contraction: xc = c + (xr - c) / 2 */
            for (int j = 0; j < n; j++) xc[j] = c[j] + 0.5 * (xr[j] - c[j]);
            double fc = eval(&k, xc);
            if (fc <= fr) {
                memcpy(s[n], xc, sizeof xc);
                f[n] = fc;
            } else {
                shrink = 1;
            }
        } else {
            /* inside contraction: xc = c + (x_worst - c) / 2 */
            for (int j = 0; j < n; j++) xc[j] = c[j] + 0.5 * (s[n][j] - c[j]);
            double fc = eval(&k, xc);
            if (fc < f[n]) {
                memcpy(s[n], xc, sizeof xc);
                f[n] = fc;
            } else {
                shrink = 1;
            }
        }
        if (shrink) {
            /* shrink towards the best: x_i = x_best + (x_i - x_best) / 2 */
            for (int i = 1; i <= n; i++) {
                for (int j = 0; j < n; j++) s[i][j] = s[0][j] + 0.5 * (s[i][j] - s[0][j]);
                f[i] = eval(&k, s[i]);
            }
        }
        sort_simplex(n, s, f);
        if (cfg->progress) {
            double xb[BR_NM_MAX_DIM];
            to_x(cfg, s[0], xb);
            cfg->progress(user, it, k.nfev, xb, f[0], n);
        }
    }
    to_x(cfg, s[0], res->x);
    res->f = f[0];
    res->nfev = k.nfev;
    res->nit = it;
    res->converged = converged;
    return 0;
}
