/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the particle filter with Maxwell-slip elements (br_pf with
 * est.model.mslip, docs/modules/pf.md "Maxwell-slip elements") against the
 * float64 reference golden/ref/pf.py, through golden/traces/pf_ms.csv (input
 * and reference per step) and pf_ms_x.csv (the reference's particle set and
 * elements at the re-synchronisation points, with the next step's
 * resampling indices). Scheme and tolerances: docs/golden.md ("pf_ms").
 *
 * One step after each re-synchronisation: the C filter's state is set to the
 * reference's after step k (particles and elements, float32 as the trace
 * stores them, the force sum k_i e_i made by the C filter's own sum; origin,
 * noise position, outlier run, last fraction), it steps once with the input
 * of step k + 1; status, origin, noise position and outlier run must be
 * exact, the max log-weight within its bound, and where its own resampling
 * indices equal the reference's the mean state, the mean elements and F_hat
 * too. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bristle/br_encoder.h"
#include "bristle/br_pf.h"
#include "bristle_gen/est/br_noise_table.h"
#include "pf_bounds.h"
#include "trace_reader.h"

/* Rounding-chain factor of one particle-step (docs/golden.md, "pf_ms"): each
 * quantity is a chain of at most a dozen float32 operations (two passes of
 * the trapezoidal step, the noise, the clamp) on terms of the scale given. */
#define C_MS 32.0
#define NE_MAX BR_MSLIP_MAX

typedef struct {
    br_trace_t t, x;
    br_pf_cfg_t cfg;
    pf_consts_t c;
    int ne;
    double k[NE_MAX], cb[NE_MAX]; /* stiffness and share / k */
    double nmax;                  /* the largest |sample| of the ROM table */
} pfm_t;

static double col(const pfm_t *G, int k, const char *name)
{
    return br_trace_get(&G->t, k, br_trace_col(&G->t, name));
}

static void load_all(pfm_t *G)
{
    br_trace_load(&G->t, "pf_ms");
    br_trace_load(&G->x, "pf_ms_x");
    G->cfg = pf_golden_cfg(&G->t);
    G->c = pf_golden_consts(&G->t, &G->cfg);
    G->ne = (int)br_trace_meta_num(&G->t, "ms_n");
    assert_true(G->ne >= 1 && G->ne <= NE_MAX);
    double sh[NE_MAX];
    br_trace_meta_nums(&G->t, "ms_k_Npm", G->k, G->ne);
    br_trace_meta_nums(&G->t, "ms_share", sh, G->ne);
    /* the firmware's own number of passes is the reference's */
    assert_int_equal((int)br_trace_meta_num(&G->t, "ms_passes"), BR_MODEL_MS_PASSES);
    br_mslip_cfg_t *ms = &G->cfg.est.model.mslip;
    ms->n = G->ne;
    for (int i = 0; i < G->ne; i++) {
        ms->k_Npm[i] = (float)G->k[i];
        ms->share[i] = (float)sh[i];
        G->cb[i] = sh[i] / G->k[i];
    }
    G->nmax = 0.0;
    for (uint32_t i = 0; i < BR_NOISE_LEN; i++) {
        G->nmax = fmax(G->nmax, fabs((double)br_noise_table[i]));
    }
    assert_int_equal(G->x.nrows % (int)G->cfg.n_particles, 0);
}

static br_pf_t g_pf; /* ~100 KiB: static */

/* The C filter's state set to the reference's after step k (the set from
 * pf_ms_x.csv's rows from xrow on) */
static void resync(br_pf_t *pf, const pfm_t *G, int k, int xrow)
{
    const br_trace_t *x = &G->x;
    const char *names[BR_NX] = {"theta", "omega", "z", "gp"};
    const uint32_t m = pf->cfg.n_particles;
    for (uint32_t j = 0; j < m; j++) {
        const int r = xrow + (int)j;
        assert_int_equal((int)br_trace_get(x, r, br_trace_col(x, "k")), k);
        assert_int_equal((int)br_trace_get(x, r, br_trace_col(x, "j")), (int)j);
        for (int i = 0; i < BR_NX; i++) {
            pf->x[i][j] = (float)br_trace_get(x, r, br_trace_col(x, names[i]));
        }
        /* the filter carries the elements and their force sum k_i e_i (from 0, i in order) */
        float f = 0.0f;
        for (int i = 0; i < G->ne; i++) {
            char nm[4] = "e0";
            nm[1] = (char)('0' + i);
            const float e = (float)br_trace_get(x, r, br_trace_col(x, nm));
            pf->ms[(uint32_t)i * m + j] = e;
            f += pf->cfg.est.model.mslip.k_Npm[i] * e;
        }
        pf->kgp[j] = f;
    }
    pf->origin_counts = (int32_t)col(G, k, "origin_counts");
    pf->noise_pos = (uint32_t)col(G, k, "noise_pos");
    pf->n_outliers = (uint32_t)col(G, k, "n_outliers");
    pf->prev_frac = (float)col(G, k, "frac");
    pf->n_predicted = 0u;
}

