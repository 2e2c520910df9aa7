/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: br_ctrl_step (float32) against golden/traces/ctrl.csv
 * (float64 reference golden/ref/ctrl.py): one continuous run from init, the
 * configuration read from the trace header. Tolerances: docs/golden.md. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "bristle/br_ctrl.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */

static void test_ctrl_sequence(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "ctrl");
    double K[3];
    br_trace_meta_nums(&t, "K", K, 3);
    const double dt = br_trace_meta_num(&t, "dt_s");
    const double tau_max = br_trace_meta_num(&t, "tau_max_Nm");
    const double tau_per_duty = br_trace_meta_num(&t, "tau_per_duty_Nm");
    const double rpc = br_trace_meta_num(&t, "rad_per_count");
    const double L = br_trace_meta_num(&t, "lead_mprad");
    br_ctrl_cfg_t cfg = {
        .K = {(float)K[0], (float)K[1], (float)K[2]},
        .dt_s = (float)dt,
        .tau_max_Nm = (float)tau_max,
        .tau_per_duty_Nm = (float)tau_per_duty,
        .rad_per_count = (float)rpc,
        .lead_mprad = (float)L,
    };
    br_ctrl_t c;
    assert_int_equal(br_ctrl_init(&c, &cfg), BR_OK);

    const int cenc = br_trace_col(&t, "enc_counts"), cref = br_trace_col(&t, "ref_counts");
    const int cfr = br_trace_col(&t, "ref_frac_counts"), cwr = br_trace_col(&t, "ref_omega_radps");
    const int ccomp = br_trace_col(&t, "comp_N"), ctau = br_trace_col(&t, "tau_Nm");
    const int cduty = br_trace_col(&t, "duty"), ceps = br_trace_col(&t, "eps_rads");
    const int csat = br_trace_col(&t, "saturated"), cet = br_trace_col(&t, "e_theta_rad");
    const int cw = br_trace_col(&t, "omega_radps");

    br_errstat_t etau, eduty, eeps, eet, ew;
    br_errstat_init(&etau, "tau", "N m");
    br_errstat_init(&eduty, "duty", "");
    br_errstat_init(&eeps, "eps", "rad s");
    br_errstat_init(&eet, "e_theta", "rad");
    br_errstat_init(&ew, "omega", "rad/s");
    long bad_status = 0, bad_sat = 0, n_sat = 0;
    double eps_prev = 0.0, eps_tol_prev = 0.0, eps_scale = 0.0;

    for (int r = 0; r < t.nrows; r++) {
        const double enc = br_trace_get(&t, r, cenc), ref = br_trace_get(&t, r, cref);
        br_ctrl_in_t in = {
            .enc_counts = (int32_t)enc,
            .ref_counts = (int32_t)ref,
            .ref_frac_counts = (float)br_trace_get(&t, r, cfr),
            .ref_omega_radps = (float)br_trace_get(&t, r, cwr),
            .comp_N = (float)br_trace_get(&t, r, ccomp),
        };
        br_ctrl_out_t out;
        const br_status_t st = br_ctrl_step(&c, &in, &out);
        if (st != BR_OK) {
            if (bad_status++ < 5) {
                print_error("%s:%d: br_ctrl_step returned %d\n", t.path, t.line[r], (int)st);
            }
            continue;
        }
        const double tau = br_trace_get(&t, r, ctau), eps = br_trace_get(&t, r, ceps);
        const double et = br_trace_get(&t, r, cet), w = br_trace_get(&t, r, cw);
        const int sat = (int)br_trace_get(&t, r, csat);
        n_sat += sat;
        if (out.saturated != sat) {
            if (bad_sat++ < 5) {
                print_error("%s:%d: saturated = %d, expected %d (tau %.9g, expected %.9g)\n",
                            t.path, t.line[r], out.saturated, sat, (double)out.tau_Nm, tau);
            }
        }
        /* e_theta = (int difference - frac) rad_per_count: int->float and
         * three roundings; omega = d rad_per_count / dt: three roundings */
        br_errstat_add(&eet, &t, r, (double)out.e_theta_rad, et, 8.0 * U32 * (fabs(et) + rpc));
        br_errstat_add(&ew, &t, r, (double)out.omega_radps, w, 8.0 * U32 * fabs(w));
        /* eps: every update rounds the sum and the product e_theta dt, so the
         * error is bounded by u times the running sum of |eps| + |e_theta dt| */
        eps_scale += fabs(eps) + fabs(et) * dt;
        const double eps_tol = 4.0 * U32 * eps_scale;
        br_errstat_add(&eeps, &t, r, (double)c.eps_rads, eps, eps_tol);
        /* u = K0 e_theta + K1 e_omega + K2 eps_prev + L comp: rounding of the
         * four terms plus K2 times the inherited eps error */
        const double S_u = fabs(K[0] * et) + fabs(K[1]) * (fabs(w) + fabs((double)in.ref_omega_radps)) +
                           fabs(K[2] * eps_prev) + fabs(L * (double)in.comp_N);
        const double tau_tol = 16.0 * U32 * S_u + fabs(K[2]) * eps_tol_prev;
        br_errstat_add(&etau, &t, r, (double)out.tau_Nm, tau, tau_tol);
        br_errstat_add(&eduty, &t, r, (double)out.duty, br_trace_get(&t, r, cduty),
                       tau_tol / tau_per_duty + 4.0 * U32 * fabs(tau / tau_per_duty));
        eps_prev = eps;
        eps_tol_prev = eps_tol;
    }
    print_message("golden ctrl       rows: %d, saturated: %ld\n", t.nrows, n_sat);
    br_errstat_print(&etau, &t, "ctrl");
    br_errstat_print(&eduty, &t, "ctrl");
    br_errstat_print(&eeps, &t, "ctrl");
    br_errstat_print(&eet, &t, "ctrl");
    br_errstat_print(&ew, &t, "ctrl");
    const long fails = etau.n_fail + eduty.n_fail + eeps.n_fail + eet.n_fail + ew.n_fail;
    const int nrows = t.nrows;
    br_trace_free(&t);
    assert_true(n_sat > 0);
    if (bad_status != 0 || bad_sat != 0) {
        fail_msg("ctrl: %ld rows with a wrong status, %ld rows with a wrong saturated flag",
                 bad_status, bad_sat);
    }
    if (fails != 0) {
        fail_msg("ctrl: %ld comparisons of %d rows outside tolerance (first lines printed above)",
                 fails, nrows);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ctrl_sequence),
    };
    return cmocka_run_group_tests_name("golden_ctrl", tests, NULL, NULL);
}
