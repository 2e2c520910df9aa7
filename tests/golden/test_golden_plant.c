/* SPDX-License-Identifier: Apache-2.0 */
/* Golden test: the double-precision plant br_plant_step against
 * golden/traces/plant.csv and plant_wrap.csv (float64 reference
 * golden/ref/plant.py), and with the Maxwell-slip friction against
 * plant_gms.csv (slip law) and plant_gms_clamp.csv (clamp limit;
 * golden/ref/gms.py): full trajectories from x0, never reset.
 * Tolerances: docs/golden.md. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "plant/br_sim_plant.h"
#include "trace_reader.h"

/* Both sides are IEEE double running the same algorithm; differences come
 * only from evaluation order and libm (~1e-16 relative per operation).
 * Perturbing the reference by 1e-13 relative (a hundred ulps) moves the
 * trajectories by < 2e-12 rad, 6e-12 rad/s, 4e-18 m, 1.4e-11 N
 * (docs/golden.md); the tolerances sit above that and are still ~1e-10 of
 * each signal's scale. */
#define TOL_THETA 1e-10   /* rad (1.7e-5 counts), plus TOL_THETA_REL |theta| */
#define TOL_THETA_REL 1e-15
#define TOL_OMEGA 1e-9    /* rad/s (signal scale 60 rad/s) */
#define TOL_Z 1e-16       /* m (bristle scale 4.5e-6 m) */
#define TOL_FNL 1e-8      /* N: sigma0 TOL_Z + 2 sigma1 L TOL_OMEGA, rounded up */
#define ENC_NEAR_INT 1e-6 /* counts: +-1 allowed where theta/rad_per_count is this close to an integer */
/* Maxwell-slip: the element deflections (scale up to 3e-5 m) and the force,
 * whose element damping adds sigma1_i times the rates' differences
 * (docs/golden.md, "plant_gms") */
#define TOL_ZI 1e-14      /* m */
#define TOL_FNL_GMS 1e-7  /* N */

/* the trace's Maxwell-slip elements (gms_* metadata) into cfg */
static void gms_from_trace(const br_trace_t *t, br_plant_cfg_t *cfg)
{
    br_gms_cfg_t *g = &cfg->gms;
    g->n = (int)br_trace_meta_num(t, "gms_n");
    assert_true(g->n >= 1 && g->n <= BR_GMS_MAX);
    g->clamp = (int)br_trace_meta_num(t, "gms_clamp");
    g->C_mps = br_trace_meta_num(t, "gms_C_mps");
    g->delta = br_trace_meta_num(t, "gms_delta");
    br_trace_meta_nums(t, "gms_k_Npm", g->k_Npm, g->n);
    br_trace_meta_nums(t, "gms_alpha", g->alpha, g->n);
    br_trace_meta_nums(t, "gms_sigma1_Nspm", g->sigma1_Nspm, g->n);
}

