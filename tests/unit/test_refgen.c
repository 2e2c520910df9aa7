/* SPDX-License-Identifier: Apache-2.0 */
/* Sinusoidal reference generator: guards, amplitude and phase against a
 * double-precision evaluation of the same float configuration, phase
 * accuracy after a million steps, fractional counts in [0, 1). */
#include "br_test.h"

#include <float.h>

#include "bristle/br_refgen.h"
#include "bristle_gen/machine/br_machine.h"

#define TWO_PI 6.283185307179586476925

/* A 5 mm, 2 s sine on the machine (its lead, encoder and control period). */
static br_refgen_cfg_t cfg_default(void)
{
    br_refgen_cfg_t c;
    c.amplitude_m = 5.0e-3f;
    c.period_s = 2.0f;
    c.phase_rad = 0.0f;
    c.dt_s = BR_MACHINE_CTRL_PERIOD_S_F;
    c.lead_mprad = BR_MACHINE_LEAD_MPRAD_F;
    c.rad_per_count = BR_MACHINE_RAD_PER_COUNT_F;
    return c;
}

/* Double evaluation of the header's equations for step k, from the float cfg. */
static double exact_phase(const br_refgen_cfg_t *c, double k)
{
    double turns = (double)c->phase_rad / TWO_PI + k * ((double)c->dt_s / (double)c->period_s);
    turns -= floor(turns);
    return turns * TWO_PI;
}

static double exact_counts(const br_refgen_cfg_t *c, double k)
{
    double amp = (double)c->amplitude_m / (double)c->lead_mprad / (double)c->rad_per_count;
    return amp * sin(exact_phase(c, k));
}

static double exact_omega(const br_refgen_cfg_t *c, double k)
{
    double amp = (double)c->amplitude_m / (double)c->lead_mprad * TWO_PI / (double)c->period_s;
    return amp * cos(exact_phase(c, k));
}

static double ref_total(const br_ref_t *r)
{
    return (double)r->ref_counts + (double)r->ref_frac_counts;
}

/* Float tolerance for a value of amplitude amp: the angle carries ~1 ulp of
 * pi plus the float 2 pi (together < 3.3e-7 rad), sinf/cosf ~1 ulp of the
 * unit value, the amplitude and the product 2-3 roundings: < 6e-7 amp.
 * 8 ulp(1) = 9.5e-7 leaves margin without hiding a real error (a one-step
 * phase slip would be 2 pi dt / T = 3e-3 amp here). */
static double float_tol(double amp)
{
    return 8.0 * (double)FLT_EPSILON * amp;
}

/* The initial phase is reduced to a turn in float (whole turns removed
 * against a two-float 2 pi): the reduced angle carries about one rounding of
 * a value below 2 pi, a constant offset on every step. The bound does not
 * grow with |phase| (a plain float reduction would: ulp(phase / 2 pi)). */
static double phase0_tol(float phase_rad)
{
    (void)phase_rad;
    return 2.0 * (double)FLT_EPSILON * TWO_PI;
}

static void test_guards(void **st)
{
    (void)st;
    br_refgen_t g;
    br_ref_t r;
    br_refgen_cfg_t c = cfg_default();

    assert_int_equal(br_refgen_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_refgen_init(&g, NULL), BR_E_NULL);

    float *fields[] = {&c.amplitude_m, &c.period_s, &c.dt_s, &c.lead_mprad, &c.rad_per_count};
    const float bad[] = {0.0f, -1.0f, NAN, INFINITY, -INFINITY};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; ++i) {
        for (size_t j = 0; j < sizeof bad / sizeof bad[0]; ++j) {
            c = cfg_default(); /* fields[] keeps pointing into c */
            *fields[i] = bad[j];
            assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);
            assert_int_equal(br_refgen_step(&g, &r), BR_E_STATE);
        }
    }
    c = cfg_default();
    c.phase_rad = NAN;
    assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);
    c.phase_rad = INFINITY;
    assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);

    /* Nyquist: at least two steps per period */
    c = cfg_default();
    c.period_s = 1.9e-3f;
    assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);
    c.period_s = 2.0e-3f;
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    /* at most 2^32 steps per period */
    c.period_s = 1.0e7f;
    assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);

    /* amplitude beyond 2^30 counts (int32 headroom; 4.1 m on the reference) */
    c = cfg_default();
    const float a_max_m = 1073741824.0f * c.rad_per_count * c.lead_mprad;
    c.amplitude_m = 0.5f * a_max_m; /* accepted */
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    c.amplitude_m = 1.25f * a_max_m;
    assert_int_equal(br_refgen_init(&g, &c), BR_E_PARAM);
    assert_int_equal(br_refgen_step(&g, &r), BR_E_STATE); /* a failed init leaves it unready */
    assert_true(br_refgen_phase_rad(&g) == 0.0f);
    assert_true(br_refgen_phase_rad(NULL) == 0.0f);

    c = cfg_default();
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    assert_int_equal(br_refgen_step(NULL, &r), BR_E_NULL);
    assert_int_equal(br_refgen_step(&g, NULL), BR_E_NULL);
    assert_int_equal(br_refgen_step(&g, &r), BR_OK);
}

