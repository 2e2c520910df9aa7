/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the extended model (the causes of a diagnosis) of
 * br_model_step_at / br_model_fcomp_N (float32) against
 * golden/traces/model_ext.csv (float64 reference golden/ref/model.py): each
 * cause alone and all together, one-step rows. Tolerances: docs/golden.md,
 * "Extended model": the rounding chains of the thesis model's test, with the
 * load force's scale grown by the causes, plus the bound of the kernel's
 * third-order expansion of the ripple about the origin and of the friction
 * scale s(t) held over the step at the model's clock (the reference takes it
 * at each stage's time). */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bristle/br_model.h"
#include "bristle_gen/model/br_causes.h"
#include "trace_reader.h"

#define U32 5.9604644775390625e-08 /* float32 unit roundoff 2^-24 */
/* the rounding-chain factors of test_golden_model.c (docs/golden.md) */
#define C_THETA 32.0
#define C_OMEGA 32.0
#define C_Z 64.0
#define C_FNL 32.0
#define SEG_MAX 16 /* segments the test holds; the trace says how many it has */
#define PI 3.14159265358979323846

/* br_causes_t's fields by name: the registry's table (bristle_gen/model/br_causes.h) */
#define FIELD_ROW(field, cause, hook, on) {#field, offsetof(br_causes_t, field)},
static const struct {
    const char *name;
    size_t off;
} FIELDS[BR_CAUSE_N_FIELDS] = {BR_CAUSE_FIELDS(FIELD_ROW)};
#undef FIELD_ROW

/* the trace's segments: its seg<n>_name header lines, n = 1.. */
static int n_segments(const br_trace_t *t)
{
    int n = 0;
    for (int i = 0; i < t->nmeta; i++) {
        int seg, len = 0;
        if (sscanf(t->meta_key[i], "seg%d_name%n", &seg, &len) == 1 && t->meta_key[i][len] == '\0') {
            n++;
        }
    }
    return n;
}

/* the trace's causes_order: each value's offset in br_causes_t; returns their count */
static int causes_order(const br_trace_t *t, size_t off[BR_CAUSE_N_FIELDS])
{
    const char *p = br_trace_meta(t, "causes_order");
    int n = 0;
    char word[64];
    int len;
    while (sscanf(p, "%63s%n", word, &len) == 1) {
        int f = 0;
        while (f < BR_CAUSE_N_FIELDS && strcmp(FIELDS[f].name, word) != 0) {
            f++;
        }
        if (f == BR_CAUSE_N_FIELDS || n == BR_CAUSE_N_FIELDS) {
            fail_msg("%s: causes_order: '%s' is not a field of br_causes_t (or one too many)", t->path, word);
        }
        off[n++] = FIELDS[f].off;
        p += len;
    }
    return n;
}

static br_causes_t seg_causes(const br_trace_t *t, int seg, const size_t off[], int n_cause)
{
    char key[16];
    double v[BR_CAUSE_N_FIELDS];
    snprintf(key, sizeof key, "seg%d", seg);
    br_trace_meta_nums(t, key, v, n_cause);
    br_causes_t c;
    memset(&c, 0, sizeof c);
    for (int i = 0; i < n_cause; i++) {
        *(float *)(void *)((char *)&c + off[i]) = (float)v[i];
    }
    return c;
}

/* |A sin(phi0 + d) - its cubic expansion| <= |A| d^4 / 24 */
static double ripple_expansion_bound(const br_causes_t *c, double L, double dtheta)
{
    if (c->ripple_amp_N == 0.0f) {
        return 0.0;
    }
    const double d = 2.0 * PI * L * dtheta / (double)c->ripple_period_m;
    return fabs((double)c->ripple_amp_N) * d * d * d * d / 24.0;
}

