/* SPDX-License-Identifier: Apache-2.0 */
/* Particle filter: configuration guards, integer resampling, bad input,
 * outliers, all-invalid and single invalid particles, underflow-proof weights,
 * the inline prediction against br_model_step, tracking. */
#include "br_test.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "bristle/br_pf.h"
#include "plant/br_sim_plant.h"

#define RPC BR_MACHINE_RAD_PER_COUNT_F

/* the test's period and its process noise on omega and g_p there (the
 * machine file's are for its own period) */
#define TEST_DT_S 1.0e-3f
#define TEST_Q_OMEGA 1.0e-5f
#define TEST_Q_GP 0.09f

/* The machine file's PF (br_circle_pf_cfg_default) with m particles at the test's period,
 * the thesis filter: its shared external force off (cfg.load, test_pf_load.c) */
static br_pf_cfg_t cfg(uint32_t m)
{
    br_pf_cfg_t c = br_circle_pf_cfg_default(TEST_DT_S);
    c.load = (br_pf_load_t){0.0f, 0.0f};
    c.n_particles = m;
    c.est.q_var[BR_X_OMEGA] = TEST_Q_OMEGA;
    c.est.q_var[BR_X_GP] = TEST_Q_GP;
    return c;
}

/* cfg(100) with the innovation-driven noise on (valid settings whatever the
 * machine file's; the guards change one field at a time) */
static br_pf_cfg_t cfg_adapt(void)
{
    br_pf_cfg_t c = cfg(100);
    c.adapt = (br_pf_adapt_t){1.0f, 0.5f, 10.0f};
    return c;
}

static br_pf_t *new_pf(uint32_t m)
{
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = cfg(m);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    return pf;
}

/* A PF of m particles after two steps at rest at y (the priming one and one more) */
static br_pf_t *pf_at_rest(uint32_t m, const br_meas_t *y)
{
    br_pf_t *pf = new_pf(m);
    assert_int_equal(br_pf_step(pf, y, 0.0f), BR_OK);
    assert_int_equal(br_pf_step(pf, y, 0.0f), BR_OK);
    return pf;
}

/* br_pf_stats of a primed filter */
static br_pf_stats_t stats(const br_pf_t *pf)
{
    br_pf_stats_t s;
    assert_int_equal(br_pf_stats(pf, &s), BR_OK);
    return s;
}

static int all_finite(const br_pf_t *pf)
{
    for (uint32_t j = 0; j < pf->cfg.n_particles; j++)
        for (int i = 0; i < BR_NX; i++)
            if (!isfinite(pf->x[i][j])) return 0;
    return 1;
}

static void test_init_guards(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    br_pf_cfg_t c = cfg(100);
    assert_int_equal(br_pf_init(NULL, &c), BR_E_NULL);
    assert_int_equal(br_pf_init(pf, NULL), BR_E_NULL);
    c = cfg(100); c.noise = NULL;                 assert_int_equal(br_pf_init(pf, &c), BR_E_NULL);
    c = cfg(0);                                   assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(BR_PF_MAX_PARTICLES + 1u);            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(BR_PF_MAX_PARTICLES);                 assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c = cfg(100); c.noise_len = 1000u;            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM); /* not 2^k */
    c = cfg(100); c.noise_len = 1u;               assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    for (int i = 0; i < BR_NX; i++) {
        c = cfg(100); c.est.q_var[i] = -1e-20f;       assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
        c = cfg(100); c.est.q_var[i] = NAN;           assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
        c = cfg(100); c.x0_std[i] = -1.0f;        assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    }
    c = cfg(100); c.est.r_var_rad2 = 0.0f;            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.r_var_rad2 = -1.0f;           assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.r_var_rad2 = INFINITY;        assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.outlier_sigma = 0.0f;         assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.reanchor_after = 0u;          assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.rad_per_count = 0.0f;         assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.gp_min_N = 0.0f;              assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.gp_max_N = 0.9f * c.est.gp_min_N; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM); /* < min */
    c = cfg(100); c.est.gp0_N = 1.1f * c.est.gp_max_N;    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM); /* > max */
    c = cfg(100); c.est.model.dt_s = 0.0f;            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.est.model.lugre.sigma0_Npm = -1.0f; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    /* cfg.adapt: off (nis_ref 0, the rest unused) or nis_ref >= BR_PF_ADAPT_REF_MIN, alpha in (0, 1],
     * max_scale in [1, BR_EST_VAR_MAX] */
    c = cfg(100); c.adapt = (br_pf_adapt_t){0.0f, 0.0f, 0.0f}; assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c = cfg_adapt(); c.adapt.nis_ref = -1.0f;            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.nis_ref = NAN;              assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.nis_ref = INFINITY;         assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.nis_ref = 0.5f * BR_PF_ADAPT_REF_MIN; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.nis_ref = BR_PF_ADAPT_REF_MIN; assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c = cfg_adapt(); c.adapt.alpha = 0.0f;               assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.alpha = 1.5f;               assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.alpha = NAN;                assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.alpha = 1.0f;               assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c = cfg_adapt(); c.adapt.max_scale = 0.5f;           assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.max_scale = 2.0f * BR_EST_VAR_MAX; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg_adapt(); c.adapt.max_scale = NAN;            assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    /* cfg.gp_curve: off or on, rho in [0, 1] when on */
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){2u, 0.5f};  assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){1u, -0.1f}; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){1u, 1.01f}; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){1u, NAN};   assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){1u, 0.0f};  assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c = cfg(100); c.gp_curve = (br_pf_gp_curve_t){1u, 1.0f};  assert_int_equal(br_pf_init(pf, &c), BR_OK);
    /* cfg.proposal: one of BR_PF_PROPOSAL_*; its constants finite (a period
     * so long that (h/2)^2 Q_omega overflows is refused with OPT_HELD only) */
    c = cfg(100); c.proposal = BR_PF_PROPOSAL_OPT_HELD + 1u; assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    c = cfg(100); c.proposal = BR_PF_PROPOSAL_OPT_HELD;   assert_int_equal(br_pf_init(pf, &c), BR_OK);
    /* (the delay identification's constants overflow at such a period: off here, test_dlyid;
     * the bristles so soft and undamped that the model needs few sub-steps even there) */
    c = cfg(100); c.est.model.dt_s = 1e20f; c.est.delay_id.n_cand = 0u;
    c.est.model.lugre.sigma0_Npm = 1e-38f; c.est.model.lugre.sigma1_Nspm = 0.0f; c.est.model.sigma2_Nspm = 0.0f;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c.proposal = BR_PF_PROPOSAL_OPT;                      assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c.proposal = BR_PF_PROPOSAL_OPT_HELD;                 assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_E_STATE); /* last init failed */
    free(pf);
}

