/* SPDX-License-Identifier: Apache-2.0 */
/* The actuator-delay identification (br_est_dlyid_*, docs/modules/dlyid.md):
 * its configuration is checked at init; on an axis of the test's own (a rigid
 * body with a smooth Coulomb and a viscous friction, integrated finely in
 * double, the torque delayed to the instant) it finds the delay the axis has
 * and keeps the one the estimator already models; a bank that overflows
 * starts again and still finds it; a step without a measurement restarts it;
 * with no switch the estimators are bit for bit those without it. The
 * machine's settings are read from the machine's configuration. */
#include "br_test.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle_est.h"
#include "bristle/br_est.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

/* the machine's periods: the UKF at the control period, the PF at its own */
#define UKF_DT_S BR_MACHINE_CTRL_PERIOD_S_F
#define PF_DT_S BR_EST_PF_PERIOD_S_F
#define SUBSTEPS 20
#define TWO_PI 6.283185307179586

/* The test's axis: J_eff omega' = u(t - delay) - L (Fc tanh(v / v0) + sigma2 v), v = L omega,
 * with the estimator model's mass, lead and levels; commands held over each period. */
typedef struct {
    double th, om, t;
    double J, L, Fc, v0, s2, delay, dt;
    double u[256]; /* commands, u[k] over [k dt, (k + 1) dt) */
    int k;
} axis_t;

static void axis_init(axis_t *a, const br_est_cfg_t *c, double delay_s)
{
    memset(a, 0, sizeof *a);
    const br_model_cfg_t *m = &c->model;
    a->L = m->lead_mprad;
    a->J = (double)m->J_kgm2 + a->L * a->L * (double)m->M_kg;
    a->Fc = m->lugre.Fc_N;
    a->v0 = 1.0e-4;
    a->s2 = m->sigma2_Nspm;
    a->delay = delay_s;
    a->dt = m->dt_s;
}

/* the command of period k: two tones and a slow sweep, in units of the machine's Coulomb
 * torque L Fc */
static float command(const axis_t *a, int k)
{
    const double t = k * a->dt, lfc = a->L * a->Fc;
    return (float)(lfc * (2.25 * sin(TWO_PI * 3.0 * t) + 0.9 * sin(TWO_PI * 37.0 * t) +
                          0.45 * sin(TWO_PI * (10.0 + 20.0 * t) * t)));
}

/* one period with command u (kept), then the measurement: the count below theta, frac 0.5 */
static br_meas_t axis_step(axis_t *a, float u, double rpc)
{
    a->u[a->k % 256] = u;
    const double h = a->dt / SUBSTEPS;
    for (int s = 0; s < SUBSTEPS; s++) {
        const double tm = a->t + 0.5 * h - a->delay; /* the command reaching the axis mid-substep */
        const long j = (long)floor(tm / a->dt + 1e-9);
        const double ua = (j < 0 || a->k - j >= 256) ? 0.0 : a->u[j % 256];
        const double v = a->L * a->om;
        const double F = a->Fc * tanh(v / a->v0) + a->s2 * v;
        const double acc = (ua - a->L * F) / a->J;
        a->th += h * a->om + 0.5 * h * h * acc;
        a->om += h * acc;
        a->t += h;
    }
    a->k++;
    const br_meas_t y = {(int32_t)floor(a->th / rpc), 0.5f};
    return y;
}

/* one period of axis a and the bank with the command u_prev (the last period's) */
static void bank_period(const br_est_cfg_t *c, axis_t *a, br_est_delay_t *d, br_dlyid_t *id, float u_prev)
{
    const br_meas_t y = axis_step(a, u_prev, c->rad_per_count);
    (void)br_est_delay_apply(d, u_prev);
    br_est_dlyid_step(id, c, &y, d);
}

/* the bank from its start on axis a over n periods, a, d and id left where they are for a
 * further period (bank_period); *u_prev the next command */
static void bank_periods(const br_est_cfg_t *c, int n, axis_t *a, br_est_delay_t *d, br_dlyid_t *id,
                         float *u_prev)
{
    br_est_delay_init(d, c);
    br_est_dlyid_init(id, c);
    *u_prev = 0.0f;
    for (int k = 0; k < n; k++) {
        bank_period(c, a, d, id, *u_prev);
        *u_prev = command(a, k + 1);
    }
}

