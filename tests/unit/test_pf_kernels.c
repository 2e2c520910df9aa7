/* SPDX-License-Identifier: Apache-2.0 */
/* The PF's kernels against the reference kernel, bit for bit
 * (firmware/private/br_pf_kernel.h, docs/modules/pf.md "Kernels"): the
 * kernel under test (br_pf_kernel_*: the library's on this host, or a
 * target's file compiled into the test, BR_TEST_KERNEL names it) and the
 * reference (br_pf_kref_*) run on two copies of the same particle set, the
 * same noise, command and measurement, over a stream of steps of a real
 * filter with edge cases put in: a NaN particle, a particle beyond the RK4
 * limit (the bounded scheme), one whose f_nl overflows, g_p outside
 * [gp_min, gp_max], a log-weight of -inf, outlier steps; runs of every
 * length from one particle up, at offsets. Then the resampling on the
 * predicted set, and on weights made for it (ties, one valid particle, the
 * largest m). Everything the kernels write is compared as bits. The same
 * with Maxwell-slip elements (br_pf_kref_predict_ms against the kernel's
 * element path; the elements' copy in place): NaN and infinite theta and
 * omega, non-finite element deflections, g_p outside its range, l = -inf,
 * outlier steps. */
#include "br_test.h"

#include <stdlib.h>
#include <string.h>

#include "bristle/br_pf.h"
#include "br_pf_kernel.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"

#ifndef BR_TEST_KERNEL
#define BR_TEST_KERNEL "the library's"
#endif

#define M 1499u

static int same_f(float a, float b) { return memcmp(&a, &b, sizeof a) == 0; }

/* the circle's PF with m particles; its bristle stiffness sigma0 times s0_k
 * (s0_k = 16: omega_n h 4 times the reference's 0.51, so that the model steps
 * in n_sub = 3 sub-steps, docs/modules/model.md "Sub-steps") */
static br_pf_t *new_pf_s0(uint32_t m, float s0_k)
{
    br_pf_t *pf = calloc(1, sizeof *pf);
    assert_non_null(pf);
    br_pf_cfg_t c = br_circle_pf_cfg_default(1.5e-3f);
    c.n_particles = m;
    c.est.model.lugre.sigma0_Npm *= s0_k;
    assert_int_equal(br_pf_init(pf, &c), BR_OK);
    return pf;
}

static br_pf_t *new_pf(uint32_t m) { return new_pf_s0(m, 1.0f); }

static br_pf_t *clone(const br_pf_t *pf)
{
    br_pf_t *c = malloc(sizeof *c);
    assert_non_null(c);
    memcpy(c, pf, sizeof *c);
    return c;
}

/* what a kernel writes: state, k_p, f_nl, l, W, idx of the first m particles */
static void assert_sets_equal(const br_pf_t *a, const br_pf_t *b, int k, const char *what)
{
    const uint32_t m = a->cfg.n_particles;
    for (int i = 0; i < BR_NX; i++) {
        if (memcmp(a->x[i], b->x[i], m * sizeof a->x[i][0]) != 0) {
            fail_msg("%s, step %d: state %d differs from the reference (kernel %s)", what, k, i, BR_TEST_KERNEL);
        }
    }
    assert_memory_equal(a->kgp, b->kgp, m * sizeof a->kgp[0]);
    assert_memory_equal(a->fnl, b->fnl, m * sizeof a->fnl[0]);
    assert_memory_equal(a->l, b->l, m * sizeof a->l[0]);
    assert_memory_equal(a->W, b->W, m * sizeof a->W[0]);
    assert_memory_equal(a->idx, b->idx, m * sizeof a->idx[0]);
    /* the elements, when the particles carry them */
    const size_t ne = (a->model.cfg.mslip.n > 0) ? (size_t)a->model.cfg.mslip.n : 0u;
    if (memcmp(a->ms, b->ms, ne * m * sizeof a->ms[0]) != 0) {
        fail_msg("%s, step %d: the elements differ from the reference (kernel %s)", what, k, BR_TEST_KERNEL);
    }
}

