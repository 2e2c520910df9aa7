/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the particle filter's shared external force (br_pf with
 * cfg.load, firmware/pf/br_pf_load.c) against the float64 reference
 * golden/ref/pf.py, through golden/traces/pf_load.csv (input and reference
 * per step) and pf_load_x.csv (the reference's particle set at the
 * re-synchronisation points, with the next step's resampling indices), and
 * through pf_glitch.csv / pf_glitch_x.csv (the same with est_input's encoder
 * faults kept: each glitch re-acquired and undone at the next step). The
 * configuration comes from the trace header. Scheme and tolerances:
 * docs/golden.md ("pf_load").
 *
 * One step after each re-synchronisation: the C filter's state is set to the
 * reference's after step k (particles, float32 as the trace stores them;
 * origin, noise position, outlier run, last fraction, F_d and the common
 * error's covariance P and the re-acquisition kept for its undo,
 * float32-rounded), it steps once with the input of step k + 1, and its
 * status, origin, noise position, outlier run, re-acquisition and undo
 * (exact), F_d, P and the max log-weight (within a propagated
 * bound) are compared; the mean state and F_hat too when its own resampling
 * indices equal the reference's (a float32 and a float64 filter may resample
 * differently where a systematic point lies on a weight boundary: reported). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bristle/br_encoder.h"
#include "bristle/br_pf.h"
#include "pf_bounds.h"
#include "trace_reader.h"

/* Rounding-chain factor of the common error's Kalman filter (docs/golden.md,
 * "pf_load"): each of the tick, the inflation, the gain and the update is a
 * handful of float32 products and sums of terms of the scale given there. */
#define C_KF 16.0

static const char *const P_NAMES[6] = {"00", "01", "02", "11", "12", "22"};
/* (i, j) of the upper triangle's entries, in P_NAMES' order */
static const int P_I[6] = {0, 0, 0, 1, 1, 2}, P_J[6] = {0, 1, 2, 1, 2, 2};

static int tri(int i, int j) /* index of P[i][j] in the upper triangle */
{
    if (i > j) {
        const int t = i;
        i = j;
        j = t;
    }
    return (i == 0) ? j : (i == 1) ? 2 + j : 5;
}

typedef struct {
    br_trace_t t, x;
    br_pf_cfg_t cfg;
    pf_consts_t c;
    double g, max_N;
    int c_P[6], c_Pm[6], c_altP[6];
} pfl_t;

static void load_all(pfl_t *G, const char *name)
{
    char xname[32];
    strcpy(xname, name);
    strcat(xname, "_x");
    br_trace_load(&G->t, name);
    br_trace_load(&G->x, xname);
    G->cfg = pf_golden_cfg(&G->t);
    G->cfg.load.q_N2 = (float)br_trace_meta_num(&G->t, "load_q_N2");
    G->cfg.load.max_N = (float)br_trace_meta_num(&G->t, "load_max_N");
    G->c = pf_golden_consts(&G->t, &G->cfg);
    G->g = G->c.L * G->c.h * G->c.h / (2.0 * G->c.Jeff);
    G->max_N = G->cfg.load.max_N;
    for (int i = 0; i < 6; i++) {
        char n[8] = "P", nm[8] = "Pm", na[8] = "alt_P";
        strcat(n, P_NAMES[i]);
        strcat(nm, P_NAMES[i]);
        strcat(na, P_NAMES[i]);
        G->c_P[i] = br_trace_col(&G->t, n);
        G->c_Pm[i] = br_trace_col(&G->t, nm);
        G->c_altP[i] = br_trace_col(&G->t, na);
    }
    assert_int_equal(G->x.nrows % (int)G->cfg.n_particles, 0);
}

static double col(const pfl_t *G, int k, const char *name)
{
    return br_trace_get(&G->t, k, br_trace_col(&G->t, name));
}

/* Bounds on the errors of the common error's filter in one step (the
 * first-order propagation of docs/golden.md, "pf_load"), from the reference's
 * values of rows k (before) and k + 1 and the particles' bound D after the
 * prediction; D's theta and omega grow by the cloud's move. */
