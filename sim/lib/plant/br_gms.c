/* SPDX-License-Identifier: Apache-2.0 */
/* The plant's generalized Maxwell-slip friction: the elements' exact update
 * over a substep at held velocity. Equations in br_gms.h and
 * docs/modules/plant.md ("Maxwell-slip friction"). */
#include "br_gms.h"

#include <math.h>
#include <stddef.h>

#define FIN_POS(x) (isfinite(x) && (x) > 0.0)

const char *br_gms_check(const br_gms_cfg_t *g)
{
    if (g->n == 0) return NULL;
    if (g->n < 0 || g->n > BR_GMS_MAX) return "gms.n (must be in 0..BR_GMS_MAX)";
    if (g->clamp != 0 && g->clamp != 1) return "gms.clamp (must be 0 or 1)";
    if (g->clamp == 0 && !FIN_POS(g->C_mps)) return "gms.C_mps (must be > 0 with the slip law)";
    if (!(FIN_POS(g->delta) && g->delta <= 10.0)) return "gms.delta (must be in (0, 10])";
    double sum = 0.0;
    for (int i = 0; i < g->n; i++) {
        if (!FIN_POS(g->k_Npm[i])) return "gms.k_Npm (each must be > 0)";
        if (!FIN_POS(g->alpha[i])) return "gms.alpha (each must be > 0)";
        if (!(isfinite(g->sigma1_Nspm[i]) && g->sigma1_Nspm[i] >= 0.0)) return "gms.sigma1_Nspm (each must be >= 0)";
        sum += g->alpha[i];
    }
    if (!(fabs(sum - 1.0) <= BR_GMS_SHARE_TOL)) return "gms.alpha (the shares must sum to 1)";
    return NULL;
}

void br_gms_from_breakaway(br_gms_cfg_t *g, int n, const double d_m[], const double alpha[], double Fs_N,
                           double sigma1_Nspm)
{
    g->n = n;
    for (int i = 0; i < n && i < BR_GMS_MAX; i++) {
        g->alpha[i] = alpha[i];
        /* d_i = alpha_i Fs / k_i (presliding.md) */
        g->k_Npm[i] = alpha[i] * Fs_N / d_m[i];
        g->sigma1_Nspm[i] = sigma1_Nspm;
    }
}

void br_gms_damping_ratio(br_gms_cfg_t *g, double zeta, double Meff_kg)
{
    for (int i = 0; i < g->n && i < BR_GMS_MAX; i++) {
        /* sigma1_i = 2 zeta sqrt(k_i Meff): element i's mode on the moving mass at ratio zeta */
        g->sigma1_Nspm[i] = 2.0 * zeta * sqrt(g->k_Npm[i] * Meff_kg);
    }
}

/* Clamp limit: the integral over [0, h] of clamp(a + v t, -D, D), the path
 * of z <- clamp(z + dx) at the held velocity v: at the bound behind until the
 * line enters [-D, D], along it, then at the bound ahead. */
static double clamp_path_int(double a, double v, double h, double D)
{
    if (v == 0.0) return h * fmin(fmax(a, -D), D);
    const double ahead = copysign(D, v);
    const double t_in = fmin(fmax((-ahead - a) / v, 0.0), h);
    const double t_out = fmin(fmax((ahead - a) / v, 0.0), h);
    /* the linear piece by the trapezoid (exact for a line) */
    const double lin = 0.5 * (t_out - t_in) * ((a + v * t_in) + (a + v * t_out));
    return -ahead * t_in + lin + ahead * (h - t_out);
}

/* Slip law, one element moving at v != 0: a stick phase (dz/dt = v) until
 * sgn(v) z reaches D, then the slip phase's exact solution of
 * dz/dt = C alpha (sgn(v) - z / D) with D held. Returns the integral of z. */
