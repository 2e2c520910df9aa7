/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_mslip_step (float32, clamp form) against
 * golden/traces/mslip.csv (float64 reference golden/ref/mslip.py), one
 * continuous run from undeflected elements. Tolerances: docs/golden.md,
 * "mslip". */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

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

static void test_mslip_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "mslip");
    const int n = (int)br_trace_meta_num(&t, "n");
    assert_true(n >= 1 && n <= BR_MSLIP_MAX);
    double k[BR_MSLIP_MAX], share[BR_MSLIP_MAX];
    br_trace_meta_nums(&t, "k_Npm", k, n);
    br_trace_meta_nums(&t, "share", share, n);
    br_mslip_cfg_t cfg = {.n = n, .sigma2_Nspm = (float)br_trace_meta_num(&t, "sigma2_Nspm")};
    for (int i = 0; i < n; i++) {
        cfg.k_Npm[i] = (float)k[i];
        cfg.share[i] = (float)share[i];
    }
    br_mslip_t s;
    assert_int_equal(br_mslip_init(&s, &cfg), BR_OK);

    const int cdx = br_trace_col(&t, "dx"), cv = br_trace_col(&t, "v"), cg = br_trace_col(&t, "g");
    const int cF = br_trace_col(&t, "F");
    int cz[BR_MSLIP_MAX];
    for (int i = 0; i < n; i++) {
        char name[16];
        snprintf(name, sizeof name, "z%d", i + 1);
        cz[i] = br_trace_col(&t, name);
    }
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
    if (fails != 0) {
        fail_msg("mslip: %ld comparisons outside tolerance (first lines printed above)", fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mslip_trace),
    };
    return cmocka_run_group_tests_name("golden_mslip", tests, NULL, NULL);
}
