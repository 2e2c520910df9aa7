/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the particle filter br_pf (float32) against the float64
 * reference golden/ref/pf.py, through golden/traces/est_input.csv (the
 * recorded closed-loop input), pf.csv (status, origin, noise position, max
 * log-weight, estimate per step), pf_w.csv (integer weights W and resampling
 * indices per step) and pf_x.csv (the particle set every 10th step). The
 * configuration comes from the trace header. Scheme and tolerances:
 * docs/golden.md.
 *
 * (a) br_pf_resample_idx on the trace's W gives the trace's indices exactly,
 *     step by step.
 * (b) The C filter runs the recorded input. A float32 and a float64 filter
 *     that resample independently drift apart after the first index that
 *     flips at a boundary, so the test keeps the C filter on the reference's
 *     ancestry: after every br_pf_step whose own indices differ from the
 *     trace's, the harness rebuilds the resampled set from the trace's
 *     indices out of the predicted set (the filter predicts and resamples in
 *     place; the harness gets the predicted set from br_pf_predict on a copy
 *     of the filter taken before the step, with theta moved to the step's new
 *     origin as br_pf_step does for a valid particle)
 *     and recomputes the estimate from it the way br_pf.h defines it. The
 *     particle states themselves drift apart too (every particle carries the
 *     rounding of its whole ancestry, and the model is locally expanding), so
 *     every 10th step the C set is compared with the reference's and then
 *     replaced by it. W, the estimate, the statuses and the particles are
 *     compared against a propagated error bound.
 * (c) The fraction of steps on which the C filter's own indices equal the
 *     trace's is reported. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bristle_gen/est/br_noise_table.h"
#include "bristle/br_encoder.h"
#include "bristle/br_model.h"
#include "bristle/br_pf.h"
#include "pf_bounds.h"
#include "trace_reader.h"

typedef struct {
    br_trace_t in, pf, w, x;
    br_pf_cfg_t cfg;
    uint32_t m;
    int nsteps;
} pf_golden_t;

static void load_all(pf_golden_t *g)
{
    br_trace_load(&g->in, "est_input");
    br_trace_load(&g->pf, "pf");
    br_trace_load(&g->w, "pf_w");
    br_trace_load(&g->x, "pf_x");
    g->cfg = pf_golden_cfg(&g->pf);
    g->m = g->cfg.n_particles;
    g->nsteps = g->pf.nrows;
    /* one input row and one pf row per step, (steps - 1) m / block W rows */
    assert_int_equal(g->in.nrows, g->nsteps);
    const int block = (g->w.ncols - 2) / 2;
    assert_true(block >= 1 && g->m % (uint32_t)block == 0u);
    assert_int_equal(g->w.nrows, (g->nsteps - 1) * (int)(g->m / (uint32_t)block));
}

static void free_all(pf_golden_t *g)
{
    br_trace_free(&g->in);
    br_trace_free(&g->pf);
    br_trace_free(&g->w);
    br_trace_free(&g->x);
}

/* W and idx of step k (k >= 1) from pf_w.csv. */
static void step_w(const pf_golden_t *g, int k, uint32_t *W, uint16_t *idx)
{
    const int block = (g->w.ncols - 2) / 2;
    const int per_step = (int)g->m / block;
    const int ck = br_trace_col(&g->w, "k"), cj = br_trace_col(&g->w, "j0");
    const int cw0 = br_trace_col(&g->w, "W0"), ci0 = br_trace_col(&g->w, "idx0");
    for (int b = 0; b < per_step; b++) {
        const int r = (k - 1) * per_step + b;
        assert_int_equal((int)br_trace_get(&g->w, r, ck), k);
        const int j0 = (int)br_trace_get(&g->w, r, cj);
        assert_int_equal(j0, b * block);
        for (int i = 0; i < block; i++) {
            const double wv = br_trace_get(&g->w, r, cw0 + i), iv = br_trace_get(&g->w, r, ci0 + i);
            assert_true(wv >= 0.0 && wv <= 65536.0 && iv >= 0.0 && iv < (double)g->m);
            W[j0 + i] = (uint32_t)wv;
            idx[j0 + i] = (uint16_t)iv;
        }
    }
}

