/* SPDX-License-Identifier: Apache-2.0 */
/* The UKF's external-force state (cfg.load; docs/modules/ukf.md, "External
 * force"): its configuration guards, a load step followed without an
 * outlier (and, without the state, the outliers it causes), the
 * compensation of friction + load within the bound, and a counter jump no
 * load can explain still rejected. */
#include "br_test.h"
#include "br_test_push.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bristle_gen/machine/br_machine.h"
#include "circle/br_circle_est.h"
#include "bristle/br_ukf.h"

#define DT_F BR_MACHINE_CTRL_PERIOD_S_F

/* the machine's tuned UKF with the state off (whatever the machine file says) */
static br_ukf_cfg_t off_cfg(void)
{
    br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(DT_F);
    c.load = (br_ukf_load_t){0.0f, 0.0f, 0.0f};
    return c;
}

/* the machine's tuned UKF with its external-force state (machines/reference.json's
 * estimator.ukf.load); a machine file without one: 1e4 N^2/s, F_act^2, F_act */
static br_ukf_cfg_t load_cfg(void)
{
    br_ukf_cfg_t c = br_circle_ukf_cfg_tuned(DT_F);
    if (c.load.max_N > 0.0f) {
        return c;
    }
    const float F_act = BR_MACHINE_TORQUE_LIMIT_NM_F / c.est.model.lead_mprad;
    c.load.q_N2 = 1.0e4f * DT_F;
    c.load.p0_N2 = F_act * F_act;
    c.load.max_N = F_act;
    return c;
}

static int init_with(br_ukf_cfg_t c)
{
    br_ukf_t u;
    return br_ukf_init(&u, &c);
}

static void test_load_guards(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = load_cfg();
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    assert_int_equal(u.n, BR_UKF_NMAX);
    c = off_cfg();
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    assert_int_equal(u.n, BR_NX); /* all 0: off */
    /* off needs all three 0 */
    c = off_cfg(); c.load.q_N2 = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    c = off_cfg(); c.load.max_N = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    const float bad[] = {NAN, INFINITY, -1.0f, 1.0e-40f, 2.0f * BR_EST_VAR_MAX};
    for (unsigned b = 0; b < sizeof bad / sizeof bad[0]; b++) {
        c = load_cfg(); c.load.p0_N2 = bad[b]; assert_int_equal(init_with(c), BR_E_PARAM);
        c = load_cfg(); c.load.q_N2 = bad[b];  assert_int_equal(init_with(c), BR_E_PARAM);
    }
    c = load_cfg(); c.load.q_N2 = 0.0f; assert_int_equal(init_with(c), BR_OK); /* a constant load */
    c = load_cfg(); c.load.max_N = 0.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    c = load_cfg(); c.load.max_N = -5.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    c = load_cfg(); c.load.max_N = NAN; assert_int_equal(init_with(c), BR_E_PARAM);
    /* n + kappa > 0 with n = 5: kappa = -4.5 passes with the state, not without */
    c = load_cfg(); c.kappa = -4.5f; assert_int_equal(init_with(c), BR_OK);
    c = off_cfg(); c.kappa = -4.5f; assert_int_equal(init_with(c), BR_E_PARAM);
}

/* Counts of an axis held still for 0.1 s, then pushed by an external force
 * F_N (toward -x: a force against +x, as friction) with no torque: theta(t) =
 * -L F_N t^2 / (2 J_eff) from t0, frictionless (the model's friction and
 * the load then share the force the filter sees). Runs n periods through u,
 * returns the number of outlier steps; *F_comp the last compensation. */
static int run_pushed(br_ukf_t *u, double F_N, int n, float *F_comp)
{
    const br_model_cfg_t *m = &u->cfg.est.model;
    const double rpc = u->cfg.est.rad_per_count;
    const br_est_t e = br_ukf_est(u);
    return br_test_run_pushed(&e, m, rpc, F_N, n, F_comp);
}

