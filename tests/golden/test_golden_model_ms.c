/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_model_ms_step (float32, the Maxwell-slip estimation model)
 * against golden/traces/model_ms.csv (float64 reference golden/ref/mslip.py),
 * one step per row. Tolerances: docs/golden.md, "model_ms". */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "bristle/br_model.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

/* one-step factors on the scales of docs/golden.md ("model_ms") */
#define C_THETA 4.0
#define C_OMEGA 16.0
#define C_Z 8.0
#define C_FNL 8.0

static void test_model_ms_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "model_ms");
    br_model_cfg_t cfg = br_trace_model_cfg(&t);
    const int n = (int)br_trace_meta_num(&t, "n");
    assert_int_equal((int)br_trace_meta_num(&t, "passes"), BR_MODEL_MS_PASSES);
    double k[BR_MSLIP_MAX], share[BR_MSLIP_MAX];
    br_trace_meta_nums(&t, "k_Npm", k, n);
    br_trace_meta_nums(&t, "share", share, n);
    cfg.mslip.n = n;
    for (int i = 0; i < n; i++) {
        cfg.mslip.k_Npm[i] = (float)k[i];
        cfg.mslip.share[i] = (float)share[i];
    }
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cfg), BR_OK);
    const double L = cfg.lead_mprad, h = cfg.dt_s, ij = 1.0 / ((double)cfg.J_kgm2 + L * L * cfg.M_kg);
    const double visc = L * L * cfg.sigma2_Nspm;
    const int cu = br_trace_col(&t, "u"), cth = br_trace_col(&t, "theta"), cw = br_trace_col(&t, "omega");
    const int cg = br_trace_col(&t, "gp"), cth1 = br_trace_col(&t, "theta1"), cw1 = br_trace_col(&t, "omega1");
    const int cf = br_trace_col(&t, "fnl");
    int cz[BR_MSLIP_MAX], cz1[BR_MSLIP_MAX];
    for (int i = 0; i < n; i++) {
        char name[16];
        snprintf(name, sizeof name, "z%d", i + 1);
        cz[i] = br_trace_col(&t, name);
        snprintf(name, sizeof name, "z%d_1", i + 1);
        cz1[i] = br_trace_col(&t, name);
    }
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
            br_errstat_add(&ez, &t, r, (double)z1[i], br_trace_get(&t, r, cz1[i]), C_Z * U32 * Sz);
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
    if (fails != 0) {
        fail_msg("model_ms: %ld comparisons outside tolerance (first lines printed above)", fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_model_ms_trace),
    };
    return cmocka_run_group_tests_name("golden_model_ms", tests, NULL, NULL);
}
