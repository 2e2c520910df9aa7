/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_model_step / br_model_fnl_N (float32) against
 * golden/traces/model.csv (float64 reference golden/ref/model.py).
 * One-step rows: each row gives x_k, u_k and the float64 x_{k+1}, so
 * float32 error does not accumulate. Tolerances: docs/golden.md. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bristle/br_model.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */
/* Rounding-chain factors: a step is a few dozen float32 operations per
 * signal, each contributing <= u of the scale of its operands (docs/golden.md). */
#define C_THETA 32.0
#define C_OMEGA 32.0
#define C_Z 64.0
#define C_FNL 32.0

static int same_float(float a, double b)
{
    return (isnan(a) && isnan(b)) || (double)a == b;
}

static void test_model_one_step(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "model");
    const double J = br_trace_meta_num(&t, "J_kgm2");
    const double M = br_trace_meta_num(&t, "M_kg");
    const double L = br_trace_meta_num(&t, "L_mprad");
    const double s0 = br_trace_meta_num(&t, "sigma0_Npm");
    const double s1 = br_trace_meta_num(&t, "sigma1_Nspm");
    const double s2 = br_trace_meta_num(&t, "sigma2_Nspm");
    const double h = br_trace_meta_num(&t, "dt_s");
    const double Jeff = J + L * L * M;
    br_model_cfg_t cfg = {
        .J_kgm2 = (float)J,
        .M_kg = (float)M,
        .lead_mprad = (float)L,
        .sigma2_Nspm = (float)s2,
        .lugre = {
            .sigma0_Npm = (float)s0,
            .sigma1_Nspm = (float)s1,
            .Fc_N = (float)br_trace_meta_num(&t, "Fc_N"),
            .Fs_N = (float)br_trace_meta_num(&t, "Fs_N"),
            .vs_mps = (float)br_trace_meta_num(&t, "vs_mps"),
        },
        .dt_s = (float)h,
    };
    br_model_t m;
    assert_int_equal(br_model_init(&m, &cfg), BR_OK);

    const int cu = br_trace_col(&t, "u"), cst = br_trace_col(&t, "status");
    const int cbr = br_trace_col(&t, "branch"), cfn = br_trace_col(&t, "fnl");
    const int cx[BR_NX] = {br_trace_col(&t, "theta"), br_trace_col(&t, "omega"),
                           br_trace_col(&t, "z"), br_trace_col(&t, "gp")};
    const int cx1[BR_NX] = {br_trace_col(&t, "theta1"), br_trace_col(&t, "omega1"),
                            br_trace_col(&t, "z1"), br_trace_col(&t, "gp1")};

    br_errstat_t e[BR_NX], efn;
    br_errstat_init(&e[0], "theta", "rad");
    br_errstat_init(&e[1], "omega", "rad/s");
    br_errstat_init(&e[2], "z", "m");
    br_errstat_init(&e[3], "gp", "N");
    br_errstat_init(&efn, "fnl", "N");
    long n_branch[3] = {0, 0, 0}; /* invalid, RK4, bounded */
    long bad_status = 0, bad_invalid = 0;

    for (int r = 0; r < t.nrows; r++) {
        float x[BR_NX], xn[BR_NX];
        double xd[BR_NX], x1d[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xd[i] = br_trace_get(&t, r, cx[i]);
            x1d[i] = br_trace_get(&t, r, cx1[i]);
            x[i] = (float)xd[i];
            xn[i] = 12345.0f;
        }
        const double u = br_trace_get(&t, r, cu);
        const int st_exp = (int)br_trace_get(&t, r, cst);
        const int branch = (int)br_trace_get(&t, r, cbr);
        n_branch[branch + 1]++;
        const br_status_t st = br_model_step(&m, x, (float)u, xn);
        if ((int)st != st_exp) {
            if (bad_status++ < 5) {
                print_error("%s:%d: br_model_step returned %d, expected %d\n",
                            t.path, t.line[r], (int)st, st_exp);
            }
            continue;
        }
        if (st_exp != BR_OK) {
            /* invalid input: x_next = x exactly */
            for (int i = 0; i < BR_NX; i++) {
                if (!same_float(xn[i], x1d[i])) {
                    if (bad_invalid++ < 5) {
                        print_error("%s:%d: invalid input: x_next[%d] = %g, expected x[%d] = %g\n",
                                    t.path, t.line[r], i, (double)xn[i], i, x1d[i]);
                    }
                }
            }
            continue;
        }
        const double w0 = fabs(xd[1]), z0 = fabs(xd[2]), gp = xd[3];
        /* theta1 = theta + (mean velocity) h */
        const double S_th = fabs(xd[0]) + fabs(x1d[0]) + h * (w0 + fabs(x1d[1]));
        /* omega1 = omega + h/Jeff (u - L (sigma0 z + sigma1 zdot + sigma2 L omega)) */
        const double S_w = w0 + fabs(x1d[1]) +
                           h / Jeff * (fabs(u) + L * (fmax(s0 * z0, gp) + (2.0 * s1 + s2) * L * w0));
        /* z stays within max(|z0|, g_p/sigma0) (RK4: a h <= 2) */
        const double S_z = fmax(fmax(z0, fabs(x1d[2])), gp / s0);
        br_errstat_add(&e[0], &t, r, (double)xn[0], x1d[0], C_THETA * U32 * S_th);
        br_errstat_add(&e[1], &t, r, (double)xn[1], x1d[1], C_OMEGA * U32 * S_w);
        br_errstat_add(&e[2], &t, r, (double)xn[2], x1d[2], C_Z * U32 * S_z);
        br_errstat_add(&e[3], &t, r, (double)xn[3], (double)x[3], 0.0); /* g_p is held exactly */
        /* fnl = sigma0 z + sigma1 (L w - sigma0 L |w| z / g_p) */
        const double S_f = s0 * z0 + s1 * L * w0 * (1.0 + s0 * z0 / gp);
        br_errstat_add(&efn, &t, r, (double)br_model_fnl_N(&m, x), br_trace_get(&t, r, cfn),
                       C_FNL * U32 * S_f);
    }
    print_message("golden model      rows: %ld RK4, %ld bounded, %ld invalid input\n",
                  n_branch[1], n_branch[2], n_branch[0]);
    long fails = 0;
    for (int i = 0; i < BR_NX; i++) {
        br_errstat_print(&e[i], &t, "model");
        fails += e[i].n_fail;
    }
    br_errstat_print(&efn, &t, "model");
    fails += efn.n_fail;
    const int nrows = t.nrows;
    br_trace_free(&t);
    assert_true(n_branch[1] > 0 && n_branch[2] > 0 && n_branch[0] > 0);
    if (bad_status != 0 || bad_invalid != 0) {
        fail_msg("model: %ld rows with a wrong status, %ld invalid-input rows with x_next != x",
                 bad_status, bad_invalid);
    }
    if (fails != 0) {
        fail_msg("model: %ld comparisons of %d rows outside tolerance (first lines printed above)",
                 fails, nrows);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_model_one_step),
    };
    return cmocka_run_group_tests_name("golden_model", tests, NULL, NULL);
}
