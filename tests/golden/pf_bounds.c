/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's golden tests' shared parts (pf_bounds.h). */
#include "pf_bounds.h"

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bristle_gen/est/br_noise_table.h"

uint32_t pf_fnv1a_table(const float *t, uint32_t n)
{
    uint32_t h = 2166136261u;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t w;
        memcpy(&w, &t[i], sizeof w);
        for (int s = 0; s < 32; s += 8) {
            h ^= (w >> s) & 0xFFu;
            h *= 16777619u;
        }
    }
    return h;
}

br_pf_cfg_t pf_golden_cfg(const br_trace_t *t)
{
    double s0[BR_NX];
    br_trace_meta_nums(t, "x0_std", s0, BR_NX);
    br_pf_cfg_t c;
    memset(&c, 0, sizeof c);
    c.est = br_trace_est_cfg(t);
    c.n_particles = (uint32_t)br_trace_meta_num(t, "n_particles");
    for (int i = 0; i < BR_NX; i++) c.x0_std[i] = (float)s0[i];
    c.noise = br_noise_table;
    c.noise_len = BR_NOISE_LEN;
    c.noise_skip = (uint32_t)br_trace_meta_num(t, "noise_skip");
    assert_true(c.n_particles >= 1u && c.n_particles <= BR_PF_MAX_PARTICLES);
    assert_int_equal((int)br_trace_meta_num(t, "w_bits"), (int)BR_PF_W_BITS);
    /* the ROM table the reference used is the one linked here */
    assert_int_equal((uint32_t)br_trace_meta_num(t, "noise_len"), BR_NOISE_LEN);
    assert_int_equal((uint32_t)br_trace_meta_num(t, "noise_fnv1a"), pf_fnv1a_table(br_noise_table, BR_NOISE_LEN));
    return c;
}

pf_consts_t pf_golden_consts(const br_trace_t *t, const br_pf_cfg_t *cfg)
{
    pf_consts_t c;
    c.h = cfg->est.model.dt_s;
    c.L = br_trace_meta_num(t, "L_mprad");
    c.Jeff = br_trace_meta_num(t, "J_kgm2") + c.L * c.L * br_trace_meta_num(t, "M_kg");
    c.s0 = br_trace_meta_num(t, "sigma0_Npm");
    c.s1 = br_trace_meta_num(t, "sigma1_Nspm");
    c.s2 = br_trace_meta_num(t, "sigma2_Nspm");
    c.R = cfg->est.r_var_rad2;
    c.sig_R = sqrt(c.R);
    c.gp_max = cfg->est.gp_max_N;
    c.m = cfg->n_particles;
    return c;
}

void step_scales(const pf_consts_t *c, const double *xa, const double *xb, double u, double shift,
                 double S[BR_NX])
{
    double x[BR_NX];
    for (int i = 0; i < BR_NX; i++) {
        x[i] = fmax(fabs(xa[i]), fabs(xb[i]));
    }
    /* theta: the particles lie within a few sqrt(R) of the measurement */
    S[0] = x[0] + 5.0 * c->sig_R + c->h * x[1] + fabs(shift);
    /* omega: as the model golden test, with the largest g_p of any particle */
    S[1] = x[1] + c->h / c->Jeff *
                      (fabs(u) + c->L * (fmax(c->s0 * x[2], c->gp_max) + (2.0 * c->s1 + c->s2) * c->L * x[1]));
    S[2] = fmax(x[2], c->gp_max / c->s0);
    S[3] = c->gp_max;
}

void drift_seed(drift_t *d, const double S[BR_NX])
{
    for (int i = 0; i < BR_NX; i++) {
        d->d[i] = 4.0 * U32 * S[i];
    }
    d->n = 0;
}

void drift_advance(drift_t *d, const pf_consts_t *c, const double S[BR_NX])
{
    const double dth = d->d[0], dom = d->d[1], dz = d->d[2], dgp = d->d[3];
    d->d[0] = dth + c->h * dom + C_THETA * U32 * S[0];
    d->d[1] = dom + C_OMEGA * U32 * S[1];
    d->d[2] = dz + 2.0 * c->h * c->L * dom + C_Z * U32 * S[2];
    d->d[3] = dgp + C_GP * U32 * S[3];
    d->n++;
}

double dlog_bound(const pf_consts_t *c, double l, double dth)
{
    const double e = sqrt(2.0 * c->R * fabs(l));
    return (2.0 * e * dth + dth * dth) / (2.0 * c->R) + C_L * U32 * fabs(l);
}

double dfnl_bound(const pf_consts_t *c, const float *x, const double *d)
{
    /* f_nl = s0 z + s1 L w (1 - s0 sgn(w) z / g_p) */
    const double w = fabs(x[1]), z = fabs(x[2]), gp = x[3];
    const double a = c->s0 * c->L * w / gp;
    const double S_f = c->s0 * z + c->s1 * c->L * w * (1.0 + c->s0 * z / gp);
    return (c->s0 + c->s1 * a) * d[2] + c->s1 * c->L * (1.0 + c->s0 * z / gp) * d[1] + c->s1 * a * z / gp * d[3] +
           C_FNL * U32 * S_f;
}

void pf_golden_report(br_errstat_t *const *all, int n, br_trace_t *t, br_trace_t *x, const char *trace,
                      long bad_exact, const char *what)
{
    long fails = 0;
    for (int i = 0; i < n; i++) {
        br_errstat_print(all[i], t, trace);
        fails += all[i]->n_fail;
    }
    br_trace_free(t);
    br_trace_free(x);
    if (bad_exact != 0) {
        fail_msg("%s: %ld steps with a wrong %s", trace, bad_exact, what);
    }
    if (fails != 0) {
        fail_msg("%s: %ld comparisons outside tolerance (first lines printed above)", trace, fails);
    }
}
