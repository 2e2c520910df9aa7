/* SPDX-License-Identifier: Apache-2.0 */
/* br_tune_qec: the reversal (quadrant-error) compensation tuned from circle
 * tests, as a CNC commissioning engineer tunes a control's friction
 * compensation (docs/modules/qec.md, "Tuning from a circle test"): on the
 * hardware-like plant (br_circle_cfg_hardware_like, the reference machine's
 * stand-in for the real axis), the thesis circle and the same circle at
 * FAST_FEED times its feed (the acceleration at the reversals FAST_FEED^2
 * times the thesis's: without a second acceleration A1 is not identifiable),
 * Nelder-Mead (sim/lib/nm/br_nm) over (A0_N, A1_kg, tau_s) minimises the sum of
 * the two circles' quadrant glitches (br_circle_quadrant.h), each divided by
 * H-inf only's on the same circle. A run the firmware stopped scores +inf.
 *
 * Usage: br_tune_qec [--max-fev N]
 * Prints the progress, then the tuned values as the machine file's
 * reversal_comp block (machines/reference.json holds them) and each circle's
 * figures with and without the pulse. */
#include <math.h>
#include <stdio.h>

#include "circle/br_circle.h"
#include "circle/br_circle_quadrant.h"
#include "nm/br_nm.h"
#include "bristle_gen/machine/br_machine.h"
#include "tool/br_args.h"

#define TOOL "br_tune_qec"
/* the second circle's feed, times the thesis's */
#define FAST_FEED 4.0
#define N_CIRCLES 2

typedef struct {
    br_circle_cfg_t cfg[N_CIRCLES]; /* H-inf + QEC on each circle */
    double hinf_q[N_CIRCLES];       /* H-inf only's quadrant glitch on each */
} tune_t;

static void set_params(br_circle_cfg_t *c, const double *x)
{
    c->qec.A0_N = (float)x[0];
    c->qec.A1_kg = (float)x[1];
    c->qec.tau_s = (float)x[2];
}

/* the objective: sum over the circles of quadrant glitch / H-inf only's */
static double objective(void *user, const double *x, int n)
{
    (void)n;
    tune_t *t = user;
    double f = 0.0;
    for (int i = 0; i < N_CIRCLES; i++) {
        set_params(&t->cfg[i], x);
        br_quadrant_result_t r;
        if (br_circle_quadrant_run(&t->cfg[i], &r) != 0) return INFINITY;
        f += r.quadrant_rms_m / t->hinf_q[i];
    }
    return f;
}

static void progress(void *user, int iter, int nfev, const double *x, double f, int n)
{
    (void)user;
    (void)n;
    printf("iter %3d  fev %4d  objective %.4f  A0 %.4g N  A1 %.4g kg  tau %.4g s\n", iter, nfev, f, x[0], x[1], x[2]);
    fflush(stdout);
}

/* the circles: the thesis's and FAST_FEED times its feed, on the hardware-like plant */
static br_circle_cfg_t circle(int i, br_circle_ctrl_t ctrl)
{
    br_circle_cfg_t c = br_circle_cfg_hardware_like(ctrl);
    if (i == 1) br_circle_use_path(&c, 0.0, FAST_FEED * br_circle_feed_mps(&c), 0);
    return c;
}

int main(int argc, char **argv)
{
    long max_fev = 120;
    static const struct option opts[] = {{"max-fev", required_argument, NULL, 'm'}, {NULL, 0, NULL, 0}};
    br_args_t p;
    const int st = br_args_begin(&p, TOOL, argc, argv);
    if (st == BR_ARGS_HELP) {
        printf("usage: %s [--max-fev N]\n" BR_ARGS_COMMON_USAGE
               "  --max-fev N   Nelder-Mead's evaluation budget (10 .. 10000, default 120)\n", argv[0], argv[0]);
        return 0;
    }
    if (st == BR_ARGS_VERSION) {
        br_args_print_version(TOOL, stdout);
        return 0;
    }
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        if (c != 'm' || br_arg_long(TOOL, p.opt, val, 10, 10000, &max_fev) != 0) {
            fprintf(stderr, "usage: %s [--max-fev N]\n", argv[0]);
            return 2;
        }
    }
    tune_t t;
    for (int i = 0; i < N_CIRCLES; i++) {
        br_circle_cfg_t h = circle(i, BR_CTRL_HINF_ONLY);
        br_quadrant_result_t r;
        if (br_circle_quadrant_run(&h, &r) != 0) {
            fprintf(stderr, "%s: H-inf only did not run circle %d to the end; no tuning\n", TOOL, i);
            return 1;
        }
        t.hinf_q[i] = r.quadrant_rms_m;
        t.cfg[i] = circle(i, BR_CTRL_HINF_QEC);
        printf("circle %d: feed %.4g mm/min, H-inf only: quadrant glitch %.4e m, contour RMS %.4e m\n", i,
               br_circle_feed_mps(&h) * 60000.0, r.quadrant_rms_m, r.run.contour_rms_m);
    }
    /* the start: a pulse of the Coulomb level, no acceleration term, 20 ms; the box: up to
     * twice the stiction level, +-2e4 kg (+-20 N at the fast circle's 1e-3 m/s^2), 1 ms .. 0.5 s */
    const double x0[3] = {BR_MACHINE_FC_N, 0.0, 0.02};
    const double lo[3] = {0.0, -2.0e4, 1.0e-3}, hi[3] = {2.0 * BR_MACHINE_FS_N, 2.0e4, 0.5};
    const br_nm_cfg_t nc = {3, 1.0e-3, 1.0e-4, (int)max_fev, lo, hi, 0.5, progress};
    br_nm_result_t res;
    if (br_nm_minimize(&nc, objective, &t, x0, &res) != 0 || !isfinite(res.f)) {
        fprintf(stderr, "%s: the search failed\n", TOOL);
        return 1;
    }
    printf("\"reversal_comp\": {\"A0_N\": %.5g, \"A1_kg\": %.5g, \"tau_s\": %.5g}\n", res.x[0], res.x[1], res.x[2]);
    printf("objective %.4f (2 = no gain), %d evaluations, %s\n", res.f, res.nfev,
           res.converged ? "converged" : "budget reached");
    for (int i = 0; i < N_CIRCLES; i++) {
        set_params(&t.cfg[i], res.x);
        br_quadrant_result_t r;
        if (br_circle_quadrant_run(&t.cfg[i], &r) != 0) return 1;
        printf("circle %d: H-inf + QEC: quadrant glitch %.4e m (%.3f of H-inf only), contour RMS %.4e m\n", i,
               r.quadrant_rms_m, r.quadrant_rms_m / t.hinf_q[i], r.run.contour_rms_m);
    }
    return 0;
}
