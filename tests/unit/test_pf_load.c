/* SPDX-License-Identifier: Apache-2.0 */
/* The PF's shared external force (cfg.load; docs/modules/pf.md, "External
 * force"): its configuration guards, a load step followed without an outlier
 * (and, without it, the outliers it causes), the compensation of friction +
 * load within the bound, and a counter jump no load can explain still
 * rejected. */
#include "br_test.h"
#include "br_test_push.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "bristle/br_pf.h"

#define DT_F BR_EST_PF_PERIOD_S_F

/* the filters are large: one, static to the test (not a mutable global of the firmware) */
static br_pf_t g_pf;

/* the machine's tuned PF with the load off (whatever the machine file says) */
static br_pf_cfg_t off_cfg(void)
{
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(DT_F);
    c.load.q_N2 = 0.0f;
    c.load.max_N = 0.0f;
    return c;
}

static br_pf_cfg_t load_cfg(void)
{
    br_pf_cfg_t c = off_cfg();
    c.load.q_N2 = 1.0e4f * DT_F; /* 1e4 N^2/s, the campaign's */
    c.load.max_N = BR_MACHINE_TORQUE_LIMIT_NM_F / c.est.model.lead_mprad;
    return c;
}

static int init_with(br_pf_cfg_t c) { return br_pf_init(&g_pf, &c); }

static void test_load_guards(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    assert_true(g_pf.load_g_radpN > 0.0f);
    assert_true(g_pf.load_P[5] == c.load.max_N * c.load.max_N);
    c = off_cfg();
    assert_int_equal(init_with(c), BR_OK); /* all 0: off */
    /* off needs both 0 */
    c = off_cfg(); c.load.q_N2 = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    c = off_cfg(); c.load.max_N = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    const float bad[] = {NAN, INFINITY, -1.0f, 1.0e-40f, 2.0f * BR_EST_VAR_MAX, 0.0f};
    for (unsigned b = 0; b < sizeof bad / sizeof bad[0]; b++) {
        c = load_cfg(); c.load.q_N2 = bad[b]; assert_int_equal(init_with(c), BR_E_PARAM);
        c = load_cfg(); c.load.max_N = bad[b]; assert_int_equal(init_with(c), BR_E_PARAM);
    }
    c = load_cfg(); c.load.max_N = 1.0e19f; assert_int_equal(init_with(c), BR_E_PARAM); /* 4 max^2 overflows */
    /* the cloud is moved and weighed again with eq. 6 and the Gaussian likelihood:
     * the bootstrap proposal of the thesis model only */
    c = load_cfg(); c.proposal = BR_PF_PROPOSAL_OPT; assert_int_equal(init_with(c), BR_E_PARAM);
    c = load_cfg(); c.est.model.causes.offset_N = 1.0f; assert_int_equal(init_with(c), BR_E_PARAM);
    /* nor with Maxwell-slip elements (the move would make their f_nl the LuGre one) */
    c = load_cfg(); br_circle_est_mslip(&c.est); assert_int_equal(init_with(c), BR_E_PARAM);
    c = off_cfg(); br_circle_est_mslip(&c.est); assert_int_equal(init_with(c), BR_OK);
}

/* Counts of an axis held still for 0.1 s, then pushed by an external force
 * F_N (toward -x: a force against +x, as friction) with no torque: theta(t) =
 * -L F_N t^2 / (2 J_eff) from t0, frictionless. Runs n periods, returns the
 * number of outlier steps; *F_comp the last compensation. */
static int run_pushed(double F_N, int n, float *F_comp)
{
    const br_model_cfg_t *m = &g_pf.cfg.est.model;
    const double rpc = g_pf.cfg.est.rad_per_count;
    const br_est_t e = br_pf_est(&g_pf);
    return br_test_run_pushed(&e, m, rpc, F_N, n, F_comp);
}

static void test_load_step_followed(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    const double F = 0.5 * (double)c.load.max_N; /* half the actuator's force */
    float comp = 0.0f;
    /* pushed from rest until the axis reaches the machine's top speed: 0.1 s still,
     * then v_max J_eff / (L^2 F) */
    const br_model_cfg_t *m = &c.est.model;
    const double L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const int n = (int)ceil(0.1 / m->dt_s) + (int)ceil((double)BR_MACHINE_MAX_SPEED_MPS_F * Jeff / (L * L * F) / m->dt_s);
    assert_int_equal(init_with(c), BR_OK);
    assert_int_equal(run_pushed(F, n, &comp), 0);
    assert_true(g_pf.n_load_acq >= 1u);
    printf("  load %.1f N: compensation %.2f N, F_d %.2f N, %u re-acquisitions\n", F, (double)comp,
           (double)g_pf.load_N, g_pf.n_load_acq);
    /* the compensation carries the load: of its size within half of it (without
     * cfg.load it is the friction's, about 0.06 F). Measured at the top speed: 1.14 F
     * on the reference machine, 0.74 F on machines/heavy.json (machine_heavy), still
     * rising there; the pushed axis of this test is frictionless while the filter's
     * model brakes it by sigma2 v, so the estimate also takes up that mismatch and
     * goes on growing with the speed (1.4 F at twice the push's time on both) */
    assert_true(comp > 0.5 * F && comp < 1.5 * F);
    /* without it the same push is a run of outliers (the lock monitor's trip) */
    assert_int_equal(init_with(off_cfg()), BR_OK);
    assert_true(run_pushed(F, 250, &comp) > 10);
}