/* runs the bank on a copy of axis a0 for n periods; returns the switches */
static uint32_t run_bank_on(axis_t *a0, const br_est_cfg_t *c, int n, br_est_delay_t *d, br_dlyid_t *id)
{
    axis_t a = *a0;
    float u_prev;
    bank_periods(c, n, &a, d, id, &u_prev);
    return id->n_switch;
}

/* runs the bank on the test's axis for n periods; returns the switches */
static uint32_t run_bank(const br_est_cfg_t *c, double delay_s, int n, br_est_delay_t *d, br_dlyid_t *id)
{
    axis_t a;
    axis_init(&a, c, delay_s);
    return run_bank_on(&a, c, n, d, id);
}

/* the delay the estimator now models, in seconds */
static double modelled_s(const br_est_delay_t *d, const br_est_cfg_t *c)
{
    return ((double)d->m + (double)d->f) * (double)c->model.dt_s;
}

static br_est_cfg_t machine_ukf(void) { return br_circle_ukf_cfg_tuned(UKF_DT_S).est; }
static br_est_cfg_t machine_pf(void) { return br_circle_pf_cfg_tuned(PF_DT_S).est; }

/* c is refused, and the same configuration with the bank off is not. The
 * bristles are made so soft and undamped that the model's own sub-step bound
 * (br_model.h, BR_MODEL_SUBSTEP_MAX) holds at these extreme periods and
 * inertias: the refusal is the bank's alone. */
static void refused_only_with_the_bank(br_est_cfg_t c)
{
    c.model.lugre.sigma0_Npm = 1e-38f;
    c.model.lugre.sigma1_Nspm = 0.0f;
    c.model.sigma2_Nspm = 0.0f;
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.delay_id.n_cand = 0u;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
}

static void test_dlyid_bounds(void **st)
{
    (void)st;
    const br_est_cfg_t ok = machine_ukf();
    assert_true(ok.delay_id.n_cand >= 2u); /* the machine has it on */
    assert_int_equal(br_est_cfg_check(&ok), BR_OK);
    br_est_cfg_t c = ok;
    const float dt = ok.model.dt_s;
/* base with field set to v is refused */
#define REFUSED_FROM(base, field, v)                                                               \
    do {                                                                                           \
        c = (base);                                                                                \
        c.delay_id.field = (v);                                                                    \
        assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);                                        \
    } while (0)
#define REFUSED(field, v) REFUSED_FROM(ok, field, v)
    REFUSED(n_cand, 1u);
    REFUSED(n_cand, BR_DLYID_MAX_CAND + 1u);
    REFUSED(step_s, 0.0f);
    REFUSED(step_s, NAN);
    REFUSED(step_s, INFINITY);
    REFUSED(q_force_N2ps, 0.0f);
    REFUSED(q_force_N2ps, NAN);
    REFUSED(q_force_N2ps, INFINITY);
    REFUSED(memory_s, 0.0f);
    REFUSED(memory_s, 1.0e12f * dt); /* e^(-dt / memory) rounds to 1: the sums would never forget */
    REFUSED(memory_s, NAN);
    REFUSED(memory_s, INFINITY);
    REFUSED(warmup_s, -1.0e-6f);
    REFUSED(warmup_s, NAN);
    REFUSED(warmup_s, 2.0e9f * dt);
    REFUSED(switch_ratio, 0.0f);
    REFUSED(switch_ratio, 1.0f);
    REFUSED(switch_ratio, NAN);
    /* the steady phase: off at 0; a time within the warm-up's bound with a memory and a ratio */
    REFUSED(steady_after_s, -1.0e-6f);
    REFUSED(steady_after_s, NAN);
    REFUSED(steady_after_s, 2.0e9f * dt);
#undef REFUSED
    c = ok;
    c.delay_id.steady_after_s = 0.1f;
    c.delay_id.steady_memory_s = 0.02f;
    c.delay_id.steady_switch_ratio = 0.5f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    {
        const br_est_cfg_t on = c;
#define REFUSED_ON(field, v) REFUSED_FROM(on, field, v)
        REFUSED_ON(steady_memory_s, 0.0f);
        REFUSED_ON(steady_memory_s, NAN);
        REFUSED_ON(steady_memory_s, 1.0e12f * dt); /* its forgetting rounds to 1 */
        REFUSED_ON(steady_switch_ratio, 0.0f);
        REFUSED_ON(steady_switch_ratio, 1.0f);
        REFUSED_ON(steady_switch_ratio, NAN);
#undef REFUSED_ON
    }