/* the constants of a prediction pass, as br_pf.c makes them (any finite
 * values would do: both kernels get the same) */
static br_pf_kc_t consts(br_pf_t *pf, float u, float shift, float y_rel)
{
    br_pf_kc_t c;
    c.mk = br_model_k(&pf->model);
    c.kp = br_model_kp(&pf->model, u);
    c.s0L = pf->model.cfg.lugre.sigma0_Npm * pf->model.cfg.lead_mprad;
    for (int i = 0; i < BR_NX; i++) {
        c.q[i] = pf->q_std[i];
    }
    c.gp_min = pf->cfg.est.gp_min_N;
    c.gp_max = pf->cfg.est.gp_max_N;
    c.inv_2r = pf->inv_2r;
    c.shift = shift;
    c.y_rel = y_rel;
    c.n_sub = pf->model.n_sub;
    c.km = br_model_km(&pf->model);
    c.uh = u * c.km.h;
    return c;
}

/* the edge cases of step k, put into both copies the same way */
typedef struct {
    int nan, bounded, overflow, gp_out, l_inf;
} edges_t;

static void put_edges(br_pf_t *a, br_pf_t *b, int k, edges_t *n)
{
    const uint32_t m = a->cfg.n_particles;
    const float s0L = a->model.cfg.lugre.sigma0_Npm * a->model.cfg.lead_mprad;
    if (k % 3 == 1) {
        const uint32_t j = (uint32_t)(7 * k) % m;
        a->x[BR_X_THETA][j] = b->x[BR_X_THETA][j] = NAN; /* only the validity test catches it */
        n->nan++;
    }
    if (k % 4 == 2) {
        for (uint32_t j = (uint32_t)k % 37u; j < m; j += 37u) {
            a->x[BR_X_OMEGA][j] = b->x[BR_X_OMEGA][j] = (j % 2u ? 1.0f : -1.0f) * 5.0e3f; /* a h > 2 */
            n->bounded++;
        }
    }
    if (k % 5 == 3) {
        for (uint32_t j = 5u; j < m; j += 211u) {
            a->x[BR_X_Z][j] = b->x[BR_X_Z][j] = 3.0e38f; /* f_nl overflows */
            n->overflow++;
        }
    }
    /* g_p outside its range on both sides (k_p consistent with it) */
    for (uint32_t j = (uint32_t)k % 53u; j < m; j += 53u) {
        const float g = (j % 2u) ? 4.0f * a->cfg.est.gp_max_N : 0.25f * a->cfg.est.gp_min_N;
        a->x[BR_X_GP][j] = b->x[BR_X_GP][j] = g;
        a->kgp[j] = b->kgp[j] = s0L / g;
        n->gp_out++;
    }
    if (k % 6 == 0) {
        /* theta far away, finite: (theta - y)^2 overflows, l = -inf, still valid */
        const uint32_t j = (uint32_t)(11 * k + 3) % m;
        a->x[BR_X_THETA][j] = b->x[BR_X_THETA][j] = 1.0e30f;
        n->l_inf++;
    }
}

/* the prediction of both copies over runs of particles in one block of the
 * noise table, of lengths 1, 2, 3, ... (then the rest of the block);
 * returns the number of particles the kernel left */