static void test_load_step_followed(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = load_cfg();
    const double F = 0.5 * (double)c.load.max_N; /* half the actuator's force */
    float comp = 0.0f;
    /* pushed from rest until the axis reaches the machine's top speed (beyond it the
     * push is no condition the axis meets: the model's viscous sigma2 v grows with the
     * speed and F_d with it): 0.1 s still, then v_max J_eff / (L^2 F) */
    const br_model_cfg_t *m = &c.est.model;
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const int n = 100 + (int)ceil((double)BR_MACHINE_MAX_SPEED_MPS_F * Jeff / (L * L * F) / m->dt_s);
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    assert_int_equal(run_pushed(&u, F, n, &comp), 0);
    assert_true(u.n_load_acq >= 1u);
    /* the compensation carries the load: friction + F_d of the size of the push
     * (measured at their top speeds: reference machine 0.99 F, heavy 1.05 F) */
    printf("  load %.1f N: compensation %.2f N, F_d %.2f N, %u re-acquisitions\n", F, (double)comp,
           (double)u.est.load_N, u.n_load_acq);
    assert_true(comp > 0.9 * F && comp < 1.1 * F);
    /* without the state the same push is a run of outliers (the lock monitor's trip) */
    br_ukf_cfg_t off = off_cfg();
    assert_int_equal(br_ukf_init(&u, &off), BR_OK);
    assert_true(run_pushed(&u, F, 250, &comp) > 10);
}

static void test_load_bounded(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = load_cfg();
    c.load.max_N = 100.0f; /* a bound below the push: F_d and the compensation stay within it */
    float comp = 0.0f;
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    (void)run_pushed(&u, 250.0, 250, &comp);
    assert_true(fabsf(u.est.load_N) <= 100.0f);
    assert_true(fabsf(comp) <= 100.0f);
}

static void test_jump_not_a_load(void **st)
{
    (void)st;
    br_ukf_t u;
    br_ukf_cfg_t c = load_cfg();
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    const br_meas_t y = {100, 0.5f};
    for (int k = 0; k < 200; k++) {
        assert_int_equal(br_ukf_step(&u, &y, 0.0f), BR_OK);
    }
    /* 2e4 counts in one period: a force of ~1e4 N, beyond 2 max_N: still an outlier, no re-acquisition */
    const br_meas_t j = {100 + 20000, 0.5f};
    assert_int_equal(br_ukf_step(&u, &j, 0.0f), BR_W_OUTLIER);
    assert_int_equal(u.n_load_acq, 0u);
}

/* The filter at period dt_s on an axis held still (counts 100) whose counter reads +off counts for one
 * period (slip 0: a spike) or from then on (slip 1) from step 200 of 400.
 * Returns the last period after the glitch that re-acquired a load (199
 * when none did, 200 when only the glitch's own did); *acq_at the glitch's
 * own re-acquisition (0: within the gate, an ordinary update); *fd_max the
 * largest |F_d| from 2 periods after the glitch on, *w_max the largest
 * |omega| there, *n_out the outlier steps. */
static int glitch(float dt_s, int32_t off, int slip, int *acq_at, float *fd_max, float *w_max, int *n_out)
{
    br_ukf_t u;
    br_ukf_cfg_t c = load_cfg();
    c.est.model.dt_s = dt_s;
    assert_int_equal(br_ukf_init(&u, &c), BR_OK);
    int last_acq = 199;
    *acq_at = 0;
    *fd_max = *w_max = 0.0f;
    *n_out = 0;
    for (int k = 0; k < 400; k++) {
        const br_meas_t y = {100 + ((k == 200 || (slip && k > 200)) ? off : 0), 0.5f};
        const uint32_t acq = u.n_load_acq;
        const br_status_t st = br_ukf_step(&u, &y, 0.0f);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        *n_out += st == BR_W_OUTLIER;
        last_acq = (k >= 200 && u.n_load_acq != acq) ? k : last_acq;
        *acq_at = (k == 200) ? (u.n_load_acq != acq) : *acq_at;
        if (k >= 202) {
            *fd_max = fmaxf(*fd_max, fabsf(u.est.load_N));
            *w_max = fmaxf(*w_max, fabsf(u.est.mean[BR_X_OMEGA]));
        }
    }
    return last_acq;
}

