/* SPDX-License-Identifier: Apache-2.0 */
/* LuGre drift under a cyclic load below breakaway (docs/modules/lugre.md,
 * "Drift below breakaway"). The LuGre bristle equation has no purely elastic
 * region: every bristle move with v != 0 relaxes z towards g/sigma0 a little,
 * so a load that cycles between two levels below the breakaway force ratchets
 * the axis forward by the same amount every cycle, without bound (Dupont,
 * Hayward, Armstrong, Altpeter 2002, who introduced the elastoplastic model to
 * remove it). The plant reproduces it; this test measures it on the reference
 * machine and holds it at the documented figures, so a change of the
 * plant's bristle integration that alters it is seen. */
#include "br_test.h"

#include "plant/br_sim_plant.h"

#define PI 3.14159265358979323846

/* the documented case: F(t) = Fc (MEAN + AMP sin(2 pi t / period)) at the
 * load, between 0.1 Fc and 0.9 Fc, CYCLES cycles */
#define MEAN 0.5
#define AMP 0.4
#define PERIOD_S 0.5
#define CYCLES 20
#define DT_S 1.0e-4
/* drift per cycle of the documented case (measured by this test on the
 * reference machine, docs/modules/lugre.md), and the relative band it is held in */
#define DRIFT_PER_CYCLE_M 7.858e-7
#define DRIFT_TOL 0.02

/* load position (m) after each cycle into x[0..CYCLES] */
static void run_cycles(double mean, double amp, double period_s, double x[CYCLES + 1])
{
    br_plant_t p;
    const br_plant_cfg_t c = br_plant_cfg_reference();
    const br_plant_state_t rest = {0.0, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    const int per_cycle = (int)(period_s / DT_S + 0.5);
    x[0] = br_plant_pos_m(&p);
    for (int k = 0; k < CYCLES; k++) {
        for (int i = 0; i < per_cycle; i++) {
            const double t = (k * per_cycle + i + 0.5) * DT_S;
            const double F = c.Fc_N * (mean + amp * sin(2.0 * PI * t / period_s));
            br_plant_step(&p, F * c.lead_mprad / c.tau_per_duty_Nm, DT_S);
        }
        x[k + 1] = br_plant_pos_m(&p);
    }
}

static void test_drift_below_breakaway(void **st)
{
    (void)st;
    double x[CYCLES + 1], xs[CYCLES + 1];
    run_cycles(MEAN, AMP, PERIOD_S, x);
    run_cycles(MEAN, 0.0, PERIOD_S, xs); /* the same mean load, held */
    for (int k = 1; k <= CYCLES; k++) {
        print_message("cycle %2d: x = %.4g m (drift %.4g m); static load x = %.4g m\n", k, x[k], x[k] - x[k - 1],
                      xs[k]);
    }
    /* after the first cycles the same step forward every cycle: x grows
     * linearly with the number of cycles, without bound */
    for (int k = CYCLES / 2; k <= CYCLES; k++) {
        BR_ASSERT_NEAR(x[k] - x[k - 1], DRIFT_PER_CYCLE_M, DRIFT_TOL * DRIFT_PER_CYCLE_M);
    }
    BR_ASSERT_NEAR(x[CYCLES] - x[CYCLES / 2], (CYCLES / 2) * DRIFT_PER_CYCLE_M,
                   DRIFT_TOL * (CYCLES / 2) * DRIFT_PER_CYCLE_M);
    /* the held load only deflects the bristles (presliding): no drift */
    BR_ASSERT_NEAR(xs[CYCLES], xs[CYCLES / 2], 1e-3 * DRIFT_PER_CYCLE_M);
}

/* Slower loads approach a quasi-static drift per cycle (about 0.6 um here);
 * faster ones drift more, the load exciting the presliding ring. Two more
 * periods of the table in docs/modules/lugre.md, held in the same band. */
static void test_drift_against_period(void **st)
{
    (void)st;
    const struct {
        double period_s, drift_m;
    } cases[] = {{0.1, 3.966e-6}, {2.0, 6.238e-7}};
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        double x[CYCLES + 1];
        run_cycles(MEAN, AMP, cases[i].period_s, x);
        const double d = x[CYCLES] - x[CYCLES - 1];
        print_message("period %.2g s: drift %.4g m per cycle\n", cases[i].period_s, d);
        BR_ASSERT_NEAR(d, cases[i].drift_m, DRIFT_TOL * cases[i].drift_m);
    }
}

/* 1000 cycles of the fastest load of the table (T = 0.05 s, 50 s of load):
 * the drift stays within the documented bound, 1000 x the per-cycle figure of
 * docs/modules/lugre.md (4.86 um), i.e. linear, neither accelerating nor
 * turning into a breakaway. */
static void test_drift_1000_cycles(void **st)
{
    (void)st;
    br_plant_t p;
    const br_plant_cfg_t c = br_plant_cfg_reference();
    const br_plant_state_t rest = {0.0, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &c, &rest), 0);
    const double T = 0.05, dt = 5.0e-4, per_cycle_m = 4.858e-6;
    const int per = (int)(T / dt + 0.5);
    double x500 = 0.0;
    for (long k = 0; k < 1000L * per; k++) {
        const double F = c.Fc_N * (MEAN + AMP * sin(2.0 * PI * ((double)k + 0.5) * dt / T));
        br_plant_step(&p, F * c.lead_mprad / c.tau_per_duty_Nm, dt);
        if (k + 1 == 500L * per) x500 = br_plant_pos_m(&p);
    }
    const double x = br_plant_pos_m(&p);
    print_message("1000 cycles of %.2g s: %.4g m (%.4g m per cycle)\n", T, x, x / 1000.0);
    assert_true(isfinite(x) && x > 0.0);
    assert_true(x <= 1000.0 * per_cycle_m * (1.0 + DRIFT_TOL));
    /* linear: the second 500 cycles drift as much as the first (no breakaway) */
    BR_ASSERT_NEAR(x - x500, x500, DRIFT_TOL * x500);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_drift_below_breakaway),
        cmocka_unit_test(test_drift_against_period),
        cmocka_unit_test(test_drift_1000_cycles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
