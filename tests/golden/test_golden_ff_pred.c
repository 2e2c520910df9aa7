/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the compensation that predicts (br_ff_pred_N; float32) against
 * golden/traces/ff_pred.csv (float64 reference golden/ref/ffpred.py), row by
 * row from its anchor. Tolerance: docs/golden.md, "ff_pred". */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "bristle/br_ff.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */
#define N_EL 4

/* The bound (docs/golden.md, "ff_pred"): C_PRED u S, S = sum_i k_i (|z_i| +
 * |z1_i| + |dp|) + g1: the travel's and the level's roundings carried through
 * the clamp into k_i z1_i, and the two sums' roundings. */
#define C_PRED 8.0

static void test_ff_pred_trace(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "ff_pred");
    br_ff_cfg_t cfg = {0};
    cfg.Fc_N = (float)br_trace_meta_num(&t, "Fc_N");
    cfg.Fs_N = (float)br_trace_meta_num(&t, "Fs_N");
    cfg.vs_mps = (float)br_trace_meta_num(&t, "vs_mps");
    cfg.v_eps_mps = 1.0f; /* not read with elements */
    cfg.comp_max_N = 1.0e6f;
    double k[N_EL], share[N_EL];
    br_trace_meta_nums(&t, "k_Npm", k, N_EL);
    br_trace_meta_nums(&t, "share", share, N_EL);
    cfg.mslip.n = N_EL;
    for (int i = 0; i < N_EL; i++) {
        cfg.mslip.k_Npm[i] = (float)k[i];
        cfg.mslip.share[i] = (float)share[i];
    }
    const int ct = br_trace_col(&t, "tau"), cv = br_trace_col(&t, "v"), ca = br_trace_col(&t, "a");
    const int cz = br_trace_col(&t, "z0"), cd = br_trace_col(&t, "dF"), cs = br_trace_col(&t, "S");
    br_errstat_t ed;
    br_errstat_init(&ed, "dF", "N");
    int bad_status = 0, crossed = 0;
    for (int r = 0; r < t.nrows; r++) {
        cfg.pred_ahead_s = (float)br_trace_get(&t, r, ct);
        br_ff_t ff;
        const br_ff_in_t in = {(float)br_trace_get(&t, r, cv), (float)br_trace_get(&t, r, ca), 0.0f};
        float z[N_EL];
        for (int i = 0; i < N_EL; i++) z[i] = (float)br_trace_get(&t, r, cz + i);
        float dF = NAN;
        if (br_ff_init(&ff, &cfg) != BR_OK || br_ff_set_ref(&ff, &in) != BR_OK ||
            br_ff_pred_N(&ff, z, NULL, &dF) != BR_OK) {
            bad_status++;
            continue;
        }
        const double want = br_trace_get(&t, r, cd);
        crossed += fabs(want) > 1.0; /* a change of more than a newton: the elements moved */
        br_errstat_add(&ed, &t, r, (double)dF, want, C_PRED * U32 * br_trace_get(&t, r, cs));
    }
    br_errstat_print(&ed, &t, "ff_pred");
    const long fails = ed.n_fail;
    const int rows = t.nrows;
    br_trace_free(&t);
    assert_int_equal(bad_status, 0);
    /* the trace exercises both: predictions that move the force and ones that do not */
    assert_true(crossed > rows / 10 && crossed < rows - rows / 10);
    if (fails != 0) {
        fail_msg("ff_pred: %ld comparisons outside tolerance (first lines printed above)", fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ff_pred_trace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