static uint32_t predict_both(br_pf_t *a, br_pf_t *b, const br_pf_kc_t *c, int k, int ms)
{
    const uint32_t m = a->cfg.n_particles, mask = a->cfg.noise_len - 1u;
    br_pf_lsum_t la = {-INFINITY, 0u, 0.0f, 0.0f}, lb = la;
    uint32_t j = 0u, len = 1u, left_b = 0u;
    while (j < m) {
        const uint32_t p = (a->noise_pos + BR_NX * j) & mask;
        const uint32_t room = (mask + 1u - p) / BR_NX;
        if (room == 0u) {
            j++; /* samples round the table's end: the orchestrator's per-particle step */
            continue;
        }
        uint32_t j1 = (m - j < room) ? m : j + room;
        if (j1 - j > len) {
            j1 = j + len;
        }
        len++;
        const float *nz = a->cfg.noise + p;
        const float s1a = la.s1, s2a = la.s2, s1b = lb.s1, s2b = lb.s2;
        const uint32_t left_a = ms ? br_pf_kref_predict_ms(a, c, j, j1, nz, &la) : br_pf_kref_predict(a, c, j, j1, nz, &la);
        const uint32_t lk = ms ? br_pf_kernel_predict_ms(b, c, j, j1, nz, &lb) : br_pf_predict_run(b, c, j, j1, nz, &lb);
        assert_int_equal(lk, left_a);
        assert_true(same_f(la.lmax, lb.lmax));
        assert_int_equal(la.n_valid, lb.n_valid);
        if (left_a == 0u) {
            /* the run's sums hold (bit for bit, in particle order) when nothing is left */
            assert_true(same_f(la.s1, lb.s1));
            assert_true(same_f(la.s2, lb.s2));
        } else {
            la.s1 = s1a, la.s2 = s2a, lb.s1 = s1b, lb.s2 = s2b;
        }
        left_b += lk;
        j = j1;
    }
    assert_sets_equal(a, b, k, "prediction");
    return left_b;
}

/* resampling of both copies; the same sum of f_nl */
static void resample_both(br_pf_t *a, br_pf_t *b, float lmax, int outlier, int k)
{
    const float sa = br_pf_kref_resample(a, lmax, outlier);
    const float sb = br_pf_kernel_resample(b, lmax, outlier);
    if (!same_f(sa, sb)) {
        fail_msg("step %d: the sum of f_nl %.9g differs from the reference's %.9g", k, (double)sb, (double)sa);
    }
    assert_sets_equal(a, b, k, "resampling");
}

/* the step's largest valid log-weight, by hand, and its outlier verdict (also
 * every fifth step); both copies resampled. Returns 1 on an outlier step. */
static int resample_step(br_pf_t *a, br_pf_t *b, int k)
{
    float lmax = -INFINITY;
    uint32_t n_valid = 0u;
    for (uint32_t j = 0; j < a->cfg.n_particles; j++) {
        if (a->l[j] == a->l[j]) {
            lmax = (a->l[j] > lmax) ? a->l[j] : lmax;
            n_valid++;
        }
    }
    assert_true(n_valid > 0u);
    const int outlier = lmax < a->outlier_l || lmax == -INFINITY || k % 5 == 0;
    resample_both(a, b, lmax, outlier, k);
    return outlier;
}

/* the stream of steps with the edge cases; n_sub: the sub-steps the model
 * must have chosen */
static void stream(float s0_k, int n_sub)
{
    br_pf_t *src = new_pf_s0(M, s0_k);
    assert_int_equal(src->model.n_sub, n_sub);
    const float rpc = src->cfg.est.rad_per_count;
    edges_t n = {0, 0, 0, 0, 0};
    int n_left = 0, n_outlier = 0, n_clamped = 0, n_steps = 0;
    int32_t prev = 0;
    for (int k = 0; k < 48; k++) {
        /* a ramp with a jump (outliers: steps 30 .. 33), a sinusoidal command */
        const int32_t counts = (int32_t)(k * 3 + (k >= 30 && k < 34 ? 5000 : 0));
        const br_meas_t y = {counts, 0.25f + 0.01f * (float)(k % 7)};
        const float u = 0.02f * sinf(0.3f * (float)k);
        if (k > 0) {
            br_pf_t *a = clone(src), *b = clone(src);
            put_edges(a, b, k, &n);
            const float shift = (float)(counts - prev) * rpc, y_rel = y.frac * rpc;
            const br_pf_kc_t c = consts(a, u, shift, y_rel);
            n_left += (int)predict_both(a, b, &c, k, 0);
            for (uint32_t j = 0; j < M; j++) {
                n_clamped += b->x[BR_X_GP][j] == c.gp_max || b->x[BR_X_GP][j] == c.gp_min;
            }
            /* the step's largest valid log-weight, by hand */
            n_outlier += resample_step(a, b, k);
            n_steps++;
            free(a);
            free(b);
        }
        const br_status_t s = br_pf_step(src, &y, u);
        assert_false(BR_FAILED(s));
        prev = counts;
    }
    /* every edge case was met, and the kernels left particles for the fix-up */
    assert_true(n.nan > 0 && n.bounded > 0 && n.overflow > 0 && n.gp_out > 0 && n.l_inf > 0);
    assert_true(n_left >= n.nan + n.bounded);
    assert_true(n_outlier > 0 && n_clamped > 0 && n_steps == 47);
    free(src);
}