/* The smallest distance, in weight units, from a systematic point t_i to the
 * edge of the interval [C_{j-1}, C_j) it falls in: a perturbation of the W
 * smaller than this cannot move an index (apart from the shift of t_i itself
 * with C_m, at most |dC_m|). */
static uint64_t resample_margin(const uint32_t *W, uint32_t m)
{
    uint64_t total = 0;
    for (uint32_t j = 0; j < m; j++) {
        total += W[j];
    }
    uint64_t best = UINT64_MAX, lo = 0, hi = W[0];
    uint32_t j = 0;
    for (uint32_t i = 0; i < m; i++) {
        const uint64_t t = ((2u * (uint64_t)i + 1u) * total) / (2u * (uint64_t)m);
        while (hi <= t && j + 1u < m) {
            j++;
            lo = hi;
            hi += W[j];
        }
        const uint64_t d = (t - lo < hi - 1u - t) ? t - lo : hi - 1u - t;
        if (d < best) {
            best = d;
        }
    }
    return best;
}

static void test_pf_noise_table(void **state)
{
    (void)state;
    pf_golden_t g;
    load_all(&g);
    print_message("golden pf         %d steps, %u particles, ROM table %u samples (FNV-1a %u)\n", g.nsteps,
                  g.m, (unsigned)BR_NOISE_LEN, pf_fnv1a_table(br_noise_table, BR_NOISE_LEN));
    free_all(&g);
}

/* (a) the integer resampling is identical step by step */
static void test_pf_resample_identical(void **state)
{
    (void)state;
    pf_golden_t g;
    load_all(&g);
    uint32_t W[BR_PF_MAX_PARTICLES];
    uint16_t idx_t[BR_PF_MAX_PARTICLES], idx_c[BR_PF_MAX_PARTICLES];
    long bad_steps = 0, bad_idx = 0, n_margin0 = 0;
    for (int k = 1; k < g.nsteps; k++) {
        step_w(&g, k, W, idx_t);
        assert_int_equal(br_pf_resample_idx(W, g.m, idx_c), BR_OK);
        int bad = 0;
        for (uint32_t i = 0; i < g.m; i++) {
            bad += idx_c[i] != idx_t[i];
        }
        if (bad) {
            if (bad_steps < 5) {
                print_error("pf_w.csv step %d: %d of %u indices differ\n", k, bad, g.m);
            }
            bad_steps++;
            bad_idx += bad;
        }
        n_margin0 += resample_margin(W, g.m) == 0u;
    }
    print_message("golden pf         resampling: %d steps x %u indices, %ld steps / %ld indices differ "
                  "(%ld steps have a point on an interval edge)\n",
                  g.nsteps - 1, g.m, bad_steps, bad_idx, n_margin0);
    free_all(&g);
    assert_int_equal(bad_steps, 0);
}

/* the set resampled with the reference's indices, and its estimate as br_pf.h
 * defines it: the mean of f_nl over the resampled set (float32, as the
 * filter; br_pf_stats makes the particle means from the set) */
static void resample_forced(br_pf_t *pf, const br_pf_t *pred, const uint16_t *idx)
{
    const uint32_t m = pf->cfg.n_particles;
    float sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        for (int i = 0; i < BR_NX; i++) {
            pf->x[i][j] = pred->x[i][idx[j]];
        }
        pf->kgp[j] = pred->kgp[idx[j]];
        sf += pf->fnl[idx[j]];
        pf->idx[j] = idx[j];
    }
    pf->est.F_hat_N = sf / (float)m;
}

/* The predicted set of the step from the filter as it was before it (*pred):
 * br_pf_predict makes the same prediction in place; a valid particle's theta
 * is then taken to the new origin, th - shift, as br_pf_step does. */