static void test_load_bounded(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    c.load.max_N = 100.0f; /* a bound below the push: F_d and the compensation stay within it */
    float comp = 0.0f;
    assert_int_equal(init_with(c), BR_OK);
    (void)run_pushed(250.0, 250, &comp);
    assert_true(fabsf(g_pf.load_N) <= 100.0f);
    assert_true(fabsf(comp) <= 100.0f);
}

static void test_jump_not_a_load(void **st)
{
    (void)st;
    br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    const br_meas_t y = {100, 0.5f};
    for (int k = 0; k < 200; k++) {
        assert_int_equal(br_pf_step(&g_pf, &y, 0.0f), BR_OK);
    }
    const uint32_t acq = g_pf.n_load_acq;
    /* 2e4 counts in one period: a force of ~5e3 N, beyond 2 max_N: still an outlier, no re-acquisition */
    const br_meas_t j = {100 + 20000, 0.5f};
    assert_int_equal(br_pf_step(&g_pf, &j, 0.0f), BR_W_OUTLIER);
    assert_int_equal(g_pf.n_load_acq, acq);
}

/* An axis at rest whose counter reads +off counts for one period (slip 0) or
 * from then on (slip 1) from step 200 of 400: returns the last step that
 * re-acquired (199 when none did); *acq_at whether step 200 itself did (0:
 * within the gate, an ordinary update), *undone whether step 201 undid it,
 * *f_max the largest |compensation| from step 205 on (the held axis's is
 * the model's friction around 0), *n_out the outlier steps. */
static int glitch_moved(int32_t off, int slip, int32_t moved, int *acq_at, int *undone, float *f_max, int *n_out);

static int glitch(int32_t off, int slip, int *acq_at, int *undone, float *f_max, int *n_out)
{
    return glitch_moved(off, slip, 0, acq_at, undone, f_max, n_out);
}

/* glitch() with the axis itself moved by `moved` counts from step 201 on (the spike's
 * period's compensation moving a real axis otherwise than the model predicts) */
static int glitch_moved(int32_t off, int slip, int32_t moved, int *acq_at, int *undone, float *f_max, int *n_out)
{
    br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    int last_acq = 199;
    *acq_at = *undone = *n_out = 0;
    *f_max = 0.0f;
    for (int k = 0; k < 400; k++) {
        const br_meas_t y = {100 + ((k == 200 || (slip && k > 200)) ? off : 0) + ((k > 200) ? moved : 0), 0.5f};
        const uint32_t acq = g_pf.n_load_acq, undo = g_pf.n_load_undo;
        const br_status_t st = br_pf_step(&g_pf, &y, 0.0f);
        assert_true(st == BR_OK || st == BR_W_OUTLIER);
        *n_out += k >= 200 && st == BR_W_OUTLIER;
        last_acq = (k >= 200 && g_pf.n_load_acq != acq) ? k : last_acq;
        *acq_at = (k == 200) ? (g_pf.n_load_acq != acq) : *acq_at;
        *undone = (k == 201) ? (g_pf.n_load_undo != undo) : *undone;
        if (k >= 205) {
            *f_max = fmaxf(*f_max, fabsf(g_pf.est.F_hat_N));
        }
    }
    return last_acq;
}

/* docs/modules/pf.md, "A glitch is not a load": a one-period spike or a
 * counter slip of up to 2 max_N g counts (g = L h^2 / (2 J_eff)) is, over one
 * period, a force the re-acquisition takes for a load. Without the undo F_d
 * then swung period by period (+-450 N for a 500-count spike, the
 * compensation +-420 N, 82 re-acquisitions, over after about 90 periods). With
 * it the next period's gated innovation undoes the re-acquisition (a spike:
 * the cloud moved back; a slip: the counter kept off), no outlier follows,
 * at most two more re-acquisitions (the particles' z moved with the wrong
 * velocity for a period: measured up to 2), and from 5 periods after the
 * glitch the compensation is the held axis's again, under 1 % of the
 * actuator's force. The sizes are 1/16 .. 16/16 of 0.95 of that window, from
 * this machine's values; a glitch within the gate (the smallest) is an
 * ordinary update and not this case; at least 12 sizes of each kind are
 * re-acquired. */