/* The one-step bounds (docs/golden.md, "pf_ms"), from the scales of the
 * set before (xa: largest |theta|, |omega|) and after the step */
typedef struct {
    double th, om, g, e[NE_MAX], f;
} ms_tol_t;

static ms_tol_t one_step_bounds(const pfm_t *G, double th_max, double om_max, double u, double shift, int reanch)
{
    const pf_consts_t *c = &G->c;
    const double U = C_MS * U32, h = c->h, L = c->L, m = c->m;
    const double g_max = c->gp_max, n = G->nmax;
    const br_est_cfg_t *e = &G->cfg.est;
    double ksum = 0.0;
    for (int i = 0; i < G->ne; i++) {
        ksum += G->k[i];
    }
    ms_tol_t T;
    /* omega1 = omega0 + (u h - L^2 s2 dtheta - L h (f0 + f1) / 2) / Jeff, |f| <= g_p (the shares sum
     * to 1), each term rounded; f1's own error enters through dtheta with the gain
     * A = h^2 L^2 sum k / (2 Jeff) per pass */
    const double A = h * h * L * L * ksum / (2.0 * c->Jeff);
    const double S_om = om_max + h / c->Jeff * (fabs(u) + L * L * c->s2 * om_max + L * g_max) +
                        sqrt((double)e->q_var[BR_X_OMEGA]) * n;
    T.om = U * S_om * (1.0 + A) * (1.0 + A);
    /* dtheta = omega_m h */
    const double dth = h * om_max, ddth = h * T.om + U * dth;
    T.th = U * (th_max + dth + sqrt((double)e->q_var[BR_X_THETA]) * n + fabs(shift)) + ddth;
    T.g = U * g_max;
    /* e_i = clamp(clamp(e_i + L dtheta) + q_z n): each clamp 1-Lipschitz in its value and its
     * bound c_i g_p */
    double de_move = 0.0;
    if (reanch) {
        /* the re-anchoring's shift from a float32 sum of m thetas */
        const double d = C_SUM * m * U32 * th_max + T.th;
        T.th += d;
        T.om += C_SUM * m * U32 * om_max + T.om;
        de_move = L * d;
    }
    T.f = U * g_max;
    for (int i = 0; i < G->ne; i++) {
        const double ei = G->cb[i] * g_max;
        T.e[i] = L * ddth + U * (ei + L * dth + sqrt((double)e->q_var[BR_X_Z]) * n) + G->cb[i] * T.g + de_move;
        T.f += G->k[i] * T.e[i];
    }
    return T;
}