/* docs/modules/ukf.md, "A glitch is not a load": a one-period spike or a
 * counter slip of up to 2 max_N g counts (g = L dt^2 / (2 J_eff), the load
 * state's rad per N over one period) is, over one period, a force the
 * re-acquisition takes for a load. Without the undo, at the control period
 * the next innovation (-4 and -3 times the glitch) is beyond what a load
 * explains: outliers and a re-anchoring; at 1.5 periods (the golden trace's
 * 1.5 ms) it is within it, and the filter cycles for good (period 2, F_d
 * about +-465 N on the reference machine). With the undo the next period's
 * innovation undoes the re-acquisition: no re-acquisition after the
 * glitch's own, no outlier, and from the period after on F_d and omega back
 * at the held axis's (under 1 % of the actuator's force, under 1e-2 rad/s:
 * measured under 1.2e-5 N, 3e-7 rad/s). The sizes are 1/32 .. 32/32 of 0.95
 * of that window, from this machine's values. A glitch within the gate (the
 * smallest sizes) is an ordinary update, not a re-acquisition, and not this
 * case (ukf.md, "Known limit: a glitch within the gate": it is then
 * re-acquired a period later, F_d off by up to 27 N on the reference
 * machine and 656 N on machines/heavy); at least 24 sizes of each kind are
 * re-acquired. Taking the first hypothesis that passes instead of the
 * smaller |nu| fails here (reference machine, 1 ms: a 113-count slip is
 * within the spike's gate a period on), and so does the model's RK4 test
 * at the ends only (machines/heavy, 1.5 ms: a slip's sigma points of F_d
 * beyond the actuator's force, stepped from rest). */
static void test_glitch_undone(void **st)
{
    (void)st;
    const float F_act = load_cfg().load.max_N;
    for (int p = 0; p < 4; p++) {
        const int slip = p & 1;
        const float dt = (p < 2) ? DT_F : 1.5f * DT_F;
        br_ukf_t u;
        br_ukf_cfg_t c = load_cfg();
        c.est.model.dt_s = dt;
        assert_int_equal(br_ukf_init(&u, &c), BR_OK);
        const float window = 0.95f * 2.0f * F_act * u.load_rad_per_N2 / c.est.rad_per_count;
        int n_acq = 0;
        for (int i = 1; i <= 32; i++) {
            const int32_t off = (int32_t)lrintf(window * (float)i / 32.0f);
            float fd, w;
            int n_out, acq_at;
            const int last = glitch(dt, off, slip, &acq_at, &fd, &w, &n_out);
            printf("  dt %g s, %s %d: %s, last re-acquisition at %d, then max |F_d| %.3g N, |omega| %.3g rad/s, "
                   "%d outliers\n", (double)dt, slip ? "slip" : "spike", (int)off,
                   acq_at ? "re-acquired" : "within the gate", last, (double)fd, (double)w, n_out);
            if (!acq_at) {
                continue; /* within the gate: an ordinary update, no re-acquisition to undo */
            }
            n_acq++;
            assert_int_equal(last, 200); /* taken for a load at the glitch, and only there */
            assert_int_equal(n_out, 0);
            assert_true(fd < 0.01f * F_act);
            assert_true(w < 1.0e-2f);
        }
        assert_true(n_acq >= 24);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_load_guards),
        cmocka_unit_test(test_load_step_followed),
        cmocka_unit_test(test_load_bounded),
        cmocka_unit_test(test_jump_not_a_load),
        cmocka_unit_test(test_glitch_undone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