/* Two periods at several initial phases, every step compared with double. */
static void test_amplitude_and_phase(void **st)
{
    (void)st;
    const float phases[] = {0.0f, 0.5f, (float)(TWO_PI / 4.0), -3.0f * (float)(TWO_PI / 2.0), 100.0f};
    for (size_t p = 0; p < sizeof phases / sizeof phases[0]; ++p) {
        br_refgen_cfg_t c = cfg_default();
        c.phase_rad = phases[p];
        br_refgen_t g;
        assert_int_equal(br_refgen_init(&g, &c), BR_OK);
        double amp_counts = (double)c.amplitude_m / (double)c.lead_mprad / (double)c.rad_per_count;
        double amp_omega = (double)c.amplitude_m / (double)c.lead_mprad * TWO_PI / (double)c.period_s;
        double max_c = 0.0, max_w = 0.0, peak = 0.0;
        for (int k = 0; k < 4000; ++k) {
            br_ref_t r;
            assert_int_equal(br_refgen_step(&g, &r), BR_OK);
            double dc = fabs(ref_total(&r) - exact_counts(&c, k));
            double dw = fabs((double)r.ref_omega_radps - exact_omega(&c, k));
            max_c = dc > max_c ? dc : max_c;
            max_w = dw > max_w ? dw : max_w;
            peak = fabs(ref_total(&r)) > peak ? fabs(ref_total(&r)) : peak;
        }
        /* the initial phase is a float phase reduced to a turn: its own
         * rounding (~ulp(phase)) adds to the per-step tolerance */
        double phase_tol = phase0_tol(phases[p]);
        BR_ASSERT_NEAR(max_c, 0.0, float_tol(amp_counts) + amp_counts * phase_tol);
        BR_ASSERT_NEAR(max_w, 0.0, float_tol(amp_omega) + amp_omega * phase_tol);
        /* the amplitude itself: A / (L r) = A / lead * counts_per_rev (655360 counts
         * for 5 mm on the reference) */
        BR_ASSERT_NEAR(peak, amp_counts, float_tol(amp_counts) + amp_counts * 1e-5);
        BR_ASSERT_NEAR(amp_counts, 5.0e-3 / (TWO_PI * BR_MACHINE_LEAD_MPRAD) * BR_MACHINE_COUNTS_PER_REV, 1.0);
    }
}

/* A million steps of a period that is not a whole number of steps: the phase
 * (read back and through the output) stays within float resolution of the
 * double reference. A float accumulator would drift by ~1e6 * ulp(pi). */
static void test_phase_after_1e6_steps(void **st)
{
    (void)st;
    br_refgen_cfg_t c = cfg_default();
    c.period_s = 0.3713f;
    c.phase_rad = 1.0f;
    br_refgen_t g;
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    double amp_counts = (double)c.amplitude_m / (double)c.lead_mprad / (double)c.rad_per_count;
    const int n = 1000000;
    br_ref_t r;
    double max_c = 0.0;
    for (int k = 0; k < n; ++k) {
        float ph = br_refgen_phase_rad(&g);
        assert_true(ph >= 0.0f && ph < (float)TWO_PI);
        assert_int_equal(br_refgen_step(&g, &r), BR_OK);
        assert_true(r.ref_frac_counts >= 0.0f && r.ref_frac_counts < 1.0f);
        if (k > n - 2000) {
            double dc = fabs(ref_total(&r) - exact_counts(&c, k));
            max_c = dc > max_c ? dc : max_c;
        }
    }
    /* the phase of step n, read back: getter resolution 2 pi / 2^24 */
    double want = exact_phase(&c, n);
    double got = (double)br_refgen_phase_rad(&g);
    double d = fabs(got - want);
    d = d > TWO_PI / 2.0 ? TWO_PI - d : d; /* circular distance */
    BR_ASSERT_NEAR(d, 0.0, 1e-6);
    BR_ASSERT_NEAR(max_c, 0.0, float_tol(amp_counts) + amp_counts * phase0_tol(c.phase_rad));
}

/* Outputs stay consistent: the integer/fraction split is exact and the
 * velocity is the derivative of the position (central difference). */
static void test_frac_and_velocity(void **st)
{
    (void)st;
    br_refgen_cfg_t c = cfg_default();
    c.amplitude_m = 1.0e-6f; /* small: about 131 counts, the fraction matters */
    c.phase_rad = 0.3f;
    br_refgen_t g;
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    double pos[3] = {0.0, 0.0, 0.0};
    double amp_omega = (double)c.amplitude_m / (double)c.lead_mprad * TWO_PI / (double)c.period_s;
    double w = TWO_PI / (double)c.period_s;
    for (int k = 0; k < 4000; ++k) {
        br_ref_t r;
        assert_int_equal(br_refgen_step(&g, &r), BR_OK);
        assert_true(r.ref_frac_counts >= 0.0f && r.ref_frac_counts < 1.0f);
        pos[0] = pos[1];
        pos[1] = pos[2];
        pos[2] = ref_total(&r);
        if (k >= 2) {
            /* omega at k-1 from the neighbours: error (w dt)^2 / 6 relative */
            double fd = (pos[2] - pos[0]) / (2.0 * (double)c.dt_s) * (double)c.rad_per_count;
            double om = exact_omega(&c, k - 1);
            BR_ASSERT_NEAR(fd, om, amp_omega * ((w * c.dt_s) * (w * c.dt_s) / 6.0 + 1e-4));
        }
    }
    /* negative positions: floor, not truncation, so frac stays in [0, 1) */
    c = cfg_default();
    c.phase_rad = -1.0f;
    assert_int_equal(br_refgen_init(&g, &c), BR_OK);
    br_ref_t r;
    assert_int_equal(br_refgen_step(&g, &r), BR_OK);
    assert_true(r.ref_counts < 0);
    assert_true(r.ref_frac_counts >= 0.0f && r.ref_frac_counts < 1.0f);
    BR_ASSERT_NEAR(ref_total(&r), exact_counts(&c, 0), 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_guards),
        cmocka_unit_test(test_amplitude_and_phase),
        cmocka_unit_test(test_phase_after_1e6_steps),
        cmocka_unit_test(test_frac_and_velocity),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