#undef REFUSED_FROM
    /* off (0): its memory and ratio are not looked at */
    c = ok;
    c.delay_id.steady_after_s = 0.0f;
    c.delay_id.steady_memory_s = NAN;
    c.delay_id.steady_switch_ratio = 7.0f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* the largest candidate at the command history's end: kept; beyond it: refused */
    c = ok;
    c.delay_id.n_cand = BR_DLYID_MAX_CAND;
    c.delay_id.step_s = (float)(BR_EST_DELAY_HIST - 2u) * dt / (float)(BR_DLYID_MAX_CAND - 1u);
    c.delay_id.step_s = nextafterf(c.delay_id.step_s, 0.0f);
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    c.delay_id.step_s = 1.01f * (float)(BR_EST_DELAY_HIST - 2u) * dt / (float)(BR_DLYID_MAX_CAND - 1u);
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    /* a period so long that the bank's constant L T^2 / (2 J_eff) overflows (a02; b1 and a12
     * stay finite), with bristles soft enough that the model's sub-step bound holds and the
     * presliding length (dly7) stays finite: a02's check is the only one that refuses */
    c = ok;
    {
        const double L = (double)c.model.lead_mprad;
        const double J = (double)c.model.J_kgm2 + (double)c.model.M_kg * L * L;
        c.gp_min_N = 0.5f;
        c.gp0_N = 0.75f;
        c.gp_max_N = 1.0f;
        /* settle_rad = 3 g_p,max / (sigma0 L) = FLT_MAX / 2 */
        c.model.lugre.sigma0_Npm = (float)(2.0 * (double)BR_DLYID_SETTLE_LENGTHS / ((double)FLT_MAX * L));
        c.model.lugre.sigma1_Nspm = 0.0f;
        c.model.sigma2_Nspm = 0.0f;
        /* L T^2 / (2 J_eff) = 2 FLT_MAX; (omega_n T)^2 = (sigma0 L)(L T^2 / J_eff) = 24 */
        c.model.dt_s = (float)sqrt(4.0 * (double)FLT_MAX * J / L);
    }
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.delay_id.n_cand = 0u;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* a lead and an inertia at which L T / J_eff overflows, L T^2 / (2 J_eff) not */
    c = ok;
    c.model.lead_mprad = 1.8e19f;
    c.model.M_kg = 0.0f;
    c.model.J_kgm2 = 1.0e-23f;
    assert_true(isfinite(-c.model.lead_mprad * (0.5f * c.model.dt_s * c.model.dt_s / c.model.J_kgm2)));
    /* the model refuses it first: its inertia at the load J / L^2 rounds to 0 (br_model_init's
     * sub-step choice), with the bank on or off */
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.delay_id.n_cand = 0u;
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    /* the friction's variance per period q T beyond float range, at a 100 s period */
    c = ok;
    c.model.dt_s = 100.0f;
    c.model.lugre.sigma0_Npm = 1.0f; /* the model's sub-steps hold at such a period (rho h ~ 20) */
    c.model.lugre.sigma1_Nspm = 0.0f;
    c.model.sigma2_Nspm = 0.0f;
    c.delay_id.q_force_N2ps = 1.0e37f;
    assert_int_equal(br_est_cfg_check(&c), BR_E_PARAM);
    c.delay_id.q_force_N2ps = 1.0e35f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* sigma0 L underflowing to 0 (the presliding length of dly7 would divide by it) */
    c = ok;
    c.model.lugre.sigma0_Npm = 1.0e-30f;
    c.model.lead_mprad = 1.0e-20f;
    assert_true(c.model.lugre.sigma0_Npm * c.model.lead_mprad == 0.0f);
    refused_only_with_the_bank(c);
    /* off: the other fields are not looked at */
    c = ok;
    c.delay_id.n_cand = 0u;
    c.delay_id.step_s = NAN;
    c.delay_id.switch_ratio = 7.0f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    /* both filters refuse a bad one at init */
    br_ukf_t u;
    br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    cu.est.delay_id.switch_ratio = 1.5f;
    assert_int_equal(br_ukf_init(&u, &cu), BR_E_PARAM);
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t cp = br_circle_pf_cfg_tuned(PF_DT_S);
    cp.est.delay_id.n_cand = 1u;
    assert_int_equal(br_pf_init(pf, &cp), BR_E_PARAM);
    free(pf);
}

/* An axis 1.5 ms late: the bank moves the estimator's delay to the candidate nearest
 * 1.5 ms within the first second, and an axis on time never moves it. */