static void predicted_set(br_pf_t *pred, const br_meas_t *y, float u)
{
    const float shift = (float)br_counts_delta(y->counts, pred->origin_counts) * pred->cfg.est.rad_per_count;
    assert_true(br_pf_predict(pred, u) == BR_OK);
    for (uint32_t j = 0; j < pred->cfg.n_particles; j++) {
        if (pred->l[j] == pred->l[j]) {
            pred->x[BR_X_THETA][j] -= shift;
        }
    }
}

static br_pf_t g_pf, g_pred; /* ~70 KiB each: static */

/* (b) and (c) */
static void test_pf_forced_run(void **state)
{
    (void)state;
    pf_golden_t g;
    load_all(&g);
    br_pf_t *pf = &g_pf;
    assert_int_equal(br_pf_init(pf, &g.cfg), BR_OK);
    const uint32_t m = g.m;
    const double rpc = g.cfg.est.rad_per_count;
    const pf_consts_t c = pf_golden_consts(&g.pf, &g.cfg);

    const int c_counts = br_trace_col(&g.in, "counts"), c_frac = br_trace_col(&g.in, "frac");
    const int c_u = br_trace_col(&g.in, "u_prev_Nm"), c_kin = br_trace_col(&g.in, "k");
    const int c_k = br_trace_col(&g.pf, "k"), c_st = br_trace_col(&g.pf, "status");
    const int c_org = br_trace_col(&g.pf, "origin_counts"), c_np = br_trace_col(&g.pf, "noise_pos");
    const int c_lmax = br_trace_col(&g.pf, "lmax"), c_F = br_trace_col(&g.pf, "F_hat");
    const int c_Fp = br_trace_col(&g.pf, "F_hat_pred");
    const int c_ess = br_trace_col(&g.pf, "ess"), c_ra = br_trace_col(&g.pf, "reanchored");
    const int c_mean[BR_NX] = {br_trace_col(&g.pf, "theta"), br_trace_col(&g.pf, "omega"),
                               br_trace_col(&g.pf, "z"), br_trace_col(&g.pf, "gp")};
    const int cx_k = br_trace_col(&g.x, "k"), cx_j = br_trace_col(&g.x, "j");
    const int cx[BR_NX] = {br_trace_col(&g.x, "theta"), br_trace_col(&g.x, "omega"), br_trace_col(&g.x, "z"),
                           br_trace_col(&g.x, "gp")};

    br_errstat_t e_mean[BR_NX], e_F, e_ess, e_lmax, e_x[BR_NX], e_W, e_W1;
    br_errstat_init(&e_mean[0], "theta", "rad");
    br_errstat_init(&e_mean[1], "omega", "rad/s");
    br_errstat_init(&e_mean[2], "z", "m");
    br_errstat_init(&e_mean[3], "gp", "N");
    br_errstat_init(&e_F, "F_hat", "N");
    br_errstat_init(&e_ess, "ess", "");
    br_errstat_init(&e_lmax, "lmax", "");
    br_errstat_init(&e_x[0], "x.theta", "rad");
    br_errstat_init(&e_x[1], "x.omega", "rad/s");
    br_errstat_init(&e_x[2], "x.z", "m");
    br_errstat_init(&e_x[3], "x.gp", "N");
    br_errstat_init(&e_W, "W", "");
    br_errstat_init(&e_W1, "W(n=1)", "");

    uint32_t W_t[BR_PF_MAX_PARTICLES];
    uint16_t idx_t[BR_PF_MAX_PARTICLES];
    const int block = (g.w.ncols - 2) / 2, per_step = (int)m / block;
    long bad_status = 0, bad_exact = 0, n_outlier = 0, n_reanchor = 0, n_fhat_pred = 0;
    long n_res_steps = 0, n_own_equal = 0, n_own_idx_diff = 0, n_W_diff = 0, n_W_total = 0;
    long hist[4] = {0, 0, 0, 0}; /* |dW| = 0, 1, 2..10, > 10 */
    double sum_dW = 0.0;
    uint64_t max_margin_flip = 0;
    long n_sync = 0;
    int xrow = 0;
    drift_t dr;
    double xm_prev[BR_NX], S[BR_NX];
    int32_t origin_prev = 0;

    for (int k = 0; k < g.nsteps; k++) {
        assert_int_equal((int)br_trace_get(&g.in, k, c_kin), k);
        assert_int_equal((int)br_trace_get(&g.pf, k, c_k), k);
        const br_meas_t y = {(int32_t)br_trace_get(&g.in, k, c_counts), (float)br_trace_get(&g.in, k, c_frac)};
        const float u = (float)br_trace_get(&g.in, k, c_u);
        const int st_exp = (int)br_trace_get(&g.pf, k, c_st);
        double xm[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xm[i] = br_trace_get(&g.pf, k, c_mean[i]);
        }
        /* the error bound of the particles after this step's prediction */
        if (k == 0) {
            step_scales(&c, xm, xm, 0.0, 0.0, S);
            drift_seed(&dr, S);
        } else {
            const double shift = (double)br_counts_delta(y.counts, origin_prev) * rpc;
            step_scales(&c, xm_prev, xm, u, shift, S);
            drift_advance(&dr, &c, S);
        }

        /* the predicted set of this step, for the forced resampling below */
        br_pf_t *const pred = &g_pred;
        memcpy(pred, pf, sizeof *pred);
        if (pf->primed) {
            predicted_set(pred, &y, u);
        }
        const br_status_t st = br_pf_step(pf, &y, u);
        if ((int)st != st_exp) {
            if (bad_status++ < 5) {
                print_error("%s:%d: br_pf_step returned %d, expected %d\n", g.pf.path, g.pf.line[k], (int)st,
                            st_exp);
            }
        }
        n_outlier += st_exp == BR_W_OUTLIER;
        const int reanchored = (int)br_trace_get(&g.pf, k, c_ra);
        n_reanchor += reanchored;
        /* integer state: exact */
        if ((double)pf->origin_counts != br_trace_get(&g.pf, k, c_org) ||
            (double)pf->noise_pos != br_trace_get(&g.pf, k, c_np) ||
            pf->est.origin_counts != pf->origin_counts) {
            if (bad_exact++ < 5) {
                print_error("%s:%d: origin %d / noise_pos %u, expected %.0f / %.0f\n", g.pf.path, g.pf.line[k],
                            (int)pf->origin_counts, (unsigned)pf->noise_pos, br_trace_get(&g.pf, k, c_org),
                            br_trace_get(&g.pf, k, c_np));
            }
        }
        if (k > 0) {
            step_w(&g, k, W_t, idx_t);
            n_res_steps++;
            const int outlier = st_exp == BR_W_OUTLIER;
            /* max log-weight over the valid particles */
            float lmax = -INFINITY;
            for (uint32_t j = 0; j < m; j++) {
                lmax = fmaxf(lmax, pf->l[j]);
            }
            const double lmax_t = br_trace_get(&g.pf, k, c_lmax);
            const double dlmax = dlog_bound(&c, lmax_t, dr.d[0]);
            br_errstat_add(&e_lmax, &g.pf, k, (double)lmax, lmax_t, dlmax);
            /* W: w = e^(l - lmax) is off by at most rho relative; quantised: +-1 */
            double A = 0.0, B = 0.0, dA = 0.0, dB = 0.0;
            for (uint32_t j = 0; j < m; j++) {
                const int r = (k - 1) * per_step + (int)j / block;
                const double dW = (double)pf->W[j] - (double)W_t[j];
                n_W_total++;
                n_W_diff += dW != 0.0;
                sum_dW += dW;
                hist[dW == 0.0 ? 0 : fabs(dW) == 1.0 ? 1 : fabs(dW) <= 10.0 ? 2 : 3]++;
                if (!(pf->l[j] > -INFINITY)) {
                    br_errstat_add(&e_W, &g.w, r, (double)pf->W[j], (double)W_t[j], 0.0); /* invalid: 0 */
                    continue;
                }
                const double rho = outlier ? 0.0 : EXP_REL + dlog_bound(&c, pf->l[j], dr.d[0]) + dlmax;
                const double tol = 1.0 + ((double)W_t[j] + 1.0) * expm1(rho);
                br_errstat_add(&e_W, &g.w, r, (double)pf->W[j], (double)W_t[j], tol);
                if (dr.n == 1) {
                    br_errstat_add(&e_W1, &g.w, r, (double)pf->W[j], (double)W_t[j], tol);
                }
                const double w = outlier ? 1.0 : exp((double)pf->l[j] - (double)lmax);
                A += w;
                B += w * w;
                dA += rho * w;
                dB += (2.0 * rho + rho * rho) * w * w;
            }
            const double ess_t = br_trace_get(&g.pf, k, c_ess);
            br_pf_stats_t ps;
            assert_int_equal(br_pf_stats(pf, &ps), BR_OK);
            br_errstat_add(&e_ess, &g.pf, k, (double)ps.ess, ess_t,
                           ess_t * (2.0 * dA / A + dB / B + C_SUM * (double)m * U32));
            /* (c) the filter's own indices */
            int own_diff = 0;
            for (uint32_t j = 0; j < m; j++) {
                own_diff += pf->idx[j] != idx_t[j];
            }
            if (own_diff == 0) {
                n_own_equal++;
            } else {
                n_own_idx_diff += own_diff;
                const uint64_t mg = resample_margin(W_t, m);
                if (mg > max_margin_flip) {
                    max_margin_flip = mg;
                }
                /* an outlier step gives every valid particle the same weight:
                 * its indices cannot differ */
                assert_int_equal(st_exp, BR_OK);
                /* (b) stay on the reference's ancestry */
                resample_forced(pf, pred, idx_t);
            }
        }
        /* largest |x| of the C set: scale of the sums over the particles */
        double xmax[BR_NX] = {0.0, 0.0, 0.0, 0.0}, fmax_ = 0.0, dF = 0.0;
        for (uint32_t j = 0; j < m; j++) {
            float xj[BR_NX];
            for (int i = 0; i < BR_NX; i++) {
                xj[i] = (k > 0) ? pred->x[i][pf->idx[j]] : pf->x[i][j];
                xmax[i] = fmax(xmax[i], fabs((double)pf->x[i][j]));
            }
            const double f = (k > 0) ? pf->fnl[pf->idx[j]] : br_model_fnl_N(&pf->model, xj);
            fmax_ = fmax(fmax_, fabs(f));
            dF = fmax(dF, dfnl_bound(&c, xj, dr.d));
        }
        if (reanchored) {
            /* the cloud's shift is computed from sums over the particles */
            dr.d[0] += 2.0 * (double)m * U32 * xmax[0];
            dr.d[1] += 2.0 * (double)m * U32 * xmax[1];
        }
        /* estimate: the particles' bound plus the rounding of the sum */
        br_pf_stats_t ps;
        assert_int_equal(br_pf_stats(pf, &ps), BR_OK);
        for (int i = 0; i < BR_NX; i++) {
            br_errstat_add(&e_mean[i], &g.pf, k, (double)ps.mean[i], xm[i],
                           dr.d[i] + C_SUM * (double)m * U32 * xmax[i]);
        }
        const double F_t = br_trace_get(&g.pf, k, c_F);
        const double tol_F = dF + C_SUM * (double)m * U32 * fmax_;
        if (!br_errstat_add(&e_F, &g.pf, k, (double)pf->est.F_hat_N, F_t, tol_F) && reanchored &&
            fabs((double)pf->est.F_hat_N - br_trace_get(&g.pf, k, c_Fp)) <= tol_F) {
            n_fhat_pred++;
            print_error("%s:%d: re-anchoring step %d: F_hat = %.9g is the mean f_nl of the cloud BEFORE it was "
                        "re-anchored (F_hat_pred = %.9g); br_pf.h: F_hat = mean f_nl of the particles, "
                        "which after re-anchoring give %.9g\n",
                        g.pf.path, g.pf.line[k], k, (double)pf->est.F_hat_N, br_trace_get(&g.pf, k, c_Fp), F_t);
        }
        /* re-synchronisation point: compare the whole set, then restart
         * the next window from the reference's set, rounded to float32 */
        if (xrow < g.x.nrows && (int)br_trace_get(&g.x, xrow, cx_k) == k) {
            for (uint32_t j = 0; j < m; j++, xrow++) {
                assert_true(xrow < g.x.nrows);
                assert_int_equal((int)br_trace_get(&g.x, xrow, cx_k), k);
                assert_int_equal((int)br_trace_get(&g.x, xrow, cx_j), (int)j);
                for (int i = 0; i < BR_NX; i++) {
                    const double ref = br_trace_get(&g.x, xrow, cx[i]);
                    br_errstat_add(&e_x[i], &g.x, xrow, (double)pf->x[i][j], ref, dr.d[i]);
                    pf->x[i][j] = (float)ref;
                }
                pf->kgp[j] = (pf->cfg.est.model.lugre.sigma0_Npm * pf->cfg.est.model.lead_mprad) /
                              pf->x[BR_X_GP][j]; /* the filter carries sigma0 L / g_p with g_p */
            }
            step_scales(&c, xm, xm, 0.0, 0.0, S);
            drift_seed(&dr, S);
            n_sync++;
        }
        for (int i = 0; i < BR_NX; i++) {
            xm_prev[i] = xm[i];
        }
        origin_prev = (int32_t)br_trace_get(&g.pf, k, c_org);
    }
    assert_int_equal(xrow, g.x.nrows);

    print_message("golden pf         %d steps (%ld outlier, %ld re-anchoring), %u particles, %ld re-synchronisations\n",
                  g.nsteps, n_outlier, n_reanchor, m, n_sync);
    print_message("golden pf         own indices == trace on %ld of %ld steps (%.2f %%); %ld of %ld indices differ; "
                  "largest reference margin at such a step: %llu\n",
                  n_own_equal, n_res_steps, 100.0 * (double)n_own_equal / (double)n_res_steps, n_own_idx_diff,
                  n_res_steps * (long)m, (unsigned long long)max_margin_flip);
    print_message("golden pf         W: %ld of %ld differ (%.2f %%), mean W_C - W_ref = %+.4f; |dW| = 0: %ld, 1: %ld, "
                  "2..10: %ld, > 10: %ld\n",
                  n_W_diff, n_W_total, 100.0 * (double)n_W_diff / (double)n_W_total, sum_dW / (double)n_W_total,
                  hist[0], hist[1], hist[2], hist[3]);
    br_errstat_t *all[] = {&e_W, &e_W1, &e_lmax, &e_mean[0], &e_mean[1], &e_mean[2], &e_mean[3], &e_F, &e_ess,
                           &e_x[0], &e_x[1], &e_x[2], &e_x[3]};
    const br_trace_t *of[] = {&g.w, &g.w, &g.pf, &g.pf, &g.pf, &g.pf, &g.pf, &g.pf, &g.pf, &g.x, &g.x, &g.x, &g.x};
    long fails = 0;
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        br_errstat_print(all[i], of[i], "pf");
        fails += all[i]->n_fail;
    }
    free_all(&g);
    if (bad_status != 0 || bad_exact != 0) {
        fail_msg("pf: %ld steps with a wrong status, %ld with a wrong origin / noise position", bad_status,
                 bad_exact);
    }
    /* quantisation is floor on both sides: no systematic offset (a rounding
     * instead of the floor gives +0.44) */
    assert_true(fabs(sum_dW / (double)n_W_total) < 0.05);
    if (n_fhat_pred != 0) {
        fail_msg("pf: on %ld re-anchoring step(s) F_hat is the mean f_nl of the cloud before re-anchoring",
                 n_fhat_pred);
    }
    if (fails != 0) {
        fail_msg("pf: %ld comparisons outside tolerance (first lines printed above)", fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pf_noise_table),
        cmocka_unit_test(test_pf_resample_identical),
        cmocka_unit_test(test_pf_forced_run),
    };
    return cmocka_run_group_tests_name("golden_pf", tests, NULL, NULL);
}
