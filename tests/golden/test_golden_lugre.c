/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_lugre_step (float32) against golden/traces/lugre.csv
 * (float64 reference golden/ref/lugre.py), one continuous run from z = 0.
 * Tolerances: docs/golden.md. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "bristle/br_lugre.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

/* Drift bound (docs/golden.md). z is a state: each float32 step adds a
 * local rounding error of at most ~u (|z1| + 3 |z0 - zss|) (z_advance in
 * either form, zss + (z0 - zss) e or z0 + (zss - z0)(1 - e), e = exp(-r)
 * faithfully rounded), and the bristle forgets an old error only at the rate
 * q = 1 - exp(-r), r = sigma0 |v dt| / g, per step. The test propagates this
 * worst case (coherent roundings) along the trace,
 *     D_k = (1 - q_k) D_{k-1} + u (|z_k| + 3 |z_{k-1} - zss_k|),
 * and allows C_DRIFT D_k on z and sigma0 C_DRIFT D_k on F. In the slow creep
 * (2e-6 m/s, q = 4.7e-4) D reaches ~u z / q ~ 6e-10 m. */
#define C_DRIFT 4.0

static void test_lugre_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "lugre");
    br_lugre_cfg_t cfg = {
        .sigma0_Npm = (float)br_trace_meta_num(&t, "sigma0_Npm"),
        .sigma1_Nspm = (float)br_trace_meta_num(&t, "sigma1_Nspm"),
        .Fc_N = (float)br_trace_meta_num(&t, "Fc_N"),
        .Fs_N = (float)br_trace_meta_num(&t, "Fs_N"),
        .vs_mps = (float)br_trace_meta_num(&t, "vs_mps"),
    };
    const double sigma0 = br_trace_meta_num(&t, "sigma0_Npm");
    const double sigma1 = br_trace_meta_num(&t, "sigma1_Nspm");
    const float dt = (float)br_trace_meta_num(&t, "dt_s");
    assert_int_equal(br_trace_meta_num(&t, "z0_m"), 0.0);

    const int cv = br_trace_col(&t, "v"), cg = br_trace_col(&t, "g");
    const int cz = br_trace_col(&t, "z"), cF = br_trace_col(&t, "F");
    br_lugre_t s;
    assert_int_equal(br_lugre_init(&s, &cfg), BR_OK);
    assert_true(s.z_m == 0.0f);

    br_errstat_t eg, ez, eF;
    br_errstat_init(&eg, "g", "N");
    br_errstat_init(&ez, "z", "m");
    br_errstat_init(&eF, "F", "N");
    int bad_status = 0;
    double drift = 0.0, z_prev = 0.0, drift_max = 0.0;

    for (int r = 0; r < t.nrows; r++) {
        const double v = br_trace_get(&t, r, cv);
        const double g = br_trace_get(&t, r, cg);
        const double z = br_trace_get(&t, r, cz);
        const double F = br_trace_get(&t, r, cF);
        float Fo = NAN;
        br_status_t st = br_lugre_step(&s, (float)v, dt, &Fo);
        if (st != BR_OK) {
            if (bad_status++ < 5) {
                print_error("%s:%d: br_lugre_step returned %d\n", t.path, t.line[r], (int)st);
            }
            continue;
        }
        /* worst-case drift of z, propagated from the reference values */
        if (v != 0.0) {
            const double zss = copysign(g / sigma0, v);
            const double q = -expm1(-sigma0 * fabs(v * (double)dt) / g);
            drift = (1.0 - q) * drift + U32 * (fabs(z) + 3.0 * fabs(z_prev - zss));
        }
        drift_max = fmax(drift_max, drift);
        z_prev = z;
        const double z_drift_tol = C_DRIFT * drift;
        const double F_drift_tol = sigma0 * z_drift_tol;
        /* g: a handful of roundings, no state */
        br_errstat_add(&eg, &t, r, (double)br_lugre_g_N(&cfg, (float)v), g, 8.0 * U32 * g);
        /* z: creep drift bound + the per-step rounding of the bristle scale */
        br_errstat_add(&ez, &t, r, (double)s.z_m, z,
                       z_drift_tol + 32.0 * U32 * fmax(fabs(z), g / sigma0));
        /* F = sigma0 z + sigma1 (v - sigma0 |v| z / g): sigma0 times the z
         * bound, plus rounding of the three terms (the last two cancel in
         * steady sliding) */
        br_errstat_add(&eF, &t, r, (double)Fo, F,
                       F_drift_tol + 32.0 * U32 *
                       (sigma0 * fabs(z) + sigma1 * fabs(v) * (1.0 + sigma0 * fabs(z) / g)));
    }
    print_message("golden lugre      largest drift tolerance: z %.3g m, F %.3g N\n",
                  C_DRIFT * drift_max, sigma0 * C_DRIFT * drift_max);
    br_errstat_print(&eg, &t, "lugre");
    br_errstat_print(&ez, &t, "lugre");
    br_errstat_print(&eF, &t, "lugre");
    const long fails = eg.n_fail + ez.n_fail + eF.n_fail;
    const int nrows = t.nrows;
    br_trace_free(&t);
    assert_int_equal(bad_status, 0);
    if (fails != 0) {
        fail_msg("lugre: %ld of %d rows outside tolerance (first lines printed above)", fails, nrows);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lugre_trace),
    };
    return cmocka_run_group_tests_name("golden_lugre", tests, NULL, NULL);
}