typedef struct {
    double P[6], Fd;
} kf_tol_t;

static kf_tol_t kf_bounds(const pfl_t *G, int k, drift_t *D)
{
    const pf_consts_t *c = &G->c;
    const int k1 = k + 1;
    const double h = c->h, g = G->g, a = 2.0 * g / h;
    const double absPhi[3][3] = {{1.0, h, g}, {0.0, 1.0, a}, {0.0, 0.0, 1.0}};
    /* an undo at k + 1 predicts P from the re-acquisition's P as predicted (alt_P of row k)
     * instead of P after step k */
    const int undo = col(G, k1, "load_undo") != 0.0;
    double P0[3][3], Pm[3][3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            P0[i][j] = fabs(br_trace_get(&G->t, k, (undo ? G->c_altP : G->c_P)[tri(i, j)]));
            Pm[i][j] = br_trace_get(&G->t, k1, G->c_Pm[tri(i, j)]);
        }
    }
    /* the tick: P rounded to float32, then |Phi| |P| |Phi|^T is the scale of Phi P Phi^T's roundings */
    double dPm[3][3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int p = 0; p < 3; p++) {
                for (int q = 0; q < 3; q++) {
                    s += absPhi[i][p] * P0[p][q] * absPhi[j][q];
                }
            }
            dPm[i][j] = C_KF * U32 * (s + ((i == 2 && j == 2) ? G->cfg.load.q_N2 : 0.0));
        }
    }
    /* the cloud's mean innovation d and spread v from the sums of e_j = theta_j - y and e_j^2
     * over the m particles, every theta_j off by D_theta: a float32 sum of m terms is off by
     * m u times the sum of their magnitudes, sum |e_j| <= m E and sum e_j^2 = m E^2 with E the
     * RMS of e_j, sqrt(v + d^2). An undo moved every theta_j by -(Phi e)_theta (+ nu1 for a
     * slip) and omega_j by -(Phi e)_omega first: e and nu1 float32-rounded from row k, the
     * shift's few products and sums */
    if (undo) {
        const double e0 = fabs(col(G, k, "alt_e0")), e1 = fabs(col(G, k, "alt_e1")), e2 = fabs(col(G, k, "alt_e2"));
        const double nu1 = fabs(col(G, k, "alt_nu1"));
        D->d[0] += C_KF * U32 * (e0 + h * e1 + g * e2 + nu1);
        D->d[1] += C_KF * U32 * (e1 + a * e2);
    }
    const double d = col(G, k1, "innov_d"), v = col(G, k1, "spread_v"), m = c->m;
    const double E = sqrt(v + d * d);
    const double dd = D->d[0] + C_SUM * m * U32 * E;
    const double dv = 2.0 * E * D->d[0] + D->d[0] * D->d[0] + 2.0 * fabs(d) * dd + dd * dd + C_SUM * m * U32 * E * E;
    /* a re-acquisition: P += dF^2 b b^T, dF = d / g (k = 1), off by dd / g and g's own rounding */
    if (col(G, k1, "load_acq") != 0.0) {
        const double dF = fabs(d) / g, ddF = dd / g + 4.0 * U32 * dF;
        const double b[3] = {g, a, 1.0};
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++) {
                dPm[i][j] += (2.0 * dF * ddF + C_KF * U32 * dF * dF) * b[i] * b[j];
            }
        }
    }
    /* S = Pm00 + v + R + rpc^2/12, K = Pm[:, 0] / S */
    const double r_gate = c->R + (double)G->cfg.est.rad_per_count * G->cfg.est.rad_per_count / 12.0;
    const double S = Pm[0][0] + fmax(v, 0.0) + r_gate;
    const double dS = dPm[0][0] + dv + C_KF * U32 * S;
    double K[3], dK[3];
    for (int i = 0; i < 3; i++) {
        K[i] = Pm[i][0] / S;
        dK[i] = dPm[i][0] / S + fabs(Pm[i][0]) * dS / (S * S) + C_KF * U32 * fabs(K[i]);
    }
    kf_tol_t T;
    /* P <- Pm - K Pm[0, :] */
    for (int e = 0; e < 6; e++) {
        const int i = P_I[e], j = P_J[e];
        T.P[e] = dPm[i][j] + dK[i] * fabs(Pm[0][j]) + fabs(K[i]) * dPm[0][j] +
                 C_KF * U32 * (fabs(Pm[i][j]) + fabs(K[i] * Pm[0][j]));
    }
    /* F_d <- clamp(F_d + K2 nu), nu = -d (after an undo's F_d - e2); the clamp is 1-Lipschitz */
    const double Fd0 = fabs(col(G, k, "Fd")) + (undo ? fabs(col(G, k, "alt_e2")) : 0.0);
    T.Fd = U32 * Fd0 + fabs(K[2]) * dd + fabs(d) * dK[2] + C_KF * U32 * (Fd0 + fabs(K[2] * d));
    /* the cloud moved by K0 nu and K1 nu */
    D->d[0] += fabs(K[0]) * dd + fabs(d) * dK[0] + C_KF * U32 * fabs(K[0] * d);
    D->d[1] += fabs(K[1]) * dd + fabs(d) * dK[1] + C_KF * U32 * fabs(K[1] * d);
    return T;
}