static void test_glitch_undone(void **st)
{
    (void)st;
    const br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    const float F_act = c.load.max_N;
    const float window = 0.95f * 2.0f * F_act * g_pf.load_g_radpN / c.est.rad_per_count;
    for (int slip = 0; slip < 2; slip++) {
        int n_acq = 0;
        for (int i = 1; i <= 16; i++) {
            const int32_t off = (int32_t)lrintf(window * (float)i / 16.0f);
            int acq_at, undone, n_out;
            float f;
            const int last = glitch(off, slip, &acq_at, &undone, &f, &n_out);
            printf("  %s %d: %s%s, last re-acquisition at %d, then max |F_hat| %.3g N, %d outliers\n",
                   slip ? "slip" : "spike", (int)off, acq_at ? "re-acquired" : "within the gate",
                   undone ? ", undone" : "", last, (double)f, n_out);
            if (!acq_at) {
                continue; /* within the gate: an ordinary update, no re-acquisition to undo */
            }
            n_acq++;
            if (i <= 7) {
                /* up to 7/16 of the window: undone on every machine */
                assert_true(undone);
                assert_true(last <= 203);
                assert_int_equal(n_out, 0);
                assert_true(f < 0.01f * F_act);
            } else {
                /* beyond it (docs/modules/pf.md, "A glitch is not a load": on machines/heavy
                 * from 8/16 on no hypothesis passes): never a lasting cycle, the compensation
                 * back within 5 % of the actuator's force from 5 periods on */
                assert_true(last <= 260);
                assert_true(f < 0.05f * F_act);
            }
        }
        assert_true(n_acq >= 12);
    }
}

/* docs/modules/pf.md, "A glitch is not a load": in closed loop the glitch period's
 * compensation moves the real axis, which the model predicts only as well as it
 * knows the plant (on the hardware-like plant a 500-count spike's -60 N moved the
 * table 287 counts, the spike hypothesis's best particle 1.44 gates off). A spike
 * followed by a move of `moved` counts the model does not predict, 1.05 and
 * 1.1 gates either way (the hypotheses' test at twice the gate's distance,
 * BR_PF_LOAD_UNDO_GATE2): the spike is undone at the next step, the moved axis
 * is then re-acquired for at most 12 periods (measured: up to 6) and the
 * compensation stays within 5 % of the actuator's force (measured: 3.2 N). With
 * the plain gate for the hypotheses the + moves are not undone, on the reference
 * and on machines/heavy (on the hardware-like plant in closed loop F_d then swung
 * +-460 N period by period and the held axis latched ENC_FROZEN, br_faults
 * enc_spike_hold). The spike hypothesis misses by itself, toward +: on the
 * reference +1.5 gates is still undone, on machines/heavy from +1.2 it is not
 * (its own miss about 0.85 gate; the - moves are undone at every size, with the
 * plain gate too). */
static void test_glitch_undone_moved(void **st)
{
    (void)st;
    const br_pf_cfg_t c = load_cfg();
    assert_int_equal(init_with(c), BR_OK);
    const float F_act = c.load.max_N;
    /* the gate's distance in counts: l >= outlier_l <=> |e| <= sqrt(-2 R outlier_l) */
    const float gate = sqrtf(-2.0f * c.est.r_var_rad2 * g_pf.outlier_l) / c.est.rad_per_count;
    const float window = 0.95f * 2.0f * F_act * g_pf.load_g_radpN / c.est.rad_per_count;
    const int32_t off = (int32_t)lrintf(window * 5.0f / 16.0f);
    static const float share[] = {1.05f, 1.1f};
    for (unsigned i = 0; i < sizeof share / sizeof share[0]; i++) {
        for (int sign = -1; sign <= 1; sign += 2) {
            const int32_t moved = (int32_t)sign * (int32_t)lrintf(share[i] * gate);
            int acq_at, undone, n_out;
            float f;
            const int last = glitch_moved(off, 0, moved, &acq_at, &undone, &f, &n_out);
            printf("  spike %d, then moved %d (%.2f gates): %s%s, last re-acquisition at %d, max |F_hat| %.3g N\n",
                   (int)off, (int)moved, (double)share[i], acq_at ? "re-acquired" : "within the gate",
                   undone ? ", undone" : "", last, (double)f);
            assert_true(acq_at);
            assert_true(undone);
            assert_true(last <= 212);
            assert_true(f < 0.05f * F_act);
        }
    }
}