static void test_dlyid_finds_delay(void **st)
{
    (void)st;
    const br_est_cfg_t c = machine_ukf();
    br_est_delay_t d;
    br_dlyid_t id;
    const double step = c.delay_id.step_s;
    assert_true(run_bank(&c, 1.5e-3, 1000, &d, &id) >= 1u);
    assert_true(fabs(modelled_s(&d, &c) - 1.5e-3) <= 0.5 * step + 1e-9);
    assert_int_equal(d.on, 1);
    /* in time: no switch in 3 s, the estimator's torque the command itself */
    assert_int_equal(run_bank(&c, 0.0, 3000, &d, &id), 0u);
    assert_int_equal(d.m, 0u);
    assert_true(d.f == 0.0f);
}

/* The steady phase (docs/modules/dlyid.md, "A fast start, a slow steady state"): the PF's
 * setting finds an axis's 1.5 ms within the first second; with a steady phase from after
 * the run's end the bank is the one-phase bank bit for bit (the same switches, the same
 * sums); with one from the first periods on whose ratio no candidate can beat (1e-6) it
 * never switches: the phase's ratio is the one applied. And a phase whose memory is twice
 * the fast one's still finds the delay. */
static void test_dlyid_steady_phase(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_pf();
    c.delay_id.steady_after_s = 0.0f;
    br_est_delay_t d;
    br_dlyid_t one, id;
    const uint32_t n1 = run_bank(&c, 1.5e-3, 1000, &d, &one);
    assert_true(n1 >= 1u);
    const double found = modelled_s(&d, &c);
    /* after the run: one phase throughout */
    c.delay_id.steady_after_s = 2000.0f * c.model.dt_s;
    c.delay_id.steady_memory_s = 40.0f * c.delay_id.memory_s;
    c.delay_id.steady_switch_ratio = 1.0e-6f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    assert_int_equal(run_bank(&c, 1.5e-3, 1000, &d, &id), n1);
    assert_true(modelled_s(&d, &c) == found);
    assert_memory_equal(id.J, one.J, sizeof one.J);
    /* from the second period on, with a ratio nothing beats: no switch at all */
    c.delay_id.steady_after_s = c.model.dt_s;
    assert_int_equal(run_bank(&c, 1.5e-3, 1000, &d, &id), 0u);
    assert_true(modelled_s(&d, &c) == 0.0);
    /* with twice the memory (the setting measured in docs/modules/dlyid.md) and the one-phase
     * ratio: the delay found all the same */
    c.delay_id.steady_memory_s = 2.0f * c.delay_id.memory_s;
    c.delay_id.steady_switch_ratio = c.delay_id.switch_ratio;
    assert_true(run_bank(&c, 1.5e-3, 1000, &d, &id) >= 1u);
    assert_true(fabs(modelled_s(&d, &c) - 1.5e-3) <= 0.5 * (double)c.delay_id.step_s + 1e-9);
}

/* The estimator already models the axis's 1 ms: the bank keeps it. */
static void test_dlyid_keeps_the_modelled_delay(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    c.model.causes.delay_s = 1.0e-3f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    br_est_delay_t d;
    br_dlyid_t id;
    assert_int_equal(run_bank(&c, 1.0e-3, 3000, &d, &id), 0u);
    assert_true(fabs(modelled_s(&d, &c) - 1.0e-3) < 1e-9);
}

/* A command that overflows the bank's filters (finite, near FLT_MAX): the bank starts again
 * at the next measurement, switches nothing meanwhile, and still finds the delay after. */
static void test_dlyid_overflow_restarts(void **st)
{
    (void)st;
    /* the one-phase bank: the restart's own start phase is short of this axis's weak evidence,
     * and the steady phase's far steps (dly8) need a far better sum (docs/modules/dlyid.md,
     * "One step at a time") */
    br_est_cfg_t c = machine_ukf();
    c.delay_id.steady_after_s = 0.0f;
    br_est_delay_t d;
    br_dlyid_t id;
    br_est_delay_init(&d, &c);
    br_est_dlyid_init(&id, &c);
    axis_t a;
    axis_init(&a, &c, 1.5e-3);
    float u_prev = 0.0f;
    for (int k = 0; k < 1500; k++) {
        const br_meas_t y = axis_step(&a, (k == 5) ? 0.0f : u_prev, c.rad_per_count);
        /* period 5: the estimator is told of a torque the axis never got */
        const float told = (k == 5) ? 3.0e38f : u_prev;
        (void)br_est_delay_apply(&d, told);
        br_est_dlyid_step(&id, &c, &y, &d);
        if (k == 5) {
            assert_int_equal(id.primed, 0); /* the bank starts again */
            assert_int_equal(id.n_switch, 0u);
        }
        for (uint32_t j = 0; j < c.delay_id.n_cand; j++) {
            assert_true(isfinite(id.J[j]) || !id.primed);
        }
        u_prev = command(&a, k + 1);
    }
    assert_true(id.n_switch >= 1u);
    assert_true(fabs(modelled_s(&d, &c) - 1.5e-3) <= 0.5 * (double)c.delay_id.step_s + 1e-9);
}