static void test_model_ext_one_step(void **state)
{
    (void)state;
    br_trace_t t;
    br_trace_load(&t, "model_ext");
    br_model_cfg_t cfg = br_trace_model_cfg(&t);
    const double L = cfg.lead_mprad, s0 = cfg.lugre.sigma0_Npm, s1 = cfg.lugre.sigma1_Nspm;
    const double s2 = cfg.sigma2_Nspm, h = cfg.dt_s, Fc = cfg.lugre.Fc_N;
    const double Jeff = cfg.J_kgm2 + L * L * cfg.M_kg;
    const int n_seg = n_segments(&t);
    assert_true(n_seg >= 1 && n_seg <= SEG_MAX);
    size_t off[BR_CAUSE_N_FIELDS];
    const int n_cause = causes_order(&t, off);
    br_model_t m[SEG_MAX + 1];
    br_causes_t causes[SEG_MAX + 1];
    for (int seg = 1; seg <= n_seg; seg++) {
        causes[seg] = seg_causes(&t, seg, off, n_cause);
        cfg.causes = causes[seg];
        assert_int_equal(br_model_init(&m[seg], &cfg), BR_OK);
        assert_true(m[seg].extended);
    }
    const int cn = br_trace_col(&t, "n");
    const int cseg = br_trace_col(&t, "seg"), cp0 = br_trace_col(&t, "p0"), cu = br_trace_col(&t, "u");
    const int cst = br_trace_col(&t, "status"), cbr = br_trace_col(&t, "branch"), cfc = br_trace_col(&t, "fcomp");
    const int cx[BR_NX] = {br_trace_col(&t, "theta"), br_trace_col(&t, "omega"), br_trace_col(&t, "z"),
                           br_trace_col(&t, "gp")};
    const int cx1[BR_NX] = {br_trace_col(&t, "theta1"), br_trace_col(&t, "omega1"), br_trace_col(&t, "z1"),
                            br_trace_col(&t, "gp1")};
    br_errstat_t e[BR_NX], efc;
    br_errstat_init(&e[0], "theta", "rad");
    br_errstat_init(&e[1], "omega", "rad/s");
    br_errstat_init(&e[2], "z", "m");
    br_errstat_init(&e[3], "gp", "N");
    br_errstat_init(&efc, "fcomp", "N");
    long n_rows[SEG_MAX + 1][2] = {{0}}, bad_status = 0;

    for (int r = 0; r < t.nrows; r++) {
        const int seg = (int)br_trace_get(&t, r, cseg);
        assert_true(seg >= 1 && seg <= n_seg);
        const br_causes_t *c = &causes[seg];
        float x[BR_NX], xn[BR_NX];
        double xd[BR_NX], x1d[BR_NX];
        for (int i = 0; i < BR_NX; i++) {
            xd[i] = br_trace_get(&t, r, cx[i]);
            x1d[i] = br_trace_get(&t, r, cx1[i]);
            x[i] = (float)xd[i];
        }
        const double p0 = br_trace_get(&t, r, cp0), u = br_trace_get(&t, r, cu);
        n_rows[seg][(int)br_trace_get(&t, r, cbr) == 1]++;
        /* the model's clock: the step starts at t = n dt */
        const double n = br_trace_get(&t, r, cn);
        br_model_set_clock(&m[seg], (uint32_t)n);
        const br_status_t st = br_model_step_at(&m[seg], x, (float)p0, (float)u, xn);
        if ((int)st != (int)br_trace_get(&t, r, cst)) {
            if (bad_status++ < 5) {
                print_error("%s:%d: status %d\n", t.path, t.line[r], (int)st);
            }
            continue;
        }
        /* the load force's scale: k(p) (friction) + |offset| + |A| */
        const double c_neg = (Fc + c->dFc_neg_N) / Fc;
        const double drift = fabs((double)c->drift_per_s);
        const double kmax = fmax(1.0, 1.0 + fabs((double)c->grad_per_m) * (fabs(p0) + L * fabs(xd[0]) + 1e-3)) *
                            (1.0 + drift * (n + 1.0) * h);
        const double w0 = fabs(xd[1]), z0 = fabs(xd[2]), gp = xd[3], g = fmax(1.0, c_neg) * gp;
        const double s2d = s2 + fmax(0.0, (double)c->dsigma2_neg_Nspm);
        const double F_scale = kmax * (fmax(s0 * z0, g) + (2.0 * s1 + s2d) * L * w0) +
                               fabs((double)c->offset_N) + fabs((double)c->ripple_amp_N);
        const double S_th = fabs(xd[0]) + fabs(x1d[0]) + h * (w0 + fabs(x1d[1]));
        const double S_w = w0 + fabs(x1d[1]) + h / Jeff * (fabs(u) + L * F_scale);
        const double S_z = fmax(fmax(z0, fabs(x1d[2])), g / s0);
        /* s(t) held over the step: the friction's scale is off by at most drift h
         * (the reference's stages span [t, t + h]), its impulse by that times the
         * friction over h; theta and z follow omega over the step (|dz'/domega| <= 2 L) */
        const double hold_w = h / Jeff * L * drift * h * F_scale;
        /* the ripple's expansion, over the stages' positions and over theta alone */
        const double rip_step = ripple_expansion_bound(c, L, fabs(xd[0]) + h * (w0 + fabs(x1d[1])));
        const double rip_x = ripple_expansion_bound(c, L, fabs(xd[0]));
        br_errstat_add(&e[0], &t, r, (double)xn[0], x1d[0], C_THETA * U32 * S_th + h * hold_w);
        br_errstat_add(&e[1], &t, r, (double)xn[1], x1d[1],
                       C_OMEGA * U32 * S_w + 2.0 * h / Jeff * L * rip_step + hold_w);
        br_errstat_add(&e[2], &t, r, (double)xn[2], x1d[2], C_Z * U32 * S_z + 2.0 * L * h * hold_w);
        br_errstat_add(&e[3], &t, r, (double)xn[3], (double)x[3], 0.0); /* g_p is held exactly */
        br_errstat_add(&efc, &t, r, (double)br_model_fcomp_N(&m[seg], x, (float)p0), br_trace_get(&t, r, cfc),
                       C_FNL * U32 * (F_scale + s2 * L * w0) + 2.0 * rip_x);
    }
    for (int seg = 1; seg <= n_seg; seg++) {
        char key[32]; /* "seg" + any int + "_name" */
        snprintf(key, sizeof key, "seg%d_name", seg);
        print_message("golden model_ext seg %d (%s): %ld RK4, %ld bounded rows\n", seg, br_trace_meta(&t, key),
                      n_rows[seg][0], n_rows[seg][1]);
        /* every cause goes through both schemes */
        assert_true(n_rows[seg][0] > 0 && n_rows[seg][1] > 0);
    }
    long fails = efc.n_fail;
    for (int i = 0; i < BR_NX; i++) {
        br_errstat_print(&e[i], &t, "model_ext");
        fails += e[i].n_fail;
    }
    br_errstat_print(&efc, &t, "model_ext");
    br_trace_free(&t);
    if (bad_status != 0 || fails != 0) {
        fail_msg("model_ext: %ld wrong statuses, %ld comparisons outside tolerance", bad_status, fails);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_model_ext_one_step),
    };
    return cmocka_run_group_tests_name("golden_model_ext", tests, NULL, NULL);
}
