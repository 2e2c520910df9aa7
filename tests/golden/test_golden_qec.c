/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the reversal compensation's pulse (br_qec_set_ref, br_qec_comp;
 * float32) against golden/traces/qec.csv (float64 reference golden/ref/qec.py),
 * one continuous run from rest. Tolerances: docs/golden.md, "qec". */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "bristle/br_qec.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

/* The bound (docs/golden.md, "qec"): the amplitude max(0, A0 + A1 |a|) rounds a
 * product and a sum, C_AMP u S with S = |A0| + |A1 a| at the reversal; each
 * period after it multiplies by rho = expf(-dt / tau) (the quotient's rounding
 * times dt / tau, expf within 2u) and rounds the product: C_STEP u per period.
 * Bound at n periods after the reversal: C_Q (C_AMP + C_STEP n) u S exp(-n dt / tau). */
#define C_AMP 2.0
#define C_STEP 4.0
#define C_Q 2.0

static void test_qec_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "qec");
    br_qec_cfg_t cfg = {0};
    cfg.A0_N = (float)br_trace_meta_num(&t, "A0_N");
    cfg.A1_kg = (float)br_trace_meta_num(&t, "A1_kg");
    cfg.tau_s = (float)br_trace_meta_num(&t, "tau_s");
    cfg.dt_s = (float)br_trace_meta_num(&t, "dt_s");
    cfg.comp_max_N = 1.0e6f; /* no clamp: the pulse itself */
    br_qec_t q;
    assert_int_equal(br_qec_init(&q, &cfg), BR_OK);
    const int cv = br_trace_col(&t, "v"), ca = br_trace_col(&t, "a"), cn = br_trace_col(&t, "since");
    const int cp = br_trace_col(&t, "p");
    br_errstat_t ep;
    br_errstat_init(&ep, "p", "N");
    double S = 0.0;
    int bad_status = 0, reversals = 0, floored = 0;
    for (int r = 0; r < t.nrows; r++) {
        const double v = br_trace_get(&t, r, cv), a = br_trace_get(&t, r, ca), n = br_trace_get(&t, r, cn);
        const br_ff_in_t in = {(float)v, (float)a, 0.0f};
        float p = NAN;
        if (br_qec_set_ref(&q, &in) != BR_OK || br_qec_comp(&q, &p) != BR_OK) {
            bad_status++;
            continue;
        }
        if (n == 0.0) {
            /* a reversal in the reference: its amplitude's scale */
            S = fabs((double)cfg.A0_N) + fabs((double)cfg.A1_kg * a);
            reversals++;
            floored += br_trace_get(&t, r, cp) == 0.0;
        }
        const double tol = n < 0.0 ? 0.0
                                   : C_Q * (C_AMP + C_STEP * n) * U32 * S * exp(-n * (double)cfg.dt_s / cfg.tau_s);
        br_errstat_add(&ep, &t, r, (double)p, br_trace_get(&t, r, cp), tol);
    }
    br_errstat_print(&ep, &t, "qec");
    const long fails = ep.n_fail;
    br_trace_free(&t);
    assert_int_equal(bad_status, 0);
    /* the trace exercises the reversals, with and without the amplitude's floor */
    assert_true(reversals >= 10);
    assert_true(floored >= 2 && floored < reversals - 2);
    if (fails != 0) {
        fail_msg("qec: %ld comparisons outside tolerance (first lines printed above)", fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_qec_trace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