/* A configured delay off the grid (5 ms; the candidates end at 3.5 ms) on an axis 3.5 ms
 * late: the bank's own filter for the configured delay scores it, and the estimator moves
 * to the candidate nearest the axis's. */
static void test_dlyid_leaves_an_off_grid_delay(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    const double largest = (double)(c.delay_id.n_cand - 1u) * (double)c.delay_id.step_s;
    c.model.causes.delay_s = (float)(largest + 1.5e-3);
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    br_est_delay_t d;
    br_dlyid_t id;
    assert_true(run_bank(&c, largest, 3000, &d, &id) >= 1u);
    assert_true(fabs(modelled_s(&d, &c) - largest) <= 0.5 * (double)c.delay_id.step_s + 1e-9);
}

/* A configuration no check has seen (more candidates than the bank holds): the bank does
 * nothing, and the estimator's delay stays the configured one. */
static void test_dlyid_unchecked_count_is_off(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    c.delay_id.n_cand = BR_DLYID_MAX_CAND + 1u;
    br_est_delay_t d;
    br_dlyid_t id;
    assert_int_equal(run_bank(&c, 1.5e-3, 500, &d, &id), 0u);
    assert_int_equal(id.primed, 0);
    assert_int_equal(d.m, 0u);
    assert_true(d.f == 0.0f);
}

/* A period without a measurement restarts the bank (its filters would miss a step). */
static void test_dlyid_predict_restarts(void **st)
{
    (void)st;
    br_ukf_t u;
    const br_ukf_cfg_t cu = br_circle_ukf_cfg_tuned(UKF_DT_S);
    assert_int_equal(br_ukf_init(&u, &cu), BR_OK);
    const br_meas_t y0 = {100, 0.5f}, y1 = {101, 0.5f};
    assert_false(BR_FAILED(br_ukf_step(&u, &y0, 0.0f)));
    assert_false(BR_FAILED(br_ukf_step(&u, &y1, 0.001f)));
    assert_int_equal(u.dlyid.primed, 1);
    assert_false(BR_FAILED(br_ukf_predict(&u, 0.001f)));
    assert_int_equal(u.dlyid.primed, 0);

    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t cp = br_circle_pf_cfg_tuned(PF_DT_S);
    cp.n_particles = 100u;
    assert_int_equal(br_pf_init(pf, &cp), BR_OK);
    assert_false(BR_FAILED(br_pf_step(pf, &y0, 0.0f)));
    assert_false(BR_FAILED(br_pf_step(pf, &y1, 0.001f)));
    assert_int_equal(pf->dlyid.primed, 1);
    assert_false(BR_FAILED(br_pf_predict(pf, 0.001f)));
    assert_int_equal(pf->dlyid.primed, 0);
    free(pf);
}

/* Without a switch the identification changes nothing: the UKF and the PF on the test's
 * axis (on time) give the same estimates, bit for bit, with it on and off. */
