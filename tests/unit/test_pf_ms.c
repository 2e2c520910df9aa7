/* SPDX-License-Identifier: Apache-2.0 */
/* The PF with Maxwell-slip elements (docs/modules/pf.md, "Maxwell-slip
 * elements"): init's guards, one particle's prediction against the model's
 * own step (br_model_ms_step) bit for bit, the elements inside their bounds,
 * the scalar reference path against the kernel path bit for bit, the
 * re-anchoring moving the elements, and the thesis model untouched by the
 * element storage. */
#include "br_test.h"

#include <stdlib.h>
#include <string.h>

#include "bristle/br_pf.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"

#define DT_F 1.5e-3f

static br_pf_t *new_pf(void)
{
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    return pf;
}

/* the circle's PF with the hardware-like plant's element set */
static br_pf_cfg_t ms_cfg(uint32_t m)
{
    br_pf_cfg_t c = br_circle_pf_cfg_tuned(DT_F);
    c.load = (br_pf_load_t){0.0f, 0.0f}; /* the shared external force is LuGre-only */
    c.n_particles = m;
    br_circle_est_mslip(&c.est);
    return c;
}

static void test_ms_init_guards(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf();
    br_pf_cfg_t c = ms_cfg(1500u);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    /* the storage: n m <= BR_PF_MS_SLOTS */
    c = ms_cfg(1500u);
    c.est.model.mslip.n = BR_MSLIP_MAX;
    for (int i = 0; i < BR_MSLIP_MAX; i++) {
        c.est.model.mslip.k_Npm[i] = 1.0e6f;
        c.est.model.mslip.share[i] = 1.0f / (float)BR_MSLIP_MAX;
    }
    c.n_particles = BR_PF_MS_SLOTS / BR_MSLIP_MAX;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    c.n_particles = BR_PF_MS_SLOTS / BR_MSLIP_MAX + 1u;
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    assert_int_equal(pf->ready, 0);
    /* the look-ahead steps LuGre: refused with elements */
    c = ms_cfg(100u);
    c.est.comp_ahead_periods = 1.0f;
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    /* an invalid element set (shares not summing to 1) */
    c = ms_cfg(100u);
    c.est.model.mslip.share[0] = 0.5f;
    assert_int_equal(br_pf_init(pf, &c), BR_E_PARAM);
    free(pf);
}

/* |e_ji| <= c_i g_pj for every element of every particle, and kgp_j = sum k_i e_ji */
static void assert_elements_bounded(const br_pf_t *pf)
{
    const uint32_t m = pf->cfg.n_particles;
    const br_mslip_cfg_t *ms = &pf->model.cfg.mslip;
    for (uint32_t j = 0; j < m; j++) {
        float f = 0.0f;
        for (int i = 0; i < ms->n; i++) {
            const float e = pf->ms[(uint32_t)i * m + j];
            assert_true(fabsf(e) <= pf->model.ms_c_mpN[i] * pf->x[BR_X_GP][j]);
            f += ms->k_Npm[i] * e;
        }
        assert_true(f == pf->kgp[j]);
        assert_true(pf->x[BR_X_Z][j] == 0.0f);
    }
}

/* With a zero noise table a predict-only step is the model's own step: every
 * particle's theta, omega and elements those of br_model_ms_step, its force
 * br_model_ms_fnl_N, bit for bit (the process noise adds 0 and the clamp at
 * the same g_p leaves the elements as they are). */
static void test_ms_predict_is_model_ms_step(void **st)
{
    (void)st;
    static const float zeros[64] = {0};
    br_pf_t *pf = new_pf();
    br_pf_cfg_t c = ms_cfg(16u);
    c.noise = zeros;
    c.noise_len = 64u;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    const br_meas_t y = {0, 0.5f};
    assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    const uint32_t m = c.n_particles;
    const float u[] = {0.4f, 0.4f, -0.3f, 0.0f, 0.8f, -0.8f};
    float F_sum_seen = 0.0f;
    for (int k = 0; k < 40; k++) {
        const float uk = u[k % 6];
        float x0[16][BR_NX], e0[16][BR_MSLIP_MAX];
        for (uint32_t j = 0; j < m; j++) {
            for (int i = 0; i < BR_NX; i++) x0[j][i] = pf->x[i][j];
            for (int i = 0; i < c.est.model.mslip.n; i++) e0[j][i] = pf->ms[(uint32_t)i * m + j];
        }
        assert_int_equal(br_pf_predict(pf, uk), BR_OK);
        float sf = 0.0f;
        for (uint32_t j = 0; j < m; j++) {
            float x1[BR_NX], e1[BR_MSLIP_MAX];
            assert_int_equal(br_model_ms_step(&pf->model, x0[j], e0[j], uk, x1, e1), BR_OK);
            assert_true(x1[BR_X_THETA] == pf->x[BR_X_THETA][j]);
            assert_true(x1[BR_X_OMEGA] == pf->x[BR_X_OMEGA][j]);
            for (int i = 0; i < c.est.model.mslip.n; i++) {
                assert_true(e1[i] == pf->ms[(uint32_t)i * m + j]);
            }
            assert_true(br_model_ms_fnl_N(&pf->model, e1) == pf->fnl[j]);
            sf += pf->fnl[j];
        }
        assert_true(pf->est.F_hat_N == sf * (1.0f / (float)m));
        F_sum_seen += fabsf(pf->est.F_hat_N);
        assert_elements_bounded(pf);
    }
    assert_true(F_sum_seen > 0.0f); /* the elements moved */
    free(pf);
}