static void test_resample_idx(void **st)
{
    (void)st;
    uint16_t idx[8];
    /* equal weights: each particle once */
    const uint32_t eq[4] = {5, 5, 5, 5};
    assert_int_equal(br_pf_resample_idx(eq, 4, idx), BR_OK);
    for (int i = 0; i < 4; i++) assert_int_equal(idx[i], i);
    /* one particle carries everything */
    const uint32_t one[4] = {0, 0, 65536, 0};
    assert_int_equal(br_pf_resample_idx(one, 4, idx), BR_OK);
    for (int i = 0; i < 4; i++) assert_int_equal(idx[i], 2);
    /* C = 1,4,4,8; t_i = floor((2i+1) 8 / 8) = 1,3,5,7 -> 1,1,3,3 */
    const uint32_t w[4] = {1, 3, 0, 4};
    assert_int_equal(br_pf_resample_idx(w, 4, idx), BR_OK);
    assert_int_equal(idx[0], 1);
    assert_int_equal(idx[1], 1);
    assert_int_equal(idx[2], 3);
    assert_int_equal(idx[3], 3);
    /* the largest total, BR_PF_MAX_PARTICLES weights of 2^16: 2 C_m = 2^17 m must
     * not wrap in 32 bits (equal weights: each particle exactly once) */
    uint32_t *big = malloc((BR_PF_MAX_PARTICLES + 1u) * sizeof *big);
    uint16_t *bidx = malloc((BR_PF_MAX_PARTICLES + 1u) * sizeof *bidx);
    assert_non_null(big);
    assert_non_null(bidx);
    for (uint32_t j = 0; j <= BR_PF_MAX_PARTICLES; j++) big[j] = 1u << BR_PF_W_BITS;
    assert_int_equal(br_pf_resample_idx(big, BR_PF_MAX_PARTICLES, bidx), BR_OK);
    for (uint32_t j = 0; j < BR_PF_MAX_PARTICLES; j++) assert_int_equal(bidx[j], j);
    /* guards: the filter's contract, m <= BR_PF_MAX_PARTICLES and W_j <= 2^16,
     * keeps every sum inside 32 bits */
    assert_int_equal(br_pf_resample_idx(big, BR_PF_MAX_PARTICLES + 1u, bidx), BR_E_PARAM);
    big[7] = (1u << BR_PF_W_BITS) + 1u;
    assert_int_equal(br_pf_resample_idx(big, BR_PF_MAX_PARTICLES, bidx), BR_E_PARAM);
    free(big);
    free(bidx);
    const uint32_t zero[4] = {0, 0, 0, 0};
    assert_int_equal(br_pf_resample_idx(zero, 4, idx), BR_E_INPUT);
    assert_int_equal(br_pf_resample_idx(w, 0, idx), BR_E_PARAM);
    assert_int_equal(br_pf_resample_idx(NULL, 4, idx), BR_E_NULL);
}

static void test_bad_input_keeps_state(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf(200);
    br_meas_t y = {1000, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK); /* primes */
    assert_int_equal(br_pf_step(pf, &y, 0.001f), BR_OK);
    float th0 = pf->x[0][7], gp0 = pf->x[3][7];
    uint32_t pos = pf->noise_pos;
    const float bad[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        assert_int_equal(br_pf_step(pf, &y, bad[k]), BR_E_INPUT);
        br_meas_t yb = {1000, bad[k]};
        assert_int_equal(br_pf_step(pf, &yb, 0.0f), BR_E_INPUT);
    }
    br_meas_t yr = {1000, 1.5f};
    assert_int_equal(br_pf_step(pf, &yr, 0.0f), BR_E_INPUT);
    yr.frac = -0.1f;
    assert_int_equal(br_pf_step(pf, &yr, 0.0f), BR_E_INPUT);
    assert_true(pf->x[0][7] == th0 && pf->x[3][7] == gp0 && pf->noise_pos == pos);
    assert_int_equal(br_pf_step(pf, NULL, 0.0f), BR_E_NULL);
    free(pf);
}

static void test_outlier_100_sigma(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf(300);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    for (int k = 0; k < 5; k++) assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    /* ten gates (the machine's gate, outlier_sigma sqrt(R + rpc^2 / 12) + d, at least
     * 100 counts): every particle is an outlier */
    const double gate_counts = ((double)pf->cfg.est.outlier_sigma * sqrt((double)pf->r_gate) +
                                (double)pf->cfg.est.outlier_transient_rad) / (double)RPC;
    const int32_t jump = (int32_t)ceil((10.0 * gate_counts > 100.0) ? 10.0 * gate_counts : 100.0);
    y.counts = jump;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    assert_true(all_finite(pf));
    assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
    /* an outlier step weighs every valid particle alike (all 300 here) */
    BR_ASSERT_NEAR(stats(pf).ess, 300.0, 0.0);
    /* a single glitch: the measurement returns and tracking resumes */
    y.counts = 0;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    BR_ASSERT_NEAR(stats(pf).mean[0] / RPC, 0.5, 1.0);
    /* a lasting jump (the filter lost lock): re-anchored after 3 outliers */
    y.counts = jump;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_W_OUTLIER);
    assert_true(all_finite(pf));
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    BR_ASSERT_NEAR(stats(pf).mean[0] / RPC, 0.5, 1.0);
    free(pf);
}

/* The gate's sigma (docs/modules/pf.md): sqrt(R + rpc^2 / 12), R with the
 * encoder's quantisation. A PF sure of itself (R = 1e-3 count^2, a tight
 * cloud at rest): a one-count innovation is accepted (without the rpc^2 / 12
 * term the 8-sigma gate is 0.25 count from the nearest particle and rejects
 * it); a jump of 10 gate sigmas is rejected. */
/* A PF of 300 particles sure of itself: R = 1e-3 count^2, no theta or z
 * noise, a tight cloud; the gate's formula, not a machine's value: 8 sigma as
 * the reference machine ships (a machine with a wider gate, e.g. the heavy
 * one, would not meet test_gate_quantisation's premise). */
static br_pf_cfg_t sure_cfg(void)
{
    br_pf_cfg_t c = cfg(300);
    c.est.outlier_sigma = 8.0f;
    c.est.outlier_transient_rad = 0.0f; /* the thesis gate (the term: test_gate_transient) */
    c.est.r_var_rad2 = 1.0e-3f * RPC * RPC;
    c.est.q_var[BR_X_THETA] = 0.0f;
    c.est.q_var[BR_X_OMEGA] = 1.0e-12f;
    c.x0_std[BR_X_THETA] = 0.0f;
    c.x0_std[BR_X_OMEGA] = 0.0f;
    c.x0_std[BR_X_Z] = 0.0f;
    c.est.q_var[BR_X_Z] = 0.0f;
    return c;
}

static void test_gate_quantisation(void **st)
{
    (void)st;
    br_pf_cfg_t c = sure_cfg();
    const double sig_counts = sqrt((double)c.est.r_var_rad2 + (double)RPC * (double)RPC / 12.0) / (double)RPC;
    const double k = (c.est.outlier_sigma < 10.0f) ? 10.0 : (double)c.est.outlier_sigma + 1.0;
    /* the premise: R alone would put a count beyond the gate */
    assert_true((double)c.est.outlier_sigma * sqrt((double)c.est.r_var_rad2) < 0.5 * (double)RPC);
    br_pf_t *pf = calloc(2, sizeof *pf);
    assert_non_null(pf);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {0, 0.5f};
    for (int k0 = 0; k0 < 20; k0++) assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    pf[1] = pf[0];
    /* one count: accepted */
    const br_meas_t y1 = {1, 0.5f};
    assert_int_equal(br_pf_step(&pf[1], &y1, 0.0f), BR_OK);
    /* 10 gate sigmas: rejected */
    const br_meas_t y10 = {(int32_t)ceil(k * sig_counts), 0.5f};
    assert_int_equal(br_pf_step(&pf[0], &y10, 0.0f), BR_W_OUTLIER);
    free(pf);
}

/* The gate's transient term d (eq. G1, docs/modules/pf.md, "The gate"): the
 * sure PF (sure_cfg) at rest, 8 sigma (about 2.3 counts) wide;
 * a jump of 10 counts is an outlier without d and accepted with d = 20 counts,
 * a jump beyond 8 sigma + d is an outlier with it. With d = 0 the threshold and
 * cfg.adapt's NIS cap are the thesis gate's, bit for bit; with d the cap is the
 * NIS of a step at the gate, (g + d / sigma)^2 (eq. G2). A gate beyond the
 * float range is refused at init. */
