/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_mslip_step (float32, clamp form) against
 * golden/traces/mslip.csv (float64 reference golden/ref/mslip.py), one
 * continuous run from undeflected elements; br_model_ms_step (the Maxwell-slip
 * estimation model) against golden/traces/model_ms.csv, one step per row.
 * Tolerances: docs/golden.md, "mslip" and "model_ms". */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "bristle/br_model.h"
#include "bristle/br_mslip.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

/* Propagated bound (docs/golden.md, "mslip"): the C element differs from the
 * reference by E_i, which grows by one rounding of the addition per step,
 * E <- E (1 + u) + u (|z| + |dx|), and falls back to the rounding of the
 * bound Delta_i = fl(fl(share/k) g), 3u Delta_i, on every step where the
 * reference's unclamped value lies beyond Delta_i by more than the C value
 * can differ (both then clamp; the clamp is 1-Lipschitz). C_Z is the
 * safety factor on that bound. */
#define C_Z 2.0
/* F = sum k_i z_i + sigma2 v: the element bounds times k_i, plus the
 * rounding of n products and n + 1 additions, (n + C_F_SUM) u S_F. */
#define C_F_SUM 2.0
/* one-step factors of the model step on the scales of docs/golden.md ("model_ms") */
#define C_THETA 4.0
#define C_OMEGA 16.0
#define C_ZM 8.0
#define C_FNL 8.0

/* The trace's element set (n, k_Npm, share) into doubles and a float config. */
static int read_elements(const br_trace_t *t, double k[BR_MSLIP_MAX], double share[BR_MSLIP_MAX],
                         br_mslip_cfg_t *cfg)
{
    const int n = (int)br_trace_meta_num(t, "n");
    assert_true(n >= 1 && n <= BR_MSLIP_MAX);
    br_trace_meta_nums(t, "k_Npm", k, n);
    br_trace_meta_nums(t, "share", share, n);
    cfg->n = n;
    for (int i = 0; i < n; i++) {
        cfg->k_Npm[i] = (float)k[i];
        cfg->share[i] = (float)share[i];
    }
    return n;
}

/* A trace's column "<prefix><i + 1><suffix>" of each element. */
static void element_cols(const br_trace_t *t, int n, const char *suffix, int col[BR_MSLIP_MAX])
{
    for (int i = 0; i < n; i++) {
        char name[16];
        snprintf(name, sizeof name, "z%d%s", i + 1, suffix);
        col[i] = br_trace_col(t, name);
    }
}

/* Fails the test with the trace's name when a comparison was outside its tolerance. */
static void expect_no_fails(const char *trace, long fails)
{
    if (fails != 0) {
        fail_msg("%s: %ld comparisons outside tolerance (first lines printed above)", trace, fails);
    }
}

static void test_mslip_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "mslip");
    double k[BR_MSLIP_MAX], share[BR_MSLIP_MAX];
    br_mslip_cfg_t cfg = {.sigma2_Nspm = (float)br_trace_meta_num(&t, "sigma2_Nspm")};
    const int n = read_elements(&t, k, share, &cfg);
    br_mslip_t s;
    assert_int_equal(br_mslip_init(&s, &cfg), BR_OK);

    const int cdx = br_trace_col(&t, "dx"), cv = br_trace_col(&t, "v"), cg = br_trace_col(&t, "g");
    const int cF = br_trace_col(&t, "F");
    int cz[BR_MSLIP_MAX];
    element_cols(&t, n, "", cz);
    br_errstat_t ez, eF;
    br_errstat_init(&ez, "z", "m");
    br_errstat_init(&eF, "F", "N");
    double E[BR_MSLIP_MAX] = {0}, zprev[BR_MSLIP_MAX] = {0};
    int bad_status = 0, resets = 0;
    for (int r = 0; r < t.nrows; r++) {
        const double dx = br_trace_get(&t, r, cdx), v = br_trace_get(&t, r, cv), g = br_trace_get(&t, r, cg);
        float Fo = NAN;
        if (br_mslip_step(&s, (float)dx, (float)v, (float)g, &Fo) != BR_OK) {
            bad_status++;
            continue;
        }
        double tolF = 0.0, SF = fabs((double)cfg.sigma2_Nspm * v);
        for (int i = 0; i < n; i++) {
            const double D = share[i] * g / k[i];
            const double grow = E[i] * (1.0 + U32) + U32 * (fabs(zprev[i]) + fabs(dx));
            const double a = zprev[i] + dx; /* the reference's unclamped value */
            if (fabs(a) - D >= grow + 3.0 * U32 * D) {
                E[i] = 3.0 * U32 * D;
                resets++;
            } else {
                E[i] = fmax(grow, 3.0 * U32 * D);
            }
            const double z = br_trace_get(&t, r, cz[i]);
            br_errstat_add(&ez, &t, r, (double)s.z_m[i], z, C_Z * E[i]);
            tolF += k[i] * C_Z * E[i];
            SF += k[i] * fabs(z);
            zprev[i] = z;
        }
        br_errstat_add(&eF, &t, r, (double)Fo, br_trace_get(&t, r, cF), tolF + ((double)n + C_F_SUM) * U32 * SF);
    }
    br_errstat_print(&ez, &t, "mslip");
    br_errstat_print(&eF, &t, "mslip");
    const long fails = ez.n_fail + eF.n_fail;
    br_trace_free(&t);
    assert_int_equal(bad_status, 0);
    /* the trace exercises the clamp: most steps clamp some element */
    assert_true(resets > 1000);
    expect_no_fails("mslip", fails);
}