/* a measurement stream along a slow back-and-forth (counts, frac) and torques */
static br_meas_t meas_at(int k)
{
    const float p = 40.0f * sinf(0.02f * (float)k); /* counts */
    const float fl = floorf(p);
    const br_meas_t y = {(int32_t)fl, p - fl};
    return y;
}

/* The scalar reference path and the kernel path give the same particles,
 * elements, estimate and statuses bit for bit, with invalid particles and
 * outlier steps with re-anchoring in the stream. */
static void test_ms_scalar_is_vector_path(void **st)
{
    (void)st;
    br_pf_t *a = new_pf(), *b = new_pf();
    br_pf_cfg_t c = ms_cfg(1499u);
    assert_int_equal(br_pf_init(a, &c), BR_OK);
    c.scalar_path = 1;
    assert_int_equal(br_pf_init(b, &c), BR_OK);
    const uint32_t m = c.n_particles;
    int n_out = 0;
    for (int k = 0; k < 200; k++) {
        br_meas_t y = meas_at(k);
        if (k >= 120 && k < 125) y.counts += 400; /* a jump: outliers, then a re-anchoring */
        if (k == 60) {
            /* invalid particles: a NaN omega, an infinite one */
            a->x[BR_X_OMEGA][7] = b->x[BR_X_OMEGA][7] = NAN;
            a->x[BR_X_OMEGA][900] = b->x[BR_X_OMEGA][900] = INFINITY;
        }
        const float u = 0.3f * cosf(0.02f * (float)k);
        const br_status_t sa = (k % 17 == 5) ? br_pf_predict(a, u) : br_pf_step(a, &y, u);
        const br_status_t sb = (k % 17 == 5) ? br_pf_predict(b, u) : br_pf_step(b, &y, u);
        assert_int_equal(sa, sb);
        n_out += sa == BR_W_OUTLIER;
        for (int i = 0; i < BR_NX; i++) assert_memory_equal(a->x[i], b->x[i], m * sizeof a->x[i][0]);
        assert_memory_equal(a->kgp, b->kgp, m * sizeof a->kgp[0]);
        assert_memory_equal(a->ms, b->ms, (size_t)c.est.model.mslip.n * m * sizeof a->ms[0]);
        assert_memory_equal(&a->est, &b->est, sizeof a->est);
        assert_true(isfinite(a->est.F_hat_N));
        assert_elements_bounded(a);
    }
    assert_true(n_out >= (int)c.est.reanchor_after);
    free(a);
    free(b);
}

/* A re-anchoring moves every particle's elements by the position's jump
 * L d_theta (eq. MS1): after a jump of 400 counts every element sits at its
 * bound in the jump's direction, and F_hat is their force. */
static void test_ms_reanchor_moves_elements(void **st)
{
    (void)st;
    br_pf_t *pf = new_pf();
    br_pf_cfg_t c = ms_cfg(200u);
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    const uint32_t m = c.n_particles;
    br_meas_t y = {0, 0.5f};
    for (int k = 0; k < 20; k++) assert_int_equal(br_pf_step(pf, &y, 0.0f), BR_OK);
    /* 8000 counts (61 um): beyond twice every breakaway at the largest g_p (1.5 Fs: the
     * 20 um element's 30 um; 4000 counts left it short on a particle with g_p near there) */
    y.counts = 8000;
    br_status_t s = BR_OK;
    for (uint32_t k = 0; k < c.est.reanchor_after; k++) s = br_pf_step(pf, &y, 0.0f);
    assert_int_equal(s, BR_W_OUTLIER);
    float sf = 0.0f;
    for (uint32_t j = 0; j < m; j++) {
        for (int i = 0; i < c.est.model.mslip.n; i++) {
            assert_true(pf->ms[(uint32_t)i * m + j] == pf->model.ms_c_mpN[i] * pf->x[BR_X_GP][j]);
        }
        sf += pf->kgp[j];
    }
    assert_true(pf->est.F_hat_N == sf * (1.0f / (float)m));
    assert_elements_bounded(pf);
    free(pf);
}

/* The proposal and g_p along the curve run the per-particle step with
 * elements: finite, bounded, and not the bootstrap's particles. */
static void test_ms_variants_run(void **st)
{
    (void)st;
    for (int v = 0; v < 2; v++) {
        br_pf_t *pf = new_pf(), *p0 = new_pf();
        br_pf_cfg_t c = ms_cfg(300u);
        assert_int_equal(br_pf_init(p0, &c), BR_OK);
        if (v == 0) c.proposal = BR_PF_PROPOSAL_OPT_HELD;
        else {
            c.gp_curve.on = 1u;
            c.gp_curve.rho = 0.9f;
        }
        assert_int_equal(br_pf_init(pf, &c), BR_OK);
        for (int k = 0; k < 100; k++) {
            const br_meas_t y = meas_at(k);
            assert_false(BR_FAILED(br_pf_step(pf, &y, 0.2f)));
            assert_false(BR_FAILED(br_pf_step(p0, &y, 0.2f)));
            assert_true(isfinite(pf->est.F_hat_N));
            assert_elements_bounded(pf);
        }
        assert_true(memcmp(pf->x[BR_X_OMEGA], p0->x[BR_X_OMEGA], 300 * sizeof(float)) != 0);
        free(pf);
        free(p0);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ms_init_guards),
        cmocka_unit_test(test_ms_predict_is_model_ms_step),
        cmocka_unit_test(test_ms_scalar_is_vector_path),
        cmocka_unit_test(test_ms_reanchor_moves_elements),
        cmocka_unit_test(test_ms_variants_run),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