static void test_pf_ms_one_step(void **state)
{
    (void)state;
    pfm_t G;
    load_all(&G);
    br_pf_t *pf = &g_pf;
    assert_int_equal(br_pf_init(pf, &G.cfg), BR_OK);
    const uint32_t m = G.cfg.n_particles;
    const double rpc = G.cfg.est.rad_per_count;
    const int c_idx = br_trace_col(&G.x, "idx_next");
    const char *mean_names[BR_NX] = {"theta", "omega", "z", "gp"};
    br_errstat_t e_lmax, e_mean[BR_NX], e_el[NE_MAX], e_F;
    br_errstat_init(&e_lmax, "lmax", "");
    br_errstat_init(&e_mean[0], "theta", "rad");
    br_errstat_init(&e_mean[1], "omega", "rad/s");
    br_errstat_init(&e_mean[2], "z", "m");
    br_errstat_init(&e_mean[3], "gp", "N");
    static char el_names[NE_MAX][4];
    for (int i = 0; i < G.ne; i++) {
        memcpy(el_names[i], "em0", 4);
        el_names[i][2] = (char)('0' + i);
        br_errstat_init(&e_el[i], el_names[i], "m");
    }
    br_errstat_init(&e_F, "F_hat", "N");

    /* priming: the C filter's own */
    const br_meas_t y0 = {(int32_t)col(&G, 0, "counts"), (float)col(&G, 0, "frac")};
    assert_int_equal(br_pf_step(pf, &y0, (float)col(&G, 0, "u_prev_Nm")), BR_OK);
    long n_steps = 0, bad_exact = 0, n_outlier = 0, n_reanch = 0, n_own_equal = 0;
    for (int xrow = 0; xrow < G.x.nrows; xrow += (int)m) {
        const int k = (int)br_trace_get(&G.x, xrow, br_trace_col(&G.x, "k")), k1 = k + 1;
        resync(pf, &G, k, xrow);
        double th_max = 0.0, om_max = 0.0;
        for (uint32_t j = 0; j < m; j++) {
            th_max = fmax(th_max, fabs((double)pf->x[BR_X_THETA][j]));
            om_max = fmax(om_max, fabs((double)pf->x[BR_X_OMEGA][j]));
        }
        const br_meas_t y = {(int32_t)col(&G, k1, "counts"), (float)col(&G, k1, "frac")};
        const double u = col(&G, k1, "u_prev_Nm");
        const br_status_t st = br_pf_step(pf, &y, (float)u);
        n_steps++;
        const int reanch = col(&G, k1, "reanchored") != 0.0;
        n_reanch += reanch;
        n_outlier += col(&G, k1, "status") == (double)BR_W_OUTLIER;
        if ((double)st != col(&G, k1, "status") || (double)pf->origin_counts != col(&G, k1, "origin_counts") ||
            (double)pf->noise_pos != col(&G, k1, "noise_pos") ||
            (double)pf->n_outliers != col(&G, k1, "n_outliers")) {
            if (bad_exact++ < 5) {
                print_error("%s:%d: step %d: status %d, origin %d, noise_pos %u, outliers %u; expected %.0f, %.0f, "
                            "%.0f, %.0f\n",
                            G.t.path, G.t.line[k1], k1, (int)st, (int)pf->origin_counts, (unsigned)pf->noise_pos,
                            (unsigned)pf->n_outliers, col(&G, k1, "status"), col(&G, k1, "origin_counts"),
                            col(&G, k1, "noise_pos"), col(&G, k1, "n_outliers"));
            }
        }
        for (uint32_t j = 0; j < m; j++) {
            th_max = fmax(th_max, fabs((double)pf->x[BR_X_THETA][j]));
            om_max = fmax(om_max, fabs((double)pf->x[BR_X_OMEGA][j]));
        }
        const double shift = (double)br_counts_delta(y.counts, (int32_t)col(&G, k, "origin_counts")) * rpc;
        const ms_tol_t T = one_step_bounds(&G, th_max, om_max, u, shift, reanch);
        const double lmax_t = col(&G, k1, "lmax");
        br_errstat_add(&e_lmax, &G.t, k1, (double)pf->lmax, lmax_t, dlog_bound(&G.c, lmax_t, T.th));
        /* the estimate, where the C filter resampled as the reference did */
        int own_equal = 1;
        for (uint32_t j = 0; j < m; j++) {
            own_equal &= (double)pf->idx[j] == br_trace_get(&G.x, xrow + (int)j, c_idx);
        }
        if (!own_equal) {
            continue;
        }
        n_own_equal++;
        br_pf_stats_t ps;
        assert_int_equal(br_pf_stats(pf, &ps), BR_OK);
        const double tol_x[BR_NX] = {T.th + C_SUM * m * U32 * th_max, T.om + C_SUM * m * U32 * om_max, 0.0,
                                     T.g + C_SUM * m * U32 * G.c.gp_max};
        for (int i = 0; i < BR_NX; i++) {
            br_errstat_add(&e_mean[i], &G.t, k1, (double)ps.mean[i], col(&G, k1, mean_names[i]), tol_x[i]);
        }
        for (int i = 0; i < G.ne; i++) {
            float s = 0.0f;
            for (uint32_t j = 0; j < m; j++) {
                s += pf->ms[(uint32_t)i * m + j];
            }
            br_errstat_add(&e_el[i], &G.t, k1, (double)(s / (float)m), col(&G, k1, el_names[i]),
                           T.e[i] + C_SUM * m * U32 * G.cb[i] * G.c.gp_max);
        }
        br_errstat_add(&e_F, &G.t, k1, (double)pf->est.F_hat_N, col(&G, k1, "F_hat"),
                       T.f + C_SUM * m * U32 * G.c.gp_max);
    }
    print_message("golden pf_ms      %ld one-step comparisons (%ld outliers, %ld re-anchorings), %u particles; "
                  "own indices == trace on %ld\n",
                  n_steps, n_outlier, n_reanch, m, n_own_equal);
    br_errstat_t *all[NE_MAX + 6] = {&e_lmax, &e_mean[0], &e_mean[1], &e_mean[2], &e_mean[3], &e_F};
    int n_all = 6;
    for (int i = 0; i < G.ne; i++) {
        all[n_all++] = &e_el[i];
    }
    pf_golden_report(all, n_all, &G.t, &G.x, "pf_ms", bad_exact, "status / origin / noise position / outlier run");
    /* the trace must exercise what it is for */
    assert_true(n_reanch >= 1);
    assert_true(n_own_equal * 2 > n_steps);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pf_ms_one_step),
    };
    return cmocka_run_group_tests_name("golden_pf_ms", tests, NULL, NULL);
}
