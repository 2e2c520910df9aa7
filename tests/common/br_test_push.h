/* SPDX-License-Identifier: Apache-2.0 */
/* The measurement of an axis held still for 0.1 s, then pushed by an external
 * force F_N (toward -x: a force against +x, as friction) with no torque:
 * theta(t) = -L F_N t^2 / (2 J_eff) from t0, frictionless (the model's
 * friction and the load then share the force a filter sees). Period k of the
 * model m, encoder resolution rpc (rad per count). And an axis at rest whose
 * counter glitches. The load tests of the UKF and the PF (test_ukf_load,
 * test_pf_load). */
#ifndef BR_TEST_PUSH_H
#define BR_TEST_PUSH_H

#include <math.h>
#include <stdio.h>

#include "br_test.h"
#include "bristle/br_est.h"
#include "bristle/br_model.h"

static inline br_meas_t br_test_pushed_meas(const br_model_cfg_t *m, double rpc, double F_N, int k)
{
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const double t = (double)k * m->dt_s - 0.1;
    const double th = (t > 0.0) ? -L * F_N * t * t / (2.0 * Jeff) : 0.0;
    const double cts = th / rpc + 0.5;
    const double whole = floor(cts);
    const br_meas_t y = {(int32_t)whole, (float)(cts - whole)};
    return y;
}

/* n periods of that push through the estimator e; returns the number of outlier
 * steps (every step BR_OK or BR_W_OUTLIER), *F_comp the last compensation */
static inline int br_test_run_pushed(const br_est_t *e, const br_model_cfg_t *m, double rpc, double F_N, int n,
                                     float *F_comp)
{
    int outliers = 0;
    for (int k = 0; k < n; k++) {
        const br_meas_t y = br_test_pushed_meas(m, rpc, F_N, k);
        const br_status_t st = e->step(e->ctx, &y, 0.0f, F_comp);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        outliers += st == BR_W_OUTLIER;
    }
    return outliers;
}

/* The push of br_test_pushed_meas through e, the counter reading +500
 * counts (a spike) at the period `after` periods after the first load
 * re-acquisition (n_acq: the filter's count; after 0: no spike), n periods.
 * Returns 1 when the spike's period re-acquired a load; *F_end the last
 * compensation (the window of docs/modules/est.md, "Glitch or load") */
static inline int br_test_run_push_spike(const br_est_t *e, const uint32_t *n_acq, const br_model_cfg_t *m,
                                         double rpc, double F_N, int after, int n, float *F_end)
{
    int k_acq = -1, spike_acq = 0;
    for (int k = 0; k < n; k++) {
        br_meas_t y = br_test_pushed_meas(m, rpc, F_N, k);
        const int spike = after > 0 && k_acq >= 0 && k == k_acq + after;
        y.counts += spike ? 500 : 0;
        const uint32_t acq0 = *n_acq;
        const br_status_t st = e->step(e->ctx, &y, 0.0f, F_end);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        k_acq = (k_acq < 0 && *n_acq > acq0) ? k : k_acq;
        spike_acq |= spike && *n_acq > acq0;
    }
    return spike_acq;
}

/* An axis at rest (count 100, no torque) whose counter reads +off counts at
 * period 200 only (slip 0: a spike) or from period 200 on (slip 1: a slip),
 * n periods through e; returns the number of outlier steps, *F_max the
 * largest |compensation| from period 200 on */
static inline int br_test_run_glitch(const br_est_t *e, int32_t off, int slip, int n, float *F_max)
{
    int outliers = 0;
    *F_max = 0.0f;
    for (int k = 0; k < n; k++) {
        const br_meas_t y = {100 + ((k == 200 || (slip && k > 200)) ? off : 0), 0.5f};
        float F = 0.0f;
        const br_status_t st = e->step(e->ctx, &y, 0.0f, &F);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        outliers += st == BR_W_OUTLIER;
        *F_max = (k >= 200) ? fmaxf(*F_max, fabsf(F)) : 0.0f;
    }
    return outliers;
}

/* What a glitch must leave (test_glitch_not_a_load): no load re-acquired, the
 * compensation the friction's (< 2 % of the actuator's force max_N), a spike
 * one outlier step and a slip the re-anchoring's reanchor_after */
static inline void br_test_assert_glitch(int slip, int n_out, float F_max, uint32_t n_acq, uint32_t n_held,
                                         float max_N, uint32_t reanchor_after)
{
    printf("  %s: %d outlier steps, %u held, %u re-acquisitions, max |compensation| %.2f N\n", slip ? "slip" : "spike",
           n_out, n_held, n_acq, (double)F_max);
    assert_int_equal(n_acq, 0u);
    assert_true(n_held >= 1u);
    assert_true(F_max < 0.02f * max_N);
    assert_int_equal(n_out, slip ? (int)reanchor_after : 1);
}

/* test_glitch_in_window: acq[a] and F_end[a] of br_test_run_push_spike with
 * after = a (0: no spike) under a push of F_N */
static inline void br_test_assert_window(const int acq[4], const float F_end[4], double F_N)
{
    for (int a = 0; a < 4; a++) {
        printf("  spike %d periods after the re-acquisition: re-acquired %d, compensation at top speed %.2f N (push %.1f N)\n",
               a, acq[a], (double)F_end[a], F_N);
    }
    /* the window's limit (documented): a spike in the two periods after a re-acquisition is
     * taken for a load */
    assert_int_equal(acq[1], 1);
    assert_int_equal(acq[2], 1);
}

/* periods of the push of F_N from rest until the machine's top speed v_max:
 * 0.1 s still, then v_max J_eff / (L^2 F_N) */
static inline int br_test_push_periods(const br_model_cfg_t *m, double F_N, double v_max)
{
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    return (int)ceil(0.1 / m->dt_s) + (int)ceil(v_max * Jeff / (L * L * F_N) / m->dt_s);
}

#endif