/* A frictionless axis (the model's J_eff) held near rest by a PD on the counts with
 * the PF's compensation added (tau = Kp e + Kd de/dt + L F_comp, within the torque
 * limit), the torque reaching it delay_s later: the command of period j acts over
 * [j h + delay, (j + 1) h + delay), integrated exactly (double, NSUB substeps a
 * period). The PF knows the delay (cfg.est.model.causes.delay_s). Runs n periods;
 * returns the largest change of F_d from one period to the next over the second
 * half (the swing of a period-2 ring; the frictionless axis leaves F_d the
 * model's friction, up to F_s, to cancel), *steps the steps that were not BR_OK
 * or BR_W_OUTLIER (0 expected). */
#define LOOP_NSUB 48
#define LOOP_HIST 8
static float run_delayed_loop(double delay_s, int n, int *steps)
{
    br_pf_cfg_t c = load_cfg();
    c.est.model.causes.delay_s = (float)delay_s;
    assert_int_equal(init_with(c), BR_OK);
    const br_est_t e = br_pf_est(&g_pf);
    const br_model_cfg_t *m = &c.est.model;
    const double h = m->dt_s, L = m->lead_mprad, Jeff = m->J_kgm2 + L * L * m->M_kg;
    const double rpc = c.est.rad_per_count, tau_max = BR_MACHINE_TORQUE_LIMIT_NM_F;
    /* a PD of 100 rad/s and damping 0.7 on the axis' inertia: 2 ms of delay leaves it stable */
    const double wc = 100.0, kp = Jeff * wc * wc, kd = 2.0 * 0.7 * Jeff * wc;
    double th = 0.0, om = 0.0, cmd[LOOP_HIST] = {0.0}, e_prev = 0.0;
    float u_prev = 0.0f, fd_prev = 0.0f, swing = 0.0f;
    *steps = 0;
    for (int k = 0; k < n; k++) {
        /* the count's centre, as the application gives it */
        const br_meas_t y = {(int32_t)floor(th / rpc + 0.5), 0.5f};
        float F = 0.0f;
        const br_status_t st = e.step(e.ctx, &y, u_prev, &F);
        *steps += !(st == BR_OK || st == BR_W_OUTLIER);
        /* a slow 20-count sine (2 Hz) as the reference */
        const double ref = 20.0 * rpc * sin(4.0 * 3.14159265358979 * (double)k * h);
        const double err = ref - (double)y.counts * rpc;
        double u = kp * err + kd * (err - e_prev) / h + L * (double)F;
        u = (u > tau_max) ? tau_max : ((u < -tau_max) ? -tau_max : u);
        e_prev = err;
        cmd[k % LOOP_HIST] = u;
        u_prev = (float)u;
        /* the period [k h, (k + 1) h): each substep the command issued delay_s before it */
        const double ds = h / LOOP_NSUB;
        for (int i = 0; i < LOOP_NSUB; i++) {
            const long j = (long)floor(((double)k * h + ((double)i + 0.5) * ds - delay_s) / h);
            const double tq = (j >= 0 && j > k - LOOP_HIST) ? cmd[j % LOOP_HIST] : 0.0;
            th += om * ds + 0.5 * tq / Jeff * ds * ds;
            om += tq / Jeff * ds;
        }
        if (k >= n / 2) {
            swing = fmaxf(swing, fabsf(g_pf.load_N - fd_prev));
        }
        fd_prev = g_pf.load_N;
    }
    return swing;
}

/* docs/modules/pf.md, "The period-2 mode": with the compensation of F_d itself (not
 * filtered) an actuator delay of 2 ms made F_d ring at the PF's period and grow to
 * the actuator's force (the loop's map: an eigenvalue of -1.23 at q = 1e4 N^2/s);
 * through the notch it stays within a few newtons. 0 and 1 ms held before too. */
static void test_delay_loop_no_ring(void **st)
{
    (void)st;
    static const double delay_s[] = {0.0, 1.0e-3, 2.0e-3, 2.263e-3};
    for (unsigned i = 0; i < sizeof delay_s / sizeof delay_s[0]; i++) {
        int bad = 0;
        const float sw = run_delayed_loop(delay_s[i], 700, &bad);
        printf("  delay %.3f ms: largest change of F_d in a period over the second half %.2f N\n",
               delay_s[i] * 1e3, (double)sw);
        assert_int_equal(bad, 0);
        assert_true(sw < 0.02f * g_pf.cfg.load.max_N);
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
        cmocka_unit_test(test_glitch_undone_moved),
        cmocka_unit_test(test_delay_loop_no_ring),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