static void run_plant_trace(const char *name, int gms)
{
    br_trace_t t;
    br_trace_load(&t, name);
    br_plant_cfg_t cfg = {
        .J_kgm2 = br_trace_meta_num(&t, "J_kgm2"),
        .M_kg = br_trace_meta_num(&t, "M_kg"),
        .lead_mprad = br_trace_meta_num(&t, "L_mprad"),
        .sigma2_Nspm = br_trace_meta_num(&t, "sigma2_Nspm"),
        .sigma0_Npm = br_trace_meta_num(&t, "sigma0_Npm"),
        .sigma1_Nspm = br_trace_meta_num(&t, "sigma1_Nspm"),
        .Fc_N = br_trace_meta_num(&t, "Fc_N"),
        .Fs_N = br_trace_meta_num(&t, "Fs_N"),
        .vs_mps = br_trace_meta_num(&t, "vs_mps"),
        .counts_per_rev = br_trace_meta_num(&t, "counts_per_rev"),
        .tau_per_duty_Nm = br_trace_meta_num(&t, "tau_per_duty_Nm"),
        .n_sub = (int)br_trace_meta_num(&t, "n_sub"),
    };
    if (gms) gms_from_trace(&t, &cfg);
    double x0v[3];
    br_trace_meta_nums(&t, "x0", x0v, 3);
    const double dt = br_trace_meta_num(&t, "dt_s");
    const double rpc = 2.0 * 3.14159265358979323846 / cfg.counts_per_rev;
    br_plant_state_t x0 = {.theta_rad = x0v[0], .omega_radps = x0v[1], .z_m = x0v[2]};
    br_plant_t p;
    assert_int_equal(br_plant_init(&p, &cfg, &x0), 0);

    const int cd = br_trace_col(&t, "duty"), cth = br_trace_col(&t, "theta");
    const int cw = br_trace_col(&t, "omega"), cz = gms ? -1 : br_trace_col(&t, "z");
    int czi[BR_GMS_MAX];
    for (int i = 0; i < cfg.gms.n; i++) {
        char col[16];
        snprintf(col, sizeof col, "z%d", i + 1);
        czi[i] = br_trace_col(&t, col);
    }
    const int cf = br_trace_col(&t, "fnl"), ce = br_trace_col(&t, "encoder");
    br_errstat_t eth, ew, ez, ef, ee;
    br_errstat_init(&eth, "theta", "rad");
    br_errstat_init(&ew, "omega", "rad/s");
    br_errstat_init(&ez, "z", "m");
    br_errstat_init(&ef, "fnl", "N");
    br_errstat_init(&ee, "encoder", "count");
    long enc_off_by_one = 0;

    for (int r = 0; r < t.nrows; r++) {
        br_plant_step(&p, br_trace_get(&t, r, cd), dt);
        const double th = br_trace_get(&t, r, cth);
        br_errstat_add(&eth, &t, r, p.x.theta_rad, th, TOL_THETA + TOL_THETA_REL * fabs(th));
        br_errstat_add(&ew, &t, r, p.x.omega_radps, br_trace_get(&t, r, cw), TOL_OMEGA);
        if (gms) {
            for (int i = 0; i < cfg.gms.n; i++)
                br_errstat_add(&ez, &t, r, p.gms.z_m[i], br_trace_get(&t, r, czi[i]), TOL_ZI);
            br_errstat_add(&ef, &t, r, p.fnl_N, br_trace_get(&t, r, cf), TOL_FNL_GMS);
        } else {
            br_errstat_add(&ez, &t, r, p.x.z_m, br_trace_get(&t, r, cz), TOL_Z);
            br_errstat_add(&ef, &t, r, p.fnl_N, br_trace_get(&t, r, cf), TOL_FNL);
        }
        /* encoder: exact, except +-1 where floor() sits on an integer boundary */
        const double q = th / rpc;
        const double enc_tol = (fabs(q - nearbyint(q)) < ENC_NEAR_INT) ? 1.0 : 0.0;
        const int32_t enc = br_plant_encoder(&p);
        const int32_t enc_exp = (int32_t)br_trace_get(&t, r, ce);
        enc_off_by_one += (enc != enc_exp && enc_tol > 0.0);
        /* wrap-safe count difference */
        const int32_t d = (int32_t)(uint32_t)((uint32_t)enc - (uint32_t)enc_exp);
        br_errstat_add(&ee, &t, r, (double)d, 0.0, enc_tol);
    }
    br_errstat_print(&eth, &t, name);
    br_errstat_print(&ew, &t, name);
    br_errstat_print(&ez, &t, name);
    br_errstat_print(&ef, &t, name);
    br_errstat_print(&ee, &t, name);
    print_message("golden %-10s encoder rows off by one count at an integer boundary: %ld\n",
                  name, enc_off_by_one);
    const long fails = eth.n_fail + ew.n_fail + ez.n_fail + ef.n_fail + ee.n_fail;
    const int nrows = t.nrows;
    br_trace_free(&t);
    if (fails != 0) {
        fail_msg("%s: %ld comparisons of %d rows outside tolerance (first lines printed above)",
                 name, fails, nrows);
    }
}

static void test_plant_trajectory(void **state)
{
    (void)state;
    run_plant_trace("plant", 0);
}

static void test_plant_encoder_wrap(void **state)
{
    (void)state;
    run_plant_trace("plant_wrap", 0);
}

static void test_plant_gms_slip(void **state)
{
    (void)state;
    run_plant_trace("plant_gms", 1);
}

static void test_plant_gms_clamp(void **state)
{
    (void)state;
    run_plant_trace("plant_gms_clamp", 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plant_trajectory),
        cmocka_unit_test(test_plant_encoder_wrap),
        cmocka_unit_test(test_plant_gms_slip),
        cmocka_unit_test(test_plant_gms_clamp),
    };
    return cmocka_run_group_tests_name("golden_plant", tests, NULL, NULL);
}