static void test_model_ms_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "model_ms");
    br_model_cfg_t cfg = br_trace_model_cfg(&t);
    assert_int_equal((int)br_trace_meta_num(&t, "passes"), BR_MODEL_MS_PASSES);
    double k[BR_MSLIP_MAX], share[BR_MSLIP_MAX];
    const int n = read_elements(&t, k, share, &cfg.mslip);
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cfg), BR_OK);
    const double L = cfg.lead_mprad, h = cfg.dt_s, ij = 1.0 / ((double)cfg.J_kgm2 + L * L * cfg.M_kg);
    const double visc = L * L * cfg.sigma2_Nspm;
    const int cu = br_trace_col(&t, "u"), cth = br_trace_col(&t, "theta"), cw = br_trace_col(&t, "omega");
    const int cg = br_trace_col(&t, "gp"), cth1 = br_trace_col(&t, "theta1"), cw1 = br_trace_col(&t, "omega1");
    const int cf = br_trace_col(&t, "fnl");
    int cz[BR_MSLIP_MAX], cz1[BR_MSLIP_MAX];
    element_cols(&t, n, "", cz);
    element_cols(&t, n, "_1", cz1);
    br_errstat_t eth, ew, ez, ef;
    br_errstat_init(&eth, "theta1", "rad");
    br_errstat_init(&ew, "omega1", "rad/s");
    br_errstat_init(&ez, "z1", "m");
    br_errstat_init(&ef, "fnl", "N");
    int bad = 0;
    for (int r = 0; r < t.nrows; r++) {
        const double th = br_trace_get(&t, r, cth), w = br_trace_get(&t, r, cw), gp = br_trace_get(&t, r, cg);
        const double u = br_trace_get(&t, r, cu), th1 = br_trace_get(&t, r, cth1), w1 = br_trace_get(&t, r, cw1);
        const float x[BR_NX] = {(float)th, (float)w, 0.0f, (float)gp};
        float z[BR_MSLIP_MAX], x1[BR_NX], z1[BR_MSLIP_MAX];
        double Sf = 0.0;
        for (int i = 0; i < n; i++) {
            z[i] = (float)br_trace_get(&t, r, cz[i]);
            Sf += k[i] * fabs((double)z[i]);
        }
        br_errstat_add(&ef, &t, r, (double)br_model_ms_fnl_N(&m, z), br_trace_get(&t, r, cf), C_FNL * U32 * Sf);
        if (br_model_ms_step(&m, x, z, (float)u, x1, z1) != BR_OK) {
            bad++;
            continue;
        }
        /* S_theta = |theta0| + |theta1| + h (|omega0| + |omega1|) */
        br_errstat_add(&eth, &t, r, (double)x1[BR_X_THETA], th1,
                       C_THETA * U32 * (fabs(th) + fabs(th1) + h * (fabs(w) + fabs(w1))));
        /* S_omega = |omega0| + |omega1| + h/Jeff (|u| + L^2 sigma2 |omega0| + L (sum k_i |z_i| + g_p)) */
        const double Sw = fabs(w) + fabs(w1) + h * ij * (fabs(u) + visc * fabs(w) + L * (Sf + gp));
        br_errstat_add(&ew, &t, r, (double)x1[BR_X_OMEGA], w1, C_OMEGA * U32 * Sw);
        for (int i = 0; i < n; i++) {
            /* S_z = |z_i| + Delta_i + L h (|omega0| + |omega1|) + L h S_omega */
            const double D = share[i] * gp / k[i];
            const double Sz = fabs((double)z[i]) + D + L * h * (fabs(w) + fabs(w1)) + L * h * Sw;
            br_errstat_add(&ez, &t, r, (double)z1[i], br_trace_get(&t, r, cz1[i]), C_ZM * U32 * Sz);
        }
        assert_true(x1[BR_X_GP] == x[BR_X_GP] && x1[BR_X_Z] == x[BR_X_Z]);
    }
    br_errstat_print(&eth, &t, "model_ms");
    br_errstat_print(&ew, &t, "model_ms");
    br_errstat_print(&ez, &t, "model_ms");
    br_errstat_print(&ef, &t, "model_ms");
    const long fails = eth.n_fail + ew.n_fail + ez.n_fail + ef.n_fail;
    br_trace_free(&t);
    assert_int_equal(bad, 0);
    expect_no_fails("model_ms", fails);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mslip_trace),
        cmocka_unit_test(test_model_ms_trace),
    };
    return cmocka_run_group_tests_name("golden_mslip", tests, NULL, NULL);
}