static void test_gate_transient(void **st)
{
    (void)st;
    br_pf_cfg_t c = sure_cfg();
    const double sig_counts = sqrt((double)c.est.r_var_rad2 + (double)RPC * (double)RPC / 12.0) / (double)RPC;
    const double d_counts = 20.0;
    assert_true(8.0 * sig_counts < 5.0); /* the premise: 10 counts are beyond 8 sigma */
    br_pf_t *pf = calloc(3, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t cd = c;
    cd.est.outlier_transient_rad = (float)d_counts * RPC;
    assert_int_equal(br_pf_init(&pf[0], &c), BR_OK);
    /* d = 0: the thesis gate's constants */
    const float thesis_l = -0.5f * c.est.outlier_sigma * c.est.outlier_sigma *
                           (1.0f + c.est.rad_per_count * c.est.rad_per_count * (1.0f / 12.0f) / c.est.r_var_rad2);
    assert_true(pf[0].outlier_l == thesis_l);
    assert_true(pf[0].gate_nis == c.est.outlier_sigma * c.est.outlier_sigma);
    assert_int_equal(br_pf_init(&pf[1], &cd), BR_OK);
    const double g_nis = 8.0 + d_counts / sig_counts;
    BR_ASSERT_NEAR((double)pf[1].gate_nis, g_nis * g_nis, 1e-4 * g_nis * g_nis);
    /* the gate in counts from the threshold: sqrt(-2 R l) = g sigma + d */
    BR_ASSERT_NEAR(sqrt(-2.0 * (double)cd.est.r_var_rad2 * (double)pf[1].outlier_l) / (double)RPC,
                   8.0 * sig_counts + d_counts, 1e-3);
    br_meas_t y = {0, 0.5f};
    for (int k = 0; k < 20; k++) {
        assert_int_equal(br_pf_step(&pf[0], &y, 0.0f), BR_OK);
        assert_int_equal(br_pf_step(&pf[1], &y, 0.0f), BR_OK);
    }
    pf[2] = pf[1];
    const br_meas_t y10 = {10, 0.5f};
    assert_int_equal(br_pf_step(&pf[0], &y10, 0.0f), BR_W_OUTLIER);
    assert_int_equal(br_pf_step(&pf[1], &y10, 0.0f), BR_OK);
    const br_meas_t yfar = {(int32_t)ceil(8.0 * sig_counts + d_counts) + 2, 0.5f};
    assert_int_equal(br_pf_step(&pf[2], &yfar, 0.0f), BR_W_OUTLIER);
    /* f^2 = inf: a tiny gate in sigma with a transient term */
    cd.est.outlier_sigma = 1.0e-30f;
    cd.est.outlier_transient_rad = BR_EST_GATE_MAX_TRANSIENT_COUNTS * RPC;
    assert_int_equal(br_pf_init(&pf[0], &cd), BR_E_PARAM);
    free(pf);
}

static void test_all_invalid_keeps_previous(void **st)
{
    (void)st;
    br_meas_t y = {0, 0.5f};
    br_pf_t *pf = pf_at_rest(100, &y);
    float th = pf->x[0][3];
    int32_t origin = pf->origin_counts;
    /* a torque that overflows every particle's velocity: no particle is usable */
    y.counts = 5;
    assert_int_equal(br_pf_step(pf, &y, 3.0e38f), BR_E_NUMERIC);
    assert_true(all_finite(pf));
    assert_true(pf->x[0][3] == th && pf->origin_counts == origin);
    /* no usable weight in this step: an ESS of 0, not the 0/0 of its NaN log-weights */
    assert_true(stats(pf).ess == 0.0f);
    /* the same for a predict-only step after a predict-only step (which weighs all alike) */
    assert_int_equal(br_pf_predict(pf, 0.0f), BR_OK);
    assert_true(stats(pf).ess == 100.0f);
    th = pf->x[0][3];
    assert_int_equal(br_pf_predict(pf, 3.0e38f), BR_E_NUMERIC);
    assert_true(pf->x[0][3] == th);
    assert_true(stats(pf).ess == 0.0f);
    free(pf);
}

static void test_weights_survive_underflow(void **st)
{
    (void)st;
    /* a residual of 300 counts with R = 1 count^2: e^(-l) underflows float for
     * every particle; the max-shift keeps the best at weight 1 */
    br_pf_t *pf = calloc(1, sizeof *pf);
    br_pf_cfg_t c = cfg(100);
    c.est.outlier_sigma = 1e6f; /* not an outlier by configuration */
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    y.counts = 300;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    uint32_t wmax = 0;
    for (uint32_t j = 0; j < 100; j++) wmax = pf->W[j] > wmax ? pf->W[j] : wmax;
    assert_int_equal(wmax, 1u << BR_PF_W_BITS);
    assert_true(all_finite(pf));
    assert_true(stats(pf).ess >= 1.0f);
    free(pf);
}

/* br_pf_stats: the mean of the set and the ESS of the last step's weights,
 * against the same made here in double from the set and the log-weights; m
 * after the first measurement and after a predict-only step */
static void test_ess_reported(void **st)
{
    (void)st;
    const uint32_t m = 500u;
    br_pf_t *pf = new_pf(m);
    br_pf_stats_t s;
    assert_int_equal(br_pf_stats(pf, &s), BR_E_STATE); /* no set before the first measurement */
    assert_int_equal(br_pf_stats(NULL, &s), BR_E_NULL);
    assert_int_equal(br_pf_stats(pf, NULL), BR_E_NULL);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    BR_ASSERT_NEAR(stats(pf).ess, 500.0, 0.0); /* freshly drawn: uniform */
    double ess_min = (double)m;
    for (int k = 0; k < 20; k++) {
        y.frac = (k % 2) ? 0.3f : 0.7f; /* a measurement that moves: weights far from uniform */
        assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
        s = stats(pf);
        assert_true(s.ess >= 1.0f && s.ess <= 500.0f);
        double lmax = -INFINITY, sw = 0.0, sw2 = 0.0, mean[BR_NX] = {0.0, 0.0, 0.0, 0.0};
        for (uint32_t j = 0; j < m; j++) lmax = fmax(lmax, (double)pf->l[j]);
        for (uint32_t j = 0; j < m; j++) {
            const double w = exp((double)pf->l[j] - lmax);
            sw += w;
            sw2 += w * w;
            for (int i = 0; i < BR_NX; i++) mean[i] += (double)pf->x[i][j] / (double)m;
        }
        BR_ASSERT_NEAR(s.ess, sw * sw / sw2, 1e-4 * sw * sw / sw2);
        for (int i = 0; i < BR_NX; i++) {
            double xmax = 0.0;
            for (uint32_t j = 0; j < m; j++) xmax = fmax(xmax, fabs((double)pf->x[i][j]));
            BR_ASSERT_NEAR(s.mean[i], mean[i], 1e-5 * xmax);
        }
        ess_min = fmin(ess_min, (double)s.ess);
    }
    assert_true(ess_min < 0.9 * (double)m); /* the check above saw weights that are not all alike */
    assert_int_equal(br_pf_predict(pf, 0.0f), BR_OK);
    BR_ASSERT_NEAR(stats(pf).ess, 500.0, 0.0); /* a predict-only step does not weigh */
    /* a failed re-init leaves the filter unusable, its set included */
    br_pf_cfg_t bad = cfg(m);
    bad.n_particles = 0u;
    assert_int_equal(br_pf_init(pf, &bad), BR_E_PARAM);
    assert_int_equal(br_pf_stats(pf, &s), BR_E_STATE);
    free(pf);
}

/* Friction tracking on the double-precision plant driven open loop by a slow
 * sinusoidal torque (reversals, stiction, sliding). */
static void test_tracks_plant_friction(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf(1000);
    br_plant_t p;
    br_plant_cfg_t pc = br_plant_cfg_reference();
    br_plant_state_t x0 = {0.0, 0.0, 0.0};
    assert_int_equal(br_plant_init(&p, &pc, &x0), 0);
    double u = 0.0, se = 0.0, sf = 0.0;
    int n = 0, n_out = 0;
    for (int k = 0; k < 3000; k++) {
        br_meas_t y = {br_plant_encoder(&p), 0.5f};
        br_status_t s = br_pf_step(pf, &y, (float)u);
        /* breakaway drops the friction from Fs to Fc within a few ms, faster than
         * the g_p random walk: the filter may reject a few measurements there */
        assert_true(s == BR_OK || s == BR_W_OUTLIER);
        n_out += (s == BR_W_OUTLIER);
        if (k >= 1000) { /* after the first breakaway */
            double e = (double)br_pf_estimate(pf)->F_hat_N - p.fnl_N;
            se += e * e;
            sf += p.fnl_N * p.fnl_N;
            n++;
        }
        /* 2 N above stiction at the load (20 N on the reference), period 1 s:
         * sticks, breaks away, reverses, slides (up to 0.2 m/s on the reference) */
        u = (pc.Fs_N + 2.0) * pc.lead_mprad * sin(2.0 * 3.14159265358979 * k * 1e-3);
        br_plant_step(&p, u / pc.tau_per_duty_Nm, 1e-3);
    }
    const double rel = sqrt(se / sf);
    print_message("PF friction tracking: RMS error %.3f N, %.1f %% of the RMS friction, %d outlier steps\n",
                  sqrt(se / n), 100.0 * rel, n_out);
    assert_true(rel < 0.10);
    assert_true(n_out < 100); /* of 3000 steps; measured: 52 */
    free(pf);
}

/* The PF's inline prediction (its RK4 form, bounded fallback) is br_model_step:
 * without process noise, every predicted particle equals br_model_step of its
 * parent shifted to the new origin, at circle speeds to an ulp-level
 * tolerance and beyond the RK4 a h limit (the bounded scheme) bit for bit. */
static void predict_is_model_step(uint32_t scalar_path)
{
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = cfg(64);
    c.scalar_path = scalar_path;
    for (int i = 0; i < BR_NX; i++) c.est.q_var[i] = 0.0f;
    /* the PF requires g_p noise > 0; the smallest normal variance moves no g_p
     * of this size by even one ulp, so the prediction stays noise-free */
    c.est.q_var[BR_X_GP] = FLT_MIN;
    c.est.outlier_sigma = 1e6f;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    /* speeds from 2 um/s to 2 m/s, both signs */
    float parent[64][BR_NX];
    int n_bounded = 0;
    for (uint32_t j = 0; j < 64; j++) {
        const float v = (j % 2 ? 1.0f : -1.0f) * 2.0f * powf(10.0f, -6.0f + 6.0f * (float)j / 63.0f);
        pf->x[BR_X_OMEGA][j] = v / c.est.model.lead_mprad;
        pf->x[BR_X_Z][j] = (j % 3 == 0) ? 0.0f : 1e-6f;
        for (int i = 0; i < BR_NX; i++) parent[j][i] = pf->x[i][j];
        const float ah = c.est.model.lugre.sigma0_Npm * fabsf(v) * c.est.model.dt_s / parent[j][BR_X_GP];
        n_bounded += ah > BR_MODEL_RK4_AH_MAX;
    }
    assert_true(n_bounded >= 10 && n_bounded <= 54); /* both schemes are exercised */
    const float u = 0.05f;
    /* predict only: the set is the predicted set (no resampling), in place */
    assert_int_equal(br_pf_predict(pf, u), BR_OK);
    for (uint32_t j = 0; j < 64; j++) {
        float xn[BR_NX];
        assert_int_equal(br_model_step(&pf->model, parent[j], u, xn), BR_OK);
        const float ah = c.est.model.lugre.sigma0_Npm * c.est.model.lead_mprad * fabsf(parent[j][BR_X_OMEGA]) *
                         c.est.model.dt_s / parent[j][BR_X_GP];
        /* RK4 steps: the PF's own RK4 form (k_p = sigma0 L / g_p, folded
         * constants) rounds differently from br_model_step's (an ulp or so per
         * operation, relative to the size of each term of eqs. 4 and 6, which
         * may cancel): equal to 1e-5 of the step's change plus 1e-5 of the
         * step's terms taken in absolute value (s[]: h |omega| + h^2 |eq. 6|,
         * h |eq. 6|, h |eq. 4|) plus 2 ulp; the bounded scheme (both use it as
         * is): bit for bit */
        const br_model_cfg_t *mc = &c.est.model;
        const double L = mc->lead_mprad, h = mc->dt_s, w = fabs((double)parent[j][BR_X_OMEGA]);
        const double zabs = fabs((double)parent[j][BR_X_Z]), v = L * w;
        const double zd_abs = v + mc->lugre.sigma0_Npm * v * zabs / parent[j][BR_X_GP];
        const double wd_abs = (fabs((double)u) + L * L * mc->sigma2_Nspm * w +
                               L * (mc->lugre.sigma0_Npm * zabs + mc->lugre.sigma1_Nspm * zd_abs)) /
                              (mc->J_kgm2 + L * L * mc->M_kg);
        const double s[BR_NX] = {h * w + h * h * wd_abs, h * wd_abs, h * zd_abs, 0.0};
        if (ah > 0.9f * BR_MODEL_RK4_AH_MAX && ah < 1.1f * BR_MODEL_RK4_AH_MAX) {
            continue; /* near the limit either scheme may be taken at the step's end */
        }
        const int bounded = ah >= 1.1f * BR_MODEL_RK4_AH_MAX;
        for (int i = 0; i < BR_NX; i++) {
            const double d = fabs((double)pf->x[i][j] - (double)xn[i]);
            const double tol = bounded ? 0.0
                                       : 1e-5 * (fabs((double)xn[i] - (double)parent[j][i]) + s[i]) +
                                             2.0 * (double)FLT_EPSILON * fabs((double)xn[i]);
            if (!(d <= tol)) {
                fail_msg("path %u particle %u state %d: PF %.9g, br_model_step %.9g", (unsigned)scalar_path,
                         (unsigned)j, i, (double)pf->x[i][j], (double)xn[i]);
            }
        }
        assert_true(pf->l[j] > -INFINITY);
    }
    free(pf);
}

/* The prediction is br_model_step's: its bounded scheme bit for bit beyond
 * the a h limit, its RK4 to an ulp-level tolerance (the PF's own RK4 form,
 * br_model_kp_rk4), on both paths (the vector path fixes the bounded
 * particles up in scalar). */
static void test_predict_is_model_step(void **st)
{
    (void)st;
    predict_is_model_step(0u);
    predict_is_model_step(1u);
}

/* The vector path and the scalar reference path give identical particles,
 * weights, indices and estimates, step after step, on an input that takes
 * particles into the bounded scheme, makes some invalid, and has outliers,
 * at a particle count whose noise blocks wrap round the table; with the
 * innovation-driven noise on, whose smoothed NIS and noise factor (made in
 * the prediction loops, again after the vector path's fix-up) are the same
 * bit for bit, and which the jump drives above its reference. */
static void test_vector_path_is_scalar_path(void **st)
{
    (void)st;
    br_pf_t *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    br_pf_cfg_t c = cfg(1499);
    c.noise_skip = 3u;
    c.adapt = cfg_adapt().adapt;
    assert_int_equal(br_pf_init(a, &c), BR_OK);
    c.scalar_path = 1u;
    assert_int_equal(br_pf_init(b, &c), BR_OK);
    int n_bounded = 0, n_invalid = 0, n_outlier = 0, n_scaled = 0;
    for (int k = 0; k < 60; k++) {
        /* a ramp with a jump (outliers) and, at k = 20 and 40, particles
         * made fast (bounded scheme) or non-finite (invalid) */
        const br_meas_t y = {(int32_t)(k * 3 + (k >= 30 && k < 34 ? 5000 : 0)), 0.25f + 0.01f * (float)(k % 7)};
        const float u = 0.02f * sinf(0.3f * (float)k);
        if (k == 20 || k == 40) {
            for (uint32_t j = 0; j < c.n_particles; j += 37) {
                const float w = (j % 2 ? 1.0f : -1.0f) * 5.0e3f;
                a->x[BR_X_OMEGA][j] = b->x[BR_X_OMEGA][j] = w;
                n_bounded++;
            }
            for (uint32_t j = 5; j < c.n_particles; j += 211) {
                a->x[BR_X_Z][j] = b->x[BR_X_Z][j] = 3.0e38f;
                a->x[BR_X_OMEGA][j] = b->x[BR_X_OMEGA][j] = 1.0e3f;
                n_invalid++;
            }
        }
        if (k == 31) {
            /* an outlier step (every valid particle W = 2^16) with 5 invalid
             * particles (W = 0): V = 1494 valid of m = 1499, total = V 2^16, so
             * the point t_749 = floor(1499 V 2^16 / (2 m)) = 747 2^16 falls
             * exactly on the cumulative weight of the 747th valid particle:
             * a tie, which systematic resampling (C_{j-1} <= t < C_j) gives
             * to the next particle */
            for (uint32_t j = 7; j < c.n_particles; j += 300) {
                a->x[BR_X_Z][j] = b->x[BR_X_Z][j] = 3.0e38f;
                a->x[BR_X_OMEGA][j] = b->x[BR_X_OMEGA][j] = 1.0e3f;
                n_invalid++;
            }
        }
        const br_status_t sa = br_pf_step(a, &y, u), sb = br_pf_step(b, &y, u);
        assert_int_equal(sa, sb);
        n_outlier += sa == BR_W_OUTLIER;
        if (k == 31) {
            assert_int_equal(sa, BR_W_OUTLIER); /* the tie above is made */
        }
        if (k > 0 && !BR_FAILED(sa)) {
            /* (step 0 primes the cloud: no weights) both paths' indices are
             * systematic resampling's (br_pf_resample_idx) on the step's weights */
            static uint16_t ref[BR_PF_MAX_PARTICLES];
            assert_int_equal(br_pf_resample_idx(a->W, c.n_particles, ref), BR_OK);
            assert_memory_equal(a->idx, ref, c.n_particles * sizeof ref[0]);
        }
        assert_memory_equal(a->x, b->x, sizeof a->x);
        assert_memory_equal(a->fnl, b->fnl, sizeof a->fnl);
        assert_memory_equal(a->l, b->l, sizeof a->l);
        assert_memory_equal(a->W, b->W, sizeof a->W);
        assert_memory_equal(a->idx, b->idx, sizeof a->idx);
        assert_memory_equal(&a->est, &b->est, sizeof a->est);
        const br_pf_stats_t ta = stats(a), tb = stats(b);
        assert_memory_equal(&ta, &tb, sizeof ta);
        assert_int_equal(a->noise_pos, b->noise_pos);
        assert_memory_equal(&a->nis_avg, &b->nis_avg, sizeof a->nis_avg);
        assert_memory_equal(&a->q_scale_std, &b->q_scale_std, sizeof a->q_scale_std);
        n_scaled += a->q_scale_std > 1.0f;
    }
    assert_true(n_bounded > 0 && n_invalid > 0 && n_outlier > 0 && n_scaled > 0);
    free(a);
    free(b);
}

/* g_p stays in [gp_min, gp_max] after every step on both paths (the clamp
 * after the process noise), with particles started on both bounds and a
 * g_p noise of a tenth of the range per step. */
static void test_gp_stays_in_range(void **st)
{
    (void)st;
    for (uint32_t path = 0; path < 2u; path++) {
        br_pf_t *pf = calloc(1, sizeof *pf);
        assert_non_null(pf);
        br_pf_cfg_t c = cfg(200);
        c.scalar_path = path;
        const float lo = c.est.gp_min_N, hi = c.est.gp_max_N, sd = 0.1f * (hi - lo);
        c.est.q_var[BR_X_GP] = sd * sd;
        assert_int_equal(br_pf_init(pf, &c), BR_OK);
        br_meas_t y = {0, 0.5f};
        assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
        for (uint32_t j = 0; j < c.n_particles; j++) {
            pf->x[BR_X_GP][j] = (j % 2) ? lo : hi;
            pf->kgp[j] = (c.est.model.lugre.sigma0_Npm * c.est.model.lead_mprad) / pf->x[BR_X_GP][j]; /* k_p = sigma0 L / g_p */
        }
        int n_lo = 0, n_hi = 0;
        for (int k = 0; k < 20; k++) {
            assert_false(BR_FAILED(br_pf_predict(pf, 0.0f)));
            for (uint32_t j = 0; j < c.n_particles; j++) {
                const float g = pf->x[BR_X_GP][j];
                if (!(g >= lo && g <= hi)) {
                    fail_msg("path %u step %d particle %u: g_p %.9g outside [%.9g, %.9g]", (unsigned)path, k,
                             (unsigned)j, (double)g, (double)lo, (double)hi);
                }
                n_lo += g == lo;
                n_hi += g == hi;
            }
        }
        assert_true(n_lo > 0 && n_hi > 0); /* both bounds were reached */
        free(pf);
    }
}

/* A particle whose prediction is not finite is kept as it was, with weight 0,
 * while the others go on. */
static void test_one_invalid_particle(void **st)
{
    (void)st;
    const br_meas_t y = {0, 0.5f};
    br_pf_t *pf = pf_at_rest(100, &y);
    const int bad[3] = {5, 6, 7};
    pf->x[BR_X_Z][5] = 3.0e38f;     /* f_nl overflows */
    pf->x[BR_X_OMEGA][6] = 3.0e38f; /* the velocity overflows */
    pf->x[BR_X_OMEGA][7] = -3.0e38f;
    float keep[3][BR_NX];
    for (int b = 0; b < 3; b++)
        for (int i = 0; i < BR_NX; i++) keep[b][i] = pf->x[i][bad[b]];
    /* the predicted set (predict only, on a copy): the invalid ones kept their state */
    br_pf_t *pc = malloc(sizeof *pc);
    assert_non_null(pc);
    memcpy(pc, pf, sizeof *pc);
    assert_int_equal(br_pf_predict(pc, 0.0f), BR_OK);
    for (int b = 0; b < 3; b++)
        for (int i = 0; i < BR_NX; i++) assert_true(pc->x[i][bad[b]] == keep[b][i]);
    free(pc);
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    for (int b = 0; b < 3; b++) {
        const int j = bad[b];
        assert_true(isnan(pf->l[j]));
        assert_int_equal(pf->W[j], 0u);
        assert_true(pf->fnl[j] == 0.0f);
    }
    for (uint32_t j = 0; j < 100; j++) {
        assert_true(pf->idx[j] < 5 || pf->idx[j] > 7); /* never resampled */
    }
    assert_true(all_finite(pf));
    assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
    free(pf);
}

/* theta not finite, the rest of the particle sane (velocity, deflection and
 * g_p inside the RK4 limit): only the validity test can catch it, not the a h
 * test; it must reach the fix-up, keep f_nl = 0 and weight 0, and never be
 * resampled (the M7's combined compare: test_pf_m7_paths). */
static void test_theta_nan_particle(void **st)
{
    (void)st;
    const br_meas_t y = {0, 0.5f};
    br_pf_t *pf = pf_at_rest(100, &y);
    const uint32_t bad = 9u;
    pf->x[BR_X_THETA][bad] = NAN;
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    assert_true(isnan(pf->l[bad]));
    assert_int_equal(pf->W[bad], 0u);
    assert_true(pf->fnl[bad] == 0.0f);
    for (uint32_t j = 0; j < 100; j++) {
        assert_true(pf->idx[j] != bad);
    }
    assert_true(all_finite(pf));
    assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
    free(pf);
}

/* Only the last particle valid (every other one's f_nl overflows): the
 * whole weight is W_{m-1}, so every index of the resampled set is m - 1 on
 * both paths; the scalar path's search (resample_fused) has no j < m bound
 * of its own and must stop there because t_i < C_{m-1} = total. */
static void only_last_valid(uint32_t scalar_path)
{
    const uint32_t m = 100;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = cfg(m);
    c.scalar_path = scalar_path;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    for (uint32_t j = 0; j + 1u < m; j++) pf->x[BR_X_Z][j] = 3.0e38f; /* f_nl overflows */
    const br_status_t s = br_pf_step(pf, &y, 0.0f);
    assert_true(s == BR_OK || s == BR_W_OUTLIER);
    assert_true(pf->W[m - 1u] > 0u);
    for (uint32_t j = 0; j + 1u < m; j++) assert_int_equal(pf->W[j], 0u);
    for (uint32_t j = 0; j < m; j++) {
        assert_int_equal(pf->idx[j], m - 1u);
        for (int i = 0; i < BR_NX; i++) assert_true(pf->x[i][j] == pf->x[i][m - 1u]);
    }
    assert_true(all_finite(pf));
    assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
    free(pf);
}

static void test_only_last_particle_valid(void **st)
{
    (void)st;
    only_last_valid(0u);
    only_last_valid(1u);
}

/* theta finite, f_nl not: particles whose deflection makes the bristle rate
 * overflow (sigma0 |v| z / g_p) while theta stays finite must get weight 0;
 * the estimate must stay finite. */
static void test_fnl_overflow_is_invalid(void **st)
{
    (void)st;
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = cfg(100);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    /* every other particle: a deflection so large that sigma0 |v| z / g_p
     * overflows float at this speed, while its theta stays finite */
    for (uint32_t j = 0; j < 100; j += 2) {
        pf->x[BR_X_OMEGA][j] = 1.0e3f;
        pf->x[BR_X_Z][j] = 3.0e38f;
    }
    const br_status_t s = br_pf_step(pf, &y, 0.0f);
    assert_true(s == BR_OK || s == BR_E_NUMERIC);
    int n_invalid = 0;
    for (uint32_t j = 0; j < 100; j++) {
        n_invalid += isnan(pf->l[j]);
        if (!isnan(pf->l[j])) assert_true(isfinite(pf->fnl[j]));
    }
    assert_true(n_invalid > 0);
    assert_true(all_finite(pf));
    assert_true(isfinite(br_pf_estimate(pf)->F_hat_N));
    free(pf);
}

/* The measurement likelihood's scale: each valid particle's log-weight is the
 * Gaussian -(theta_j - y)^2 / (2 R) of its predicted theta (relative to the new
 * origin) and the measurement, R the configured variance (docs/modules/pf.md,
 * step 2). A likelihood with 1 / R, or R^2, or no square, fails here; the golden
 * test sees such a change only through the weights' rounding chain. */
static void test_likelihood_scale(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf(200);
    const br_meas_t y0 = {1000, 0.5f}, y1 = {1003, 0.25f};
    assert_int_equal(br_pf_step(pf, &y0, 0.0f), BR_OK);
    /* the predicted set of the next step: br_pf_predict on a copy makes the
     * same prediction in place (the filter keeps only the resampled set) */
    br_pf_t *pred = malloc(sizeof *pred);
    assert_non_null(pred);
    memcpy(pred, pf, sizeof *pf);
    const double shift = (double)((int64_t)y1.counts - (int64_t)pf->origin_counts) * (double)pf->cfg.est.rad_per_count;
    (void)br_pf_step(pf, &y1, 0.01f);
    assert_int_equal(br_pf_predict(pred, 0.01f), BR_OK);
    const double R = (double)pf->cfg.est.r_var_rad2;
    const double y_rel = (double)(y1.frac * pf->cfg.est.rad_per_count);
    int n = 0;
    double lmin = 0.0;
    for (uint32_t j = 0; j < pf->cfg.n_particles; j++) {
        if (isnan(pf->l[j])) continue;
        /* eq. of the weights: l = -(theta - y)^2 / (2 R), theta at the new origin */
        const double e = ((double)pred->x[BR_X_THETA][j] - shift) - y_rel;
        const double want = -(e * e) / (2.0 * R);
        BR_ASSERT_NEAR(pf->l[j], want, 1e-4 * fabs(want) + 1e-5);
        lmin = fmin(lmin, want);
        n++;
    }
    assert_int_equal(n, (int)pf->cfg.n_particles);
    /* the particles spread over several sigma: the scale is exercised, not only l ~ 0 */
    assert_true(lmin < -1.0);
    free(pred);
    free(pf);
}

/* cfg.proposal against its equations in float64 (docs/modules/pf.md, "A
 * proposal that uses the measurement"), one particle (no resampling to hide
 * the draw), Q_theta = R so that the gain on theta is about 1/2: step k of a
 * copy through br_pf_predict gives the prior's draw with the same noise
 * samples n (OPT_HELD: theta + q_t n0 + (h/2) q_w n1), from which the
 * noise-free prediction mu; then with S = Q_t + c^2 Q_w + R, e = mu - y,
 *   l = -e^2 / (2 S),  theta = mu - (S_tt / S) e + sqrt(S_tt R / S) n0,
 *   omega = mu_w - (S_tw / S) e + l10 n0 + l11 n1.
 * With the prior's draw (the thesis filter) l is -(theta - y)^2 / (2 R) and
 * theta is not pulled towards y: every assertion on l and theta fails. */
static void proposal_matches_equations(uint32_t mode)
{
    br_pf_t *pf = calloc(1, sizeof *pf), *pred = malloc(sizeof *pred);
    assert_non_null(pf);
    assert_non_null(pred);
    br_pf_cfg_t c = cfg(1);
    c.proposal = mode;
    c.est.q_var[BR_X_THETA] = c.est.r_var_rad2;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    br_meas_t y = {100, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    const double R = c.est.r_var_rad2, qt = c.est.q_var[BR_X_THETA], qw = c.est.q_var[BR_X_OMEGA];
    const double ch = (mode == BR_PF_PROPOSAL_OPT_HELD) ? 0.5 * (double)c.est.model.dt_s : 0.0;
    const double stt = qt + ch * ch * qw, stw = ch * qw, S = stt + R;
    const double l00 = sqrt(stt * R / S), l10 = stw * R / S / l00, l11 = sqrt(qw - stw * stw / S - l10 * l10);
    double pull = 0.0;
    for (int k = 0; k < 40; k++) {
        memcpy(pred, pf, sizeof *pf);
        const uint32_t pos = pf->noise_pos, mask = c.noise_len - 1u;
        const double n0 = c.noise[pos & mask], n1 = c.noise[(pos + 1u) & mask];
        const float u = 0.01f * (float)(k % 4);
        assert_int_equal(br_pf_predict(pred, u), BR_OK); /* theta relative to the old origin */
        /* a measurement on either side of the predicted particle, up to 2.1 counts away */
        static const double d[5] = {-1.5, -0.6, 0.4, 1.3, 2.1};
        const double target = (double)pf->origin_counts + (double)pred->x[BR_X_THETA][0] / (double)RPC + d[k % 5];
        const br_meas_t yk = {(int32_t)floor(target), (float)(target - floor(target))};
        const double shift = (double)(yk.counts - pf->origin_counts) * (double)RPC;
        const double mu = ((double)pred->x[BR_X_THETA][0] - sqrt(qt) * n0 - ch * sqrt(qw) * n1) - shift;
        const double mu_w = (double)pred->x[BR_X_OMEGA][0] - sqrt(qw) * n1;
        const double e = mu - (double)yk.frac * (double)RPC;
        assert_int_equal(br_pf_step(pf, &yk, u), BR_OK);
        const double l = -e * e / (2.0 * S);
        const double th = mu - stt / S * e + l00 * n0, om = mu_w - stw / S * e + l10 * n0 + l11 * n1;
        BR_ASSERT_NEAR(pf->l[0], l, 1e-4 * fabs(l) + 1e-6);
        BR_ASSERT_NEAR(pf->x[BR_X_THETA][0], th, 1e-3 * sqrt(R) + 1e-6 * fabs(th));
        BR_ASSERT_NEAR(pf->x[BR_X_OMEGA][0], om, 1e-3 * sqrt(qw) + 1e-6 * fabs(om));
        pull = fmax(pull, fabs(stt / S * e) / sqrt(R));
    }
    /* the draws were pulled by more than the tolerances: the equations were exercised */
    assert_true(pull > 0.1);
    free(pred);
    free(pf);
}

/* cfg.adapt under cfg.proposal (OPT) measures the prior's draw of theta: two
 * filters alike but for the proposal, primed alike, take one step from the
 * same particles with the same noise samples; the prior's draws agree to
 * rounding, so must their smoothed NIS. With Q_theta = R the proposal pulls
 * each draw halfway to y: an NIS taken on the proposal's draws is far off. */
static void test_proposal_adapt_takes_the_prior_draw(void **st)
{
    (void)st;
    br_pf_t *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    br_pf_cfg_t c = cfg_adapt();
    c.est.q_var[BR_X_THETA] = c.est.r_var_rad2;
    assert_int_equal(br_pf_init(a, &c), BR_OK);
    c.proposal = BR_PF_PROPOSAL_OPT;
    assert_int_equal(br_pf_init(b, &c), BR_OK);
    const br_meas_t y0 = {100, 0.5f}, y1 = {101, 0.9f}; /* 1.4 counts on: a pull of about 0.7 */
    assert_int_equal(br_pf_step(a, &y0, 0.0f), BR_OK);
    assert_int_equal(br_pf_step(b, &y0, 0.0f), BR_OK);
    for (uint32_t j = 0; j < c.n_particles; j++) {
        assert_true(a->x[BR_X_THETA][j] == b->x[BR_X_THETA][j]); /* primed alike */
    }
    assert_int_equal(br_pf_step(a, &y1, 0.0f), BR_OK);
    assert_int_equal(br_pf_step(b, &y1, 0.0f), BR_OK);
    assert_true(a->nis_avg > 0.0f);
    BR_ASSERT_NEAR(b->nis_avg, a->nis_avg, 1e-4 * a->nis_avg);
    free(a);
    free(b);
}

static void test_proposal_matches_equations(void **st)
{
    (void)st;
    proposal_matches_equations(BR_PF_PROPOSAL_OPT);
    proposal_matches_equations(BR_PF_PROPOSAL_OPT_HELD);
}

/* cfg.adapt's factor on the noise (docs/modules/pf.md, "omega too"): one
 * prediction from the same set with the factor s = 1, 2 and 4 moves each
 * particle's omega, z and g_p by s times its noise sample, so that
 * x(4) - x(2) = 2 (x(2) - x(1)) per particle (g_p away from its clamps),
 * theta's noise unscaled (theta(4) - theta(2) from omega's scaled step only
 * through the next prediction: here, the same). With cfg.proposal omega's
 * draw keeps its constants: omega(4) = omega(1), bit for bit. */
static void scaled_predictions(uint32_t proposal, float out[3][BR_NX][64])
{
    const float scales[3] = {1.0f, 2.0f, 4.0f};
    for (int s = 0; s < 3; s++) {
        br_pf_t *pf = calloc(1, sizeof *pf);
        assert_non_null(pf);
        br_pf_cfg_t c = cfg(64);
        c.proposal = proposal;
        assert_int_equal(br_pf_init(pf, &c), BR_OK);
        const br_meas_t y = {100, 0.5f};
        assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
        pf->q_scale_std = scales[s];
        assert_int_equal(br_pf_predict(pf, 0.01f), BR_OK);
        for (int i = 0; i < BR_NX; i++) {
            for (uint32_t j = 0; j < 64u; j++) {
                out[s][i][j] = pf->x[i][j];
            }
        }
        free(pf);
    }
}

static void test_adapt_scales_omega(void **st)
{
    (void)st;
    static float x[3][BR_NX][64];
    scaled_predictions(BR_PF_PROPOSAL_PRIOR, x);
    int moved = 0;
    for (uint32_t j = 0; j < 64u; j++) {
        for (int i = BR_X_OMEGA; i < BR_NX; i++) {
            const double d1 = (double)x[1][i][j] - (double)x[0][i][j];
            const double d2 = (double)x[2][i][j] - (double)x[1][i][j];
            if (i == BR_X_GP && (x[2][i][j] <= cfg(64).est.gp_min_N || x[2][i][j] >= cfg(64).est.gp_max_N)) {
                continue; /* a clamp */
            }
            BR_ASSERT_NEAR(d2, 2.0 * d1, 1e-5 * fabs(d2) + 1e-6 * fabs((double)x[0][i][j]) + 1e-30);
            moved += (i == BR_X_OMEGA) && (d1 != 0.0);
        }
        /* theta: the same noise sample, unscaled */
        assert_memory_equal(&x[0][BR_X_THETA][j], &x[2][BR_X_THETA][j], sizeof(float));
    }
    assert_true(moved > 32); /* omega moved on most particles */
    /* the predict-only step under OPT_HELD: omega's noise its own, unscaled */
    scaled_predictions(BR_PF_PROPOSAL_OPT_HELD, x);
    assert_memory_equal(x[0][BR_X_OMEGA], x[2][BR_X_OMEGA], sizeof x[0][BR_X_OMEGA]);
    int zmoved = 0;
    for (uint32_t j = 0; j < 64u; j++) {
        zmoved += x[0][BR_X_Z][j] != x[2][BR_X_Z][j];
    }
    assert_true(zmoved > 32); /* z's noise is scaled there too */
}

/* The adapt tests need the reference machine: its file switches adapt on
 * (heavy and emps keep it off) and plant 0 is drawn around it. They are
 * built only in the reference machine's configuration (BR_TEST_THESIS_MACHINE,
 * tests/unit/CMakeLists.txt), where a file without adapt fails them. */
#ifdef BR_TEST_THESIS_MACHINE
/* cfg.adapt keeps the thesis filter's arithmetic while the smoothed NIS
 * stays at or below nis_ref: a PF with it and one without, on the same
 * measurements of a slow move (innovations within the cloud), hold the same
 * particles bit for bit; a jump of 20 gate sigmas raises E above nis_ref
 * and the filters part (omega's, z's and g_p's noise scaled by q_scale_std > 1). */
static void test_adapt_is_thesis_filter_below_ref(void **st)
{
    (void)st;
    br_pf_t *a = calloc(1, sizeof *a), *b = calloc(1, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    br_pf_cfg_t ca = br_circle_pf_cfg_tuned(BR_EST_PF_PERIOD_S);
    ca.load = (br_pf_load_t){0.0f, 0.0f}; /* the thesis filter (test_pf_load.c has the load's) */
    br_pf_cfg_t cb = ca;
    ca.n_particles = cb.n_particles = 300;
    assert_true(ca.adapt.nis_ref > 0.0f); /* the reference machine's file has it on */
    cb.adapt.nis_ref = 0.0f;
    assert_int_equal(br_pf_init(a, &ca), BR_OK);
    assert_int_equal(br_pf_init(b, &cb), BR_OK);
    for (int k = 0; k < 400; k++) {
        br_meas_t y = {k / 40, 0.5f}; /* one count every 40 periods */
        assert_int_equal(br_pf_step(a, &y, 0.0f), br_pf_step(b, &y, 0.0f));
        assert_true(a->nis_avg <= ca.adapt.nis_ref);
        assert_true(a->q_scale_std == 1.0f);
    }
    assert_memory_equal(a->x, b->x, sizeof a->x);
    assert_memory_equal(&a->est, &b->est, sizeof a->est);
    /* a jump far outside the cloud */
    const float sigma = sqrtf(ca.est.r_var_rad2 + RPC * RPC / 12.0f) / RPC;
    br_meas_t y = {10 + (int32_t)(20.0f * ca.est.outlier_sigma * sigma), 0.5f};
    assert_int_equal(br_pf_step(a, &y, 0.0f), BR_W_OUTLIER);
    assert_int_equal(br_pf_step(b, &y, 0.0f), BR_W_OUTLIER);
    assert_true(a->nis_avg > ca.adapt.nis_ref);
    assert_true(a->q_scale_std > 1.0f);
    assert_true(a->q_scale_std <= sqrtf(ca.adapt.max_scale));
    assert_true(b->q_scale_std == 1.0f);
    y.counts = 10;
    (void)br_pf_step(a, &y, 0.0f);
    (void)br_pf_step(b, &y, 0.0f);
    assert_true(memcmp(a->x, b->x, sizeof a->x) != 0);
    free(a);
    free(b);
}

/* Plant 0 of the CI's robustness sample (sim/studies/robustness.py, seed
 * 20261123; docs/robustness.md): the reference machine with softer bristles
 * (sigma0 x0.53), less Coulomb friction, friction drift -8 %, 0.17 N of force
 * noise per period. The circle with H-inf + PF (the tuned PF, br_robust_run's
 * run of that plant). */
static br_circle_cfg_t robust_plant0(br_circle_ctrl_t ctrl, float nis_ref)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(ctrl);
    br_plant_cfg_t *p = &c.plant;
    p->sigma0_Npm *= 0.531522309580413;
    p->sigma1_Nspm *= 0.6942187034615022;
    p->Fc_N *= 0.8263604813152723;
    p->Fs_N *= 0.9731625474543647;
    p->vs_mps *= 1.6637765081952742;
    p->sigma2_Nspm *= 1.0080883552941136;
    p->J_kgm2 *= 1.0064866030910873; /* the moving mass x1.006 */
    p->M_kg *= 1.0064866030910873;
    c.real = (br_circle_real_t){-0.0843537, 0.169206, 0.000105894, 20261123u};
    c.pf.adapt.nis_ref = nis_ref;
    c.pf.load = (br_pf_load_t){0.0f, 0.0f}; /* adapt alone (the machine's load: below) */
    return c;
}

/* The innovation-driven process noise (cfg.adapt, docs/modules/pf.md,
 * "Keeping lock"): on plant 0 the thesis filter's cloud misses the axis at
 * reversals (its bristles and friction level are not the model's). With the
 * tuning of 2026-11-23 the lock monitor then stopped the axis (at 4.08 s);
 * with today's noise-aware tuning it runs on with 63 outlier steps
 * (2026-11-24). With the machine file's adapt the filter keeps lock: a fifth
 * of those outliers or fewer (3 measured), below 1 % of the axis-periods,
 * a contour error below the thesis filter's and below H-inf only's. */
static void test_adapt_keeps_lock_under_force_noise(void **st)
{
    (void)st;
    const br_circle_cfg_t base = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    assert_true(base.pf.adapt.nis_ref > 0.0f); /* the reference machine's file has it on */
    br_circle_result_t r_off, r_on, r_hinf;
    br_circle_cfg_t c = robust_plant0(BR_CTRL_HINF_PF, 0.0f);
    (void)br_circle_run(&c, NULL, NULL, &r_off); /* off: the thesis filter */
    c = robust_plant0(BR_CTRL_HINF_PF, base.pf.adapt.nis_ref);
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r_on), 0);
    assert_int_equal(r_on.fault_status, 0);
    assert_true((double)r_on.outlier_steps < 0.01 * 2.0 * (double)r_on.n_samples);
    /* the thesis filter stopped, or ran with at least five times the outliers and a larger error */
    assert_true(r_off.fault_status != 0 ||
                (5 * r_on.outlier_steps < r_off.outlier_steps && r_on.contour_rms_m < r_off.contour_rms_m));
    /* the machine's PF as it ships (adapt and the shared external force): the same */
    br_circle_result_t r_mach;
    c = robust_plant0(BR_CTRL_HINF_PF, base.pf.adapt.nis_ref);
    c.pf.load = base.pf.load;
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r_mach), 0);
    assert_int_equal(r_mach.fault_status, 0);
    assert_true((double)r_mach.outlier_steps < 0.01 * 2.0 * (double)r_mach.n_samples);
    print_message("plant 0, the machine's PF (load %s): %.3e m, %d outliers\n", base.pf.load.max_N > 0.0f ? "on" : "off",
                  r_mach.contour_rms_m, r_mach.outlier_steps);
    c = robust_plant0(BR_CTRL_HINF_ONLY, 0.0f);
    assert_int_equal(br_circle_run(&c, NULL, NULL, &r_hinf), 0);
    print_message("plant 0: adapt off: fault %d at %.3f s, %.3e m, %d outliers; on: %.3e m, %d outliers of %ld "
                  "periods; H-inf only %.3e m\n", r_off.fault_status, r_off.fault_t_s, r_off.contour_rms_m,
                  r_off.outlier_steps, r_on.contour_rms_m, r_on.outlier_steps, r_on.n_samples, r_hinf.contour_rms_m);
    assert_true(r_on.contour_rms_m < r_hinf.contour_rms_m);
    assert_true(r_mach.contour_rms_m < r_hinf.contour_rms_m);
}