static br_pf_t g_pf; /* ~70 KiB: static */

/* The C filter's state set to the reference's after step k (the set from
 * pf_load_x.csv's rows from xrow on) */
static void resync(br_pf_t *pf, const pfl_t *G, int k, int xrow)
{
    const br_trace_t *x = &G->x;
    const char *names[BR_NX] = {"theta", "omega", "z", "gp"};
    for (uint32_t j = 0; j < pf->cfg.n_particles; j++) {
        const int r = xrow + (int)j;
        assert_int_equal((int)br_trace_get(x, r, br_trace_col(x, "k")), k);
        assert_int_equal((int)br_trace_get(x, r, br_trace_col(x, "j")), (int)j);
        for (int i = 0; i < BR_NX; i++) {
            pf->x[i][j] = (float)br_trace_get(x, r, br_trace_col(x, names[i]));
        }
        /* the filter carries sigma0 L / g_p with g_p */
        pf->kgp[j] = (pf->cfg.est.model.lugre.sigma0_Npm * pf->cfg.est.model.lead_mprad) / pf->x[BR_X_GP][j];
    }
    pf->origin_counts = (int32_t)col(G, k, "origin_counts");
    pf->noise_pos = (uint32_t)col(G, k, "noise_pos");
    pf->n_outliers = (uint32_t)col(G, k, "n_outliers");
    pf->prev_frac = (float)col(G, k, "frac");
    pf->n_predicted = 0u;
    pf->load_N = (float)col(G, k, "Fd");
    pf->load_comp_N = (float)col(G, k, "Fd_comp");
    for (int e = 0; e < 6; e++) {
        pf->load_P[e] = (float)br_trace_get(&G->t, k, G->c_P[e]);
        pf->load_alt_P[e] = (float)br_trace_get(&G->t, k, G->c_altP[e]);
    }
    pf->load_alt = col(G, k, "alt") != 0.0;
    pf->load_alt_e[0] = (float)col(G, k, "alt_e0");
    pf->load_alt_e[1] = (float)col(G, k, "alt_e1");
    pf->load_alt_e[2] = (float)col(G, k, "alt_e2");
    pf->load_alt_nu1 = (float)col(G, k, "alt_nu1");
}

/* One trace's one-step comparisons; returns the re-acquisitions and undos it holds
 * (acq_undo[0], [1]) */