static void test_dlyid_on_without_switch_is_off(void **st)
{
    (void)st;
    br_ukf_cfg_t on = br_circle_ukf_cfg_tuned(UKF_DT_S), off = on;
    off.est.delay_id.n_cand = 0u;
    br_ukf_t a, b;
    assert_int_equal(br_ukf_init(&a, &on), BR_OK);
    assert_int_equal(br_ukf_init(&b, &off), BR_OK);
    assert_int_equal(a.delay.on, 1);
    assert_int_equal(b.delay.on, 0);
    br_pf_t *pa = calloc(1, sizeof *pa), *pb = calloc(1, sizeof *pb);
    assert_non_null(pa);
    assert_non_null(pb);
    br_pf_cfg_t pon = br_circle_pf_cfg_tuned(PF_DT_S), poff = pon;
    pon.n_particles = poff.n_particles = 200u;
    /* the PF's machine setting decides fast and switches at this axis's start (docs/modules/dlyid.md,
     * "False switches"): a ratio no candidate reaches keeps the bank running without a switch */
    pon.est.delay_id.switch_ratio = 1.0e-30f;
    poff.est.delay_id.n_cand = 0u;
    assert_int_equal(br_pf_init(pa, &pon), BR_OK);
    assert_int_equal(br_pf_init(pb, &poff), BR_OK);
    axis_t ax;
    axis_init(&ax, &on.est, 0.0);
    float u_prev = 0.0f;
    for (int k = 0; k < 600; k++) {
        const br_meas_t y = axis_step(&ax, u_prev, on.est.rad_per_count);
        float fa, fb;
        assert_int_equal(br_ukf_est_step(&a, &y, u_prev, &fa), br_ukf_est_step(&b, &y, u_prev, &fb));
        assert_memory_equal(&fa, &fb, sizeof fa);
        u_prev = command(&ax, k + 1);
    }
    axis_init(&ax, &pon.est, 0.0); /* the PF's own period */
    u_prev = 0.0f;
    for (int k = 0; k < 400; k++) {
        const br_meas_t y = axis_step(&ax, u_prev, pon.est.rad_per_count);
        float fa, fb;
        assert_int_equal(br_pf_est_step(pa, &y, u_prev, &fa), br_pf_est_step(pb, &y, u_prev, &fb));
        assert_memory_equal(&fa, &fb, sizeof fa);
        u_prev = command(&ax, k + 1);
    }
    assert_int_equal(pa->dlyid.n_switch, 0u);
    assert_int_equal(a.dlyid.n_switch, 0u);
    free(pa);
    free(pb);
}

/* The PF's setting (the faster one: 10 ms memory, ratio 0.6) on an axis on time. Sums at
 * the noise floor, whose ratio wanders below 0.6, and one period's event (a command step, the
 * friction's jump at a reversal) favour a wrong delay for a period or two: the bank keeps the
 * delay in use unless its sum is above the noise's and a candidate stays decisively best
 * (dly6; the EMPS chain's switch to 0.5 ms at an acceleration step and its lost lock). No
 * switch, with the smooth friction of the other tests and with one that jumps by 2 Fs within
 * 1 um/s; an axis 1.5 ms late with the sharp friction is still found. */
/* runs the bank on a for n periods and returns the switches after the first n0 (the
 * start, where the bank's filters converge from rest and a candidate may win a period or two
 * before the delay in use takes over again); the delay at the end is 0 */
static uint32_t switches_after(axis_t *a, const br_est_cfg_t *c, int n0, int n)
{
    br_est_delay_t d;
    br_dlyid_t id;
    const uint32_t s0 = run_bank_on(a, c, n0, &d, &id);
    const uint32_t s = run_bank_on(a, c, n, &d, &id);
    assert_true(s >= s0); /* the same run, longer: the start's switches are its first */
    assert_int_equal(d.m, 0u);
    assert_true(d.f == 0.0f);
    return s - s0;
}

/* the PF's setting, an axis on time with the smooth friction of the other tests: no switch
 * after the first 0.1 s */
static void test_dlyid_no_false_switch(void **st)
{
    (void)st;
    const br_est_cfg_t c = machine_pf();
    axis_t a;
    axis_init(&a, &c, 0.0);
    assert_int_equal(switches_after(&a, &c, (int)(0.1 / PF_DT_S), 6000), 0u);
}

/* the test's axis with a friction that jumps by 2 Fs within 1 um/s at each reversal */
static axis_t sharp_axis(const br_est_cfg_t *c, double delay_s)
{
    axis_t a;
    axis_init(&a, c, delay_s);
    a.Fc = c->model.lugre.Fs_N;
    a.v0 = 1.0e-6;
    return a;
}

/* the PF's setting on it, on time: no switch after the first 0.1 s */
static void test_dlyid_no_switch_at_reversals(void **st)
{
    (void)st;
    const br_est_cfg_t c = machine_pf();
    axis_t a = sharp_axis(&c, 0.0);
    assert_int_equal(switches_after(&a, &c, (int)(0.1 / PF_DT_S), 6000), 0u);
}