static double slip_elem(double Ca, double D, double v, double h, double *z, int *slip)
{
    const int dir = v > 0.0 ? 1 : -1;
    const double zT = dir * D; /* the slip phase's target */
    double z0 = *z, t_st = 0.0, zint = 0.0;
    if (*slip != dir) {
        /* sticks: it was sticking, or the velocity changed sign */
        *slip = 0;
        const double t_hit = (D - dir * z0) / fabs(v);
        if (t_hit >= h) {
            *z = z0 + v * h;
            return 0.5 * h * (z0 + *z);
        }
        t_st = fmax(t_hit, 0.0);
        const double za = t_st > 0.0 ? zT : z0; /* beyond D already (D fell): slips from where it is */
        zint = 0.5 * t_st * (z0 + za);
        z0 = za;
        *slip = dir;
    }
    /* slip phase over tau: z = zT + (z0 - zT) e^{-lam t}, lam = C alpha / D */
    const double tau = h - t_st, lam = Ca / D;
    const double q = -expm1(-lam * tau); /* 1 - e^{-lam tau} */
    *z = z0 + (zT - z0) * q;
    return zint + zT * tau + (z0 - zT) * q / lam;
}

double br_gms_advance(const br_gms_cfg_t *g, const br_gms_state_t *x0, br_gms_state_t *x1, double v, double h,
                      double s_N)
{
    double imp = 0.0;
    for (int i = 0; i < g->n; i++) {
        /* Delta_i(v) = alpha_i s(v) / k_i */
        const double D = g->alpha[i] * s_N / g->k_Npm[i];
        const double z0 = x0->z_m[i];
        double zint;
        x1->slip[i] = x0->slip[i];
        if (g->clamp) {
            /* z <- clamp(z + dx, -Delta, Delta) */
            zint = clamp_path_int(z0, v, h, D);
            x1->z_m[i] = fmin(fmax(z0 + v * h, -D), D);
        } else if (v == 0.0) {
            /* at rest: sticks */
            x1->slip[i] = 0;
            x1->z_m[i] = z0;
            zint = z0 * h;
        } else {
            x1->z_m[i] = z0;
            zint = slip_elem(g->C_mps * g->alpha[i], D, v, h, &x1->z_m[i], &x1->slip[i]);
        }
        /* integral of k z + sigma1 dz/dt */
        imp += g->k_Npm[i] * zint + g->sigma1_Nspm[i] * (x1->z_m[i] - z0);
    }
    return imp;
}

double br_gms_force_N(const br_gms_cfg_t *g, const br_gms_state_t *x, double v, double s_N)
{
    double f = 0.0;
    for (int i = 0; i < g->n; i++) {
        const double D = g->alpha[i] * s_N / g->k_Npm[i];
        const double z = x->z_m[i];
        double zdot;
        if (g->clamp) {
            /* held at the bound it moves towards, else it follows the travel */
            zdot = (v > 0.0 && z >= D) || (v < 0.0 && z <= -D) ? 0.0 : v;
        } else if (v != 0.0 && x->slip[i] == (v > 0.0 ? 1 : -1)) {
            zdot = g->C_mps * g->alpha[i] * ((double)x->slip[i] - z / D);
        } else {
            zdot = v;
        }
        f += g->k_Npm[i] * z + g->sigma1_Nspm[i] * zdot;
    }
    return f;
}

/* the force of the loop's rising branch after travel x from steady sliding
 * in -x, as a fraction of Fs: sum_i alpha_i clamp(x / d_i - 1, -1, 1) */
static double rising_frac(const br_gms_cfg_t *g, double Fs_N, double x)
{
    double f = 0.0;
    for (int i = 0; i < g->n; i++) {
        const double d = g->alpha[i] * Fs_N / g->k_Npm[i];
        f += g->alpha[i] * fmin(fmax(x / d - 1.0, -1.0), 1.0);
    }
    return f;
}

double br_gms_presliding_m(const br_gms_cfg_t *g, double Fs_N)
{
    /* 90 % of the swing from -Fs to +Fs: F = 0.8 Fs; reached by x = 2 max d_i */
    double lo = 0.0, hi = 0.0;
    for (int i = 0; i < g->n; i++) hi = fmax(hi, 2.0 * g->alpha[i] * Fs_N / g->k_Npm[i]);
    for (int it = 0; it < 200; it++) {
        const double mid = 0.5 * (lo + hi);
        if (rising_frac(g, Fs_N, mid) < 0.8) lo = mid;
        else hi = mid;
    }
    return hi;
}