static void test_stream(void **st)
{
    (void)st;
    stream(1.0f, 1);
}

/* the same with the model in sub-steps: every kernel gives the reference's
 * sub-stepped prediction bit for bit */
static void test_stream_sub(void **st)
{
    (void)st;
    stream(16.0f, 3);
}

/* the element path's edge cases of step k, in both copies the same way */
static void put_edges_ms(br_pf_t *a, br_pf_t *b, int k, edges_t *n)
{
    const uint32_t m = a->cfg.n_particles;
    if (k % 3 == 1) {
        const uint32_t j = (uint32_t)(7 * k) % m;
        a->x[BR_X_THETA][j] = b->x[BR_X_THETA][j] = NAN;
        a->x[BR_X_OMEGA][(j + 1u) % m] = b->x[BR_X_OMEGA][(j + 1u) % m] = NAN; /* f_nl stays finite */
        a->x[BR_X_OMEGA][(j + 2u) % m] = b->x[BR_X_OMEGA][(j + 2u) % m] = INFINITY;
        n->nan += 3;
    }
    if (k % 4 == 2) {
        /* element deflections not finite: the clamps take them to a bound */
        for (uint32_t j = (uint32_t)k % 37u; j < m; j += 37u) {
            const uint32_t i = j % (uint32_t)a->model.cfg.mslip.n;
            const float v = (j % 3u == 0u) ? NAN : (j % 3u == 1u) ? INFINITY : -INFINITY;
            a->ms[i * m + j] = b->ms[i * m + j] = v;
            n->overflow++;
        }
    }
    if (k % 5 == 3) {
        /* the force f0 overflowing: omega infinite, the particle left */
        for (uint32_t j = 5u; j < m; j += 211u) {
            a->kgp[j] = b->kgp[j] = 3.0e38f;
            n->bounded++;
        }
    }
    for (uint32_t j = (uint32_t)k % 53u; j < m; j += 53u) {
        const float g = (j % 2u) ? 4.0f * a->cfg.est.gp_max_N : 0.25f * a->cfg.est.gp_min_N;
        a->x[BR_X_GP][j] = b->x[BR_X_GP][j] = g;
        n->gp_out++;
    }
    if (k % 6 == 0) {
        const uint32_t j = (uint32_t)(11 * k + 3) % m;
        a->x[BR_X_THETA][j] = b->x[BR_X_THETA][j] = 1.0e30f;
        n->l_inf++;
    }
}

/* the element stream with the hardware-like set (ne = 4, the M7's written-out
 * path) or its first three elements with equal shares (the loops' path) */