#endif /* BR_TEST_THESIS_MACHINE */

/* cfg.gp_curve (docs/modules/pf.md, "Fast moves"): a cloud at rest pushed
 * well beyond the Stribeck velocity by predictions alone. With g_p along the
 * curve (rho = 1: the offset kept) the mean g_p falls by Fs - Fc with the
 * curve; as the thesis's random walk it stays at its start, Fs. */
static void test_gp_curve_follows_breakaway(void **st)
{
    (void)st;
    for (uint32_t on = 0u; on <= 1u; on++) {
        br_pf_t *pf = calloc(1, sizeof *pf);
        assert_non_null(pf);
        br_pf_cfg_t c = cfg(200);
        c.gp_curve = (br_pf_gp_curve_t){on, 1.0f};
        assert_int_equal(br_pf_init(pf, &c), BR_OK);
        const br_lugre_cfg_t *lg = &c.est.model.lugre;
        const br_meas_t y = {0, 0.5f};
        assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
        const float gp_start = stats(pf).mean[BR_X_GP];
        /* a force of 5 Fs on the table: above 100 vs within the first steps */
        const float u = 5.0f * lg->Fs_N * c.est.model.lead_mprad;
        for (int k = 0; k < 20; k++) assert_int_equal(br_pf_predict(pf, u), BR_OK);
        const br_pf_stats_t s = stats(pf);
        assert_true(c.est.model.lead_mprad * s.mean[BR_X_OMEGA] > 100.0f * lg->vs_mps);
        const float drop = gp_start - s.mean[BR_X_GP], step = lg->Fs_N - lg->Fc_N;
        if (on) {
            assert_true(fabsf(drop - step) < 0.1f * step);
        } else {
            assert_true(fabsf(drop) < 0.1f * step);
        }
        free(pf);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_guards),          cmocka_unit_test(test_resample_idx),
        cmocka_unit_test(test_bad_input_keeps_state), cmocka_unit_test(test_outlier_100_sigma),
        cmocka_unit_test(test_gate_transient),
        cmocka_unit_test(test_gate_quantisation),
        cmocka_unit_test(test_all_invalid_keeps_previous), cmocka_unit_test(test_weights_survive_underflow),
        cmocka_unit_test(test_ess_reported),         cmocka_unit_test(test_tracks_plant_friction),
        cmocka_unit_test(test_predict_is_model_step),
        cmocka_unit_test(test_vector_path_is_scalar_path),
        cmocka_unit_test(test_gp_stays_in_range),
        cmocka_unit_test(test_gp_curve_follows_breakaway),
        cmocka_unit_test(test_one_invalid_particle),
        cmocka_unit_test(test_theta_nan_particle),
        cmocka_unit_test(test_fnl_overflow_is_invalid),
        cmocka_unit_test(test_only_last_particle_valid),
        cmocka_unit_test(test_likelihood_scale),
        cmocka_unit_test(test_proposal_matches_equations),
        cmocka_unit_test(test_proposal_adapt_takes_the_prior_draw),
        cmocka_unit_test(test_adapt_scales_omega),
#ifdef BR_TEST_THESIS_MACHINE
        cmocka_unit_test(test_adapt_is_thesis_filter_below_ref),
        cmocka_unit_test(test_adapt_keeps_lock_under_force_noise),
#endif
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