/* and 1.5 ms late: found */
static void test_dlyid_finds_delay_at_reversals(void **st)
{
    (void)st;
    const br_est_cfg_t c = machine_pf();
    br_est_delay_t d;
    br_dlyid_t id;
    axis_t a = sharp_axis(&c, 1.5e-3);
    assert_true(run_bank_on(&a, &c, 2000, &d, &id) >= 1u);
    assert_true(fabs(modelled_s(&d, &c) - 1.5e-3) <= 0.5 * (double)c.delay_id.step_s + 1e-9);
}

/* the bank on the test's axis (delay_s) from rest over `periods` periods (bank_periods) */
static void bank_run(const br_est_cfg_t *c, double delay_s, int periods, axis_t *a, br_est_delay_t *d,
                     br_dlyid_t *id, float *u_prev)
{
    axis_init(a, c, delay_s);
    bank_periods(c, periods, a, d, id, u_prev);
}

/* One step at a time (dly8; docs/modules/dlyid.md, "One step at a time"): in the steady phase a
 * candidate d steps along the grid from the delay in use takes over only when its sum is below
 * rho^d times the one in use's: a far candidate just decisive enough for a neighbour does not
 * take over (in a closed loop slot 0 won so by chance and the UKF's external force ran away), a
 * far one far better does, and so does a neighbour; the configured delay's slot is not a step.
 * Before the steady phase the one-phase rule (dly6): a far candidate below rho takes over. */
static uint32_t bank_then(br_est_cfg_t c, int low, float J_low, uint32_t *c0_out)
{
    const uint32_t n = c.delay_id.n_cand;
    br_est_delay_t d;
    br_dlyid_t id;
    axis_t a;
    float u_prev;
    bank_run(&c, 2.0e-3, 1000, &a, &d, &id, &u_prev);
    /* the first switch left the configured slot n for a candidate 2 or more from either end */
    assert_true(id.n_switch >= 1u && id.cur >= 2u && id.cur + 2u < n);
    *c0_out = id.cur;
    /* every sum 1 (far above the noise floor) but slot low's */
    for (uint32_t j = 0; j <= n; j++) {
        id.J[j] = ((int)j == low) ? J_low : 1.0f;
    }
    bank_period(&c, &a, &d, &id, u_prev);
    /* the history models the delay in use */
    assert_true(fabs(modelled_s(&d, &c) - (double)id.cur * (double)c.delay_id.step_s) < 1e-9);
    return id.cur;
}

static void test_dlyid_one_step_at_a_time(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    const uint32_t n = c.delay_id.n_cand;
    assert_true(n >= 6u);
    /* a steady phase from 0.5 s on (the first 1000 periods reach it) */
    const float rho = 0.5f;
    c.delay_id.steady_after_s = 0.5f;
    c.delay_id.steady_memory_s = 0.1f;
    c.delay_id.steady_switch_ratio = rho;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    assert_true(1000.0f * c.model.dt_s > c.delay_id.steady_after_s);
    uint32_t c0 = 0u, got;
    got = bank_then(c, -1, 1.0f, &c0);
    assert_int_equal(got, c0);
    const uint32_t start = c0;
    /* slot 0, start steps away, 0.9 rho^(start - 1) of the sum in use: kept */
    const float far = 0.9f * powf(rho, (float)(start - 1u));
    got = bank_then(c, 0, far, &c0);
    assert_int_equal(got, start);
    /* 0.9 rho^start: taken */
    got = bank_then(c, 0, 0.9f * powf(rho, (float)start), &c0);
    assert_int_equal(got, 0u);
    /* the configured delay's slot (0 ms here, as slot 0), far best: kept */
    got = bank_then(c, (int)n, 1.0e-30f, &c0);
    assert_int_equal(got, start);
    /* a neighbour either side at 0.9 rho: taken */
    got = bank_then(c, (int)start - 1, 0.9f * rho, &c0);
    assert_int_equal(got, start - 1u);
    got = bank_then(c, (int)start + 1, 0.9f * rho, &c0);
    assert_int_equal(got, start + 1u);
    /* before the steady phase: slot 0 at 0.9 rho^(start - 1) taken */
    c.delay_id.steady_after_s = 2.0f;
    got = bank_then(c, 0, far, &c0);
    assert_int_equal(c0, start);
    assert_int_equal(got, 0u);
}

/* dly8 from a configured delay off the grid (0.2 ms; its nearest candidate 0): in the steady
 * phase that candidate, within half a step, is taken when it fits better at all (a refinement,
 * d = 0); the next one, a step from it, only below rho times the configured one's sum. */