static void stream_ms(int ne)
{
    br_pf_t *src = calloc(1, sizeof *src);
    assert_non_null(src);
    br_pf_cfg_t cfg = br_circle_pf_cfg_default(1.5e-3f);
    cfg.load = (br_pf_load_t){0.0f, 0.0f}; /* the shared external force is LuGre-only */
    cfg.n_particles = M;
    br_circle_est_mslip(&cfg.est);
    if (ne != cfg.est.model.mslip.n) {
        cfg.est.model.mslip.n = ne;
        for (int i = 0; i < ne; i++) {
            cfg.est.model.mslip.share[i] = 1.0f / (float)ne;
        }
    }
    assert_int_equal(br_pf_init(src, &cfg), BR_OK);
    const float rpc = src->cfg.est.rad_per_count;
    edges_t n = {0, 0, 0, 0, 0};
    int n_left = 0, n_outlier = 0, n_steps = 0, n_bound = 0;
    int32_t prev = 0;
    for (int k = 0; k < 48; k++) {
        /* a back-and-forth of 60 counts (elements at their bounds and between), a jump at 30 .. 33 */
        const int32_t counts = (int32_t)(60.0f * sinf(0.25f * (float)k)) + (k >= 30 && k < 34 ? 5000 : 0);
        const br_meas_t y = {counts, 0.25f + 0.01f * (float)(k % 7)};
        const float u = 0.3f * cosf(0.25f * (float)k);
        if (k > 0) {
            br_pf_t *a = clone(src), *b = clone(src);
            put_edges_ms(a, b, k, &n);
            const float shift = (float)(counts - prev) * rpc, y_rel = y.frac * rpc;
            const br_pf_kc_t c = consts(a, u, shift, y_rel);
            n_left += (int)predict_both(a, b, &c, k, 1);
            for (uint32_t j = 0; j < M; j++) {
                n_bound += b->ms[j] == b->model.ms_c_mpN[0] * b->x[BR_X_GP][j];
            }
            n_outlier += resample_step(a, b, k);
            n_steps++;
            free(a);
            free(b);
        }
        assert_false(BR_FAILED(br_pf_step(src, &y, u)));
        prev = counts;
    }
    assert_true(n.nan > 0 && n.bounded > 0 && n.overflow > 0 && n.gp_out > 0 && n.l_inf > 0);
    assert_true(n_left >= n.nan && n_outlier > 0 && n_bound > 0 && n_steps == 47);
    free(src);
}

static void test_stream_ms(void **st)
{
    (void)st;
    stream_ms(4);
    stream_ms(3);
}

/* resampling on weights made for it: log-weights with ties of the
 * cumulative sums, only the last particle valid, m = 1, 2 and the largest */
static void weights_case(uint32_t m, int kind)
{
    br_pf_t *a = new_pf(m);
    for (uint32_t j = 0; j < m; j++) {
        for (int i = 0; i < BR_NX; i++) {
            a->x[i][j] = (float)(i + 1) * 1.0e-3f * (float)j;
        }
        a->kgp[j] = 1.0f + (float)j;
        a->fnl[j] = 0.01f * (float)(j % 17) - 0.05f;
        switch (kind) {
        case 0: /* all equal: every t_i on a multiple of 2^16 */
            a->l[j] = -0.0f;
            break;
        case 1: /* only the last valid */
            a->l[j] = (j + 1u == m) ? -0.5f : NAN;
            break;
        case 2: /* a spread with NaNs and -inf among them */
            a->l[j] = (j % 13u == 4u) ? NAN : (j % 29u == 7u) ? -INFINITY : -0.002f * (float)((j * 7919u) % 5003u);
            break;
        default: /* underflowing weights: most below e^-87 */
            a->l[j] = (j % 7u == 0u) ? -1.0f : -100.0f - (float)j;
            break;
        }
    }
    float lmax = -INFINITY;
    for (uint32_t j = 0; j < m; j++) {
        lmax = (a->l[j] > lmax) ? a->l[j] : lmax; /* a NaN never compares greater */
    }
    for (int outlier = 0; outlier < 2; outlier++) {
        br_pf_t *r = clone(a), *b = clone(a);
        resample_both(r, b, lmax, outlier, kind);
        assert_true(r->W[m - 1u] > 0u || kind != 1);
        free(r);
        free(b);
    }
    free(a);
}

static void test_made_weights(void **st)
{
    (void)st;
    const uint32_t ms[] = {1u, 2u, 3u, 100u, 1499u, BR_PF_MAX_PARTICLES};
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) {
        for (int kind = 0; kind < 4; kind++) {
            weights_case(ms[i], kind);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stream),
        cmocka_unit_test(test_stream_sub),
        cmocka_unit_test(test_stream_ms),
        cmocka_unit_test(test_made_weights),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