static void one_step(const char *name, long acq_undo[2])
{
    pfl_t G;
    load_all(&G, name);
    br_pf_t *pf = &g_pf;
    assert_int_equal(br_pf_init(pf, &G.cfg), BR_OK);
    const uint32_t m = G.cfg.n_particles;
    const double rpc = G.cfg.est.rad_per_count;
    const int c_idx = br_trace_col(&G.x, "idx_next");
    const char *mean_names[BR_NX] = {"theta", "omega", "z", "gp"};
    br_errstat_t e_P[6], e_Fd, e_lmax, e_mean[BR_NX], e_F;
    for (int e = 0; e < 6; e++) {
        static char nm[6][8];
        strcpy(nm[e], "P");
        strcat(nm[e], P_NAMES[e]);
        br_errstat_init(&e_P[e], nm[e], "");
    }
    br_errstat_init(&e_Fd, "Fd", "N");
    br_errstat_init(&e_lmax, "lmax", "");
    br_errstat_init(&e_mean[0], "theta", "rad");
    br_errstat_init(&e_mean[1], "omega", "rad/s");
    br_errstat_init(&e_mean[2], "z", "m");
    br_errstat_init(&e_mean[3], "gp", "N");
    br_errstat_init(&e_F, "F_hat", "N");

    /* priming: the C filter's own */
    const br_meas_t y0 = {(int32_t)col(&G, 0, "counts"), (float)col(&G, 0, "frac")};
    assert_int_equal(br_pf_step(pf, &y0, (float)col(&G, 0, "u_prev_Nm")), BR_OK);
    long n_steps = 0, bad_exact = 0, n_acq = 0, n_undo = 0, n_outlier = 0, n_own_equal = 0;
    for (int xrow = 0; xrow < G.x.nrows; xrow += (int)m) {
        const int k = (int)br_trace_get(&G.x, xrow, br_trace_col(&G.x, "k")), k1 = k + 1;
        resync(pf, &G, k, xrow);
        const uint32_t acq0 = pf->n_load_acq, undo0 = pf->n_load_undo;
        const br_meas_t y = {(int32_t)col(&G, k1, "counts"), (float)col(&G, k1, "frac")};
        const double u = col(&G, k1, "u_prev_Nm");
        const br_status_t st = br_pf_step(pf, &y, (float)u);
        n_steps++;
        const int acq = (int)col(&G, k1, "load_acq"), undo = (int)col(&G, k1, "load_undo");
        n_acq += acq;
        n_undo += undo;
        n_outlier += col(&G, k1, "status") == (double)BR_W_OUTLIER;
        if ((double)st != col(&G, k1, "status") || (double)pf->origin_counts != col(&G, k1, "origin_counts") ||
            (double)pf->noise_pos != col(&G, k1, "noise_pos") ||
            (double)pf->n_outliers != col(&G, k1, "n_outliers") || (int)(pf->n_load_acq - acq0) != acq ||
            (int)(pf->n_load_undo - undo0) != undo) {
            if (bad_exact++ < 5) {
                print_error("%s:%d: step %d: status %d, origin %d, noise_pos %u, outliers %u, re-acquired %d, "
                            "undone %d; expected %.0f, %.0f, %.0f, %.0f, %d, %d\n",
                            G.t.path, G.t.line[k1], k1, (int)st, (int)pf->origin_counts, (unsigned)pf->noise_pos,
                            (unsigned)pf->n_outliers, (int)(pf->n_load_acq - acq0), (int)(pf->n_load_undo - undo0),
                            col(&G, k1, "status"), col(&G, k1, "origin_counts"), col(&G, k1, "noise_pos"),
                            col(&G, k1, "n_outliers"), acq, undo);
            }
        }
        /* the particles' bound: a float32 copy of the reference's set, one prediction with the
         * torque u - L F_d */
        double xa[BR_NX], xb[BR_NX], S[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xa[i] = col(&G, k, mean_names[i]);
            xb[i] = col(&G, k1, mean_names[i]);
        }
        drift_t D;
        step_scales(&G.c, xa, xa, 0.0, 0.0, S);
        drift_seed(&D, S);
        const double shift = (double)br_counts_delta(y.counts, (int32_t)col(&G, k, "origin_counts")) * rpc;
        step_scales(&G.c, xa, xb, fabs(u) + G.c.L * fabs(col(&G, k, "Fd")), shift, S);
        drift_advance(&D, &G.c, S);
        /* the common error's filter; an outlier that is no load has no update */
        const int updated = acq || col(&G, k1, "status") == (double)BR_OK;
        kf_tol_t T = {{0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, U32 * fabs(col(&G, k, "Fd"))};
        if (updated) {
            T = kf_bounds(&G, k, &D);
        }
        for (int e = 0; e < 6; e++) {
            br_errstat_add(&e_P[e], &G.t, k1, (double)pf->load_P[e], br_trace_get(&G.t, k1, G.c_P[e]), T.P[e]);
        }
        br_errstat_add(&e_Fd, &G.t, k1, (double)pf->load_N, col(&G, k1, "Fd"), T.Fd);
        const double lmax_t = col(&G, k1, "lmax");
        br_errstat_add(&e_lmax, &G.t, k1, (double)pf->lmax, lmax_t, dlog_bound(&G.c, lmax_t, D.d[0]));
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
        double xmax[BR_NX] = {0.0, 0.0, 0.0, 0.0}, fmax_ = 0.0, dF = 0.0;
        for (uint32_t j = 0; j < m; j++) {
            float xj[BR_NX];
            for (int i = 0; i < BR_NX; i++) {
                xj[i] = pf->x[i][j];
                xmax[i] = fmax(xmax[i], fabs((double)xj[i]));
            }
            fmax_ = fmax(fmax_, fabs((double)pf->fnl[pf->idx[j]]));
            dF = fmax(dF, dfnl_bound(&G.c, xj, D.d));
        }
        for (int i = 0; i < BR_NX; i++) {
            br_errstat_add(&e_mean[i], &G.t, k1, (double)ps.mean[i], xb[i],
                           D.d[i] + C_SUM * (double)m * U32 * xmax[i]);
        }
        /* the notch y = (1 + r)/2 (F_d + F_d') - r y' (0 <= r < 1, so both weights <= 1): F_d's
         * bound, F_d' and y' float32-rounded from the trace, the rounding of its three terms */
        const double fd0 = fabs(col(&G, k, "Fd")), yc0 = fabs(col(&G, k, "Fd_comp"));
        const double dy = T.Fd + U32 * (fd0 + yc0) + C_KF * U32 * (fabs(col(&G, k1, "Fd")) + fd0 + yc0);
        /* F_hat = clamp(mean f_nl + y): f_nl's bound, the sum's rounding, y's bound */
        br_errstat_add(&e_F, &G.t, k1, (double)pf->est.F_hat_N, col(&G, k1, "F_hat"),
                       dF + C_SUM * (double)m * U32 * fmax_ + dy + 2.0 * U32 * G.max_N);
    }
    print_message("golden %-10s %ld one-step comparisons (%ld re-acquisitions, %ld undone, %ld outliers), "
                  "%u particles; own indices == trace on %ld\n",
                  name, n_steps, n_acq, n_undo, n_outlier, m, n_own_equal);
    br_errstat_t *all[] = {&e_Fd, &e_P[0], &e_P[1], &e_P[2], &e_P[3], &e_P[4], &e_P[5], &e_lmax,
                           &e_mean[0], &e_mean[1], &e_mean[2], &e_mean[3], &e_F};
    pf_golden_report(all, (int)(sizeof all / sizeof all[0]), &G.t, &G.x, name, bad_exact,
                     "status / origin / noise position / outlier run / re-acquisition / undo");
    assert_true(n_own_equal * 2 > n_steps);
    acq_undo[0] = n_acq;
    acq_undo[1] = n_undo;
}

static void test_pf_load_one_step(void **state)
{
    (void)state;
    long n[2];
    one_step("pf_load", n);
    /* the trace must exercise what it is for: the load step's re-acquisitions, none undone */
    assert_true(n[0] >= 2);
    assert_int_equal(n[1], 0);
}

/* docs/modules/pf.md, "A glitch is not a load": est_input's spike and slip each re-acquired
 * and undone at the next step */
static void test_pf_glitch_one_step(void **state)
{
    (void)state;
    long n[2];
    one_step("pf_glitch", n);
    assert_true(n[0] >= 4);
    assert_int_equal(n[1], 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pf_load_one_step),
        cmocka_unit_test(test_pf_glitch_one_step),
    };
    return cmocka_run_group_tests_name("golden_pf_load", tests, NULL, NULL);
}