static void test_dlyid_off_grid_start_refined(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    c.model.causes.delay_s = 0.2e-3f;
    /* the steady phase from the 300th period on: the manipulated period is in it */
    c.delay_id.steady_after_s = 300.0f * c.model.dt_s;
    c.delay_id.steady_memory_s = 0.1f;
    c.delay_id.steady_switch_ratio = 0.5f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    const uint32_t n = c.delay_id.n_cand;
    /* (slot, its sum against the configured one's 1, the slot in use after the period) */
    static const struct {
        uint32_t slot;
        float J;
        int taken;
    } cases[] = {{0u, 0.9f, 1}, {1u, 0.9f, 0}, {1u, 0.45f, 1}};
    for (unsigned t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        br_est_delay_t d;
        br_dlyid_t id;
        axis_t a;
        float u_prev;
        /* the axis's delay the configured one: nothing better before */
        bank_run(&c, 0.2e-3, 301, &a, &d, &id, &u_prev);
        assert_int_equal(id.cur, n); /* still the configured delay */
        assert_true(id.k >= id.steady); /* the next period is in the steady phase */
        for (uint32_t j = 0; j <= n; j++) {
            id.J[j] = 1.0f;
        }
        id.J[cases[t].slot] = cases[t].J;
        bank_period(&c, &a, &d, &id, u_prev);
        assert_int_equal(id.cur, cases[t].taken ? cases[t].slot : n);
    }
}

/* The noise floor (dly6; docs/modules/dlyid.md, "False switches"): a candidate far better than
 * the delay in use is not taken while the one in use explains the motion within the noise, its
 * sum at most BR_DLYID_NOISE_FACTOR (R' + P_00) / (1 - forget); above it, the same candidate
 * is. The one-phase rule, the axis on time (the configured delay, slot n, in use). */
static void test_dlyid_noise_floor(void **st)
{
    (void)st;
    br_est_cfg_t c = machine_ukf();
    c.delay_id.steady_after_s = 0.0f;
    assert_int_equal(br_est_cfg_check(&c), BR_OK);
    const uint32_t n = c.delay_id.n_cand;
    const int low = 1; /* a neighbour of 0 ms, the axis's delay */
    /* (the sums of every slot but low's, in units of the floor; the slot in use after) */
    static const struct {
        float of_floor;
        int taken;
    } cases[] = {{0.5f, 0}, {4.0f, 1}};
    for (unsigned t = 0; t < sizeof cases / sizeof cases[0]; t++) {
        br_est_delay_t d;
        br_dlyid_t id;
        axis_t a;
        float u_prev;
        /* past the warm-up, no switch yet */
        const int periods = (int)(c.delay_id.warmup_s / c.model.dt_s) + 40;
        bank_run(&c, 0.0, periods, &a, &d, &id, &u_prev);
        assert_true(id.k >= id.warmup);
        assert_int_equal(id.n_switch, 0u);
        assert_int_equal(id.cur, n);
        const float floor_rad2 = BR_DLYID_NOISE_FACTOR * (id.r_rad2 + id.P[0][0]) / (1.0f - id.forget);
        for (uint32_t j = 0; j <= n; j++) {
            id.J[j] = cases[t].of_floor * floor_rad2;
        }
        id.J[low] = 0.0f; /* after the period: one squared innovation, far below the others */
        bank_period(&c, &a, &d, &id, u_prev);
        assert_int_equal(id.cur, cases[t].taken ? (uint32_t)low : n);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dlyid_bounds),
        cmocka_unit_test(test_dlyid_finds_delay),
        cmocka_unit_test(test_dlyid_steady_phase),
        cmocka_unit_test(test_dlyid_keeps_the_modelled_delay),
        cmocka_unit_test(test_dlyid_overflow_restarts),
        cmocka_unit_test(test_dlyid_leaves_an_off_grid_delay),
        cmocka_unit_test(test_dlyid_unchecked_count_is_off),
        cmocka_unit_test(test_dlyid_predict_restarts),
        cmocka_unit_test(test_dlyid_on_without_switch_is_off),
        cmocka_unit_test(test_dlyid_no_false_switch),
        cmocka_unit_test(test_dlyid_no_switch_at_reversals),
        cmocka_unit_test(test_dlyid_finds_delay_at_reversals),
        cmocka_unit_test(test_dlyid_one_step_at_a_time),
        cmocka_unit_test(test_dlyid_off_grid_start_refined),
        cmocka_unit_test(test_dlyid_noise_floor),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
