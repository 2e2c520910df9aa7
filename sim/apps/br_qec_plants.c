/* SPDX-License-Identifier: Apache-2.0 */
/* br_qec_plants: does the reversal compensation's tuning transfer? (docs/modules/qec.md,
 * "On drawn Maxwell-slip plants"). N plants drawn like the hardware-like one
 * (br_circle_cfg_hardware_like) with another presliding: 2-6 elements, each
 * breaking away at Fs at a displacement log-uniform in 0.3-30 um, shares
 * uniform in [0.5, 1.5] normalised to 1, element damping uniform in
 * 300-4000 N s/m (the ranges of issue 30's random plants), the slip law and C
 * of the hardware-like plant; the rest of the machine as it is. On each, the
 * thesis circle with H-inf only, + static feedforward, + the reversal pulse
 * tuned once on the hardware-like plant (the machine file's), + UKF, + PF, all
 * as shipped. A run the firmware stopped is a fault, never a figure
 * (br_run_report.h); medians over the plants where a controller ran.
 *
 * Usage: br_qec_plants [--n N] [--seed S]
 * Prints one line per plant (contour RMS in m, or FAULT) and the medians. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "circle/br_circle.h"
#include "tools/br_args.h"
#include "tools/br_rng.h"
#include "tools/br_run_report.h"

#define TOOL "br_qec_plants"
#define MAX_N 200
#define N_CTRL 5

static const br_circle_ctrl_t ctrls[N_CTRL] = {BR_CTRL_HINF_ONLY, BR_CTRL_HINF_FF, BR_CTRL_HINF_QEC,
                                               BR_CTRL_HINF_UKF, BR_CTRL_HINF_PF};

/* plant j's Maxwell-slip presliding into c (the draw described above) */
static void draw_plant(br_circle_cfg_t *c, br_rng_t *r)
{
    const int n = 2 + (int)floor(5.0 * br_rng_uniform(r)); /* 2..6 */
    double d[BR_GMS_MAX], a[BR_GMS_MAX], sum = 0.0;
    for (int i = 0; i < n; i++) {
        d[i] = 0.3e-6 * pow(100.0, br_rng_uniform(r)); /* log-uniform 0.3-30 um */
        a[i] = 0.5 + br_rng_uniform(r);
        sum += a[i];
    }
    for (int i = 0; i < n; i++) a[i] /= sum;
    br_gms_from_breakaway(&c->plant.gms, n, d, a, c->plant.Fs_N, 0.0);
    for (int i = 0; i < n; i++) c->plant.gms.sigma1_Nspm[i] = 300.0 + 3700.0 * br_rng_uniform(r);
}

static int cmp_double(const void *x, const void *y)
{
    const double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int main(int argc, char **argv)
{
    long n = 10, seed = 1;
    static const struct option opts[] = {{"n", required_argument, NULL, 'n'}, {"seed", required_argument, NULL, 's'},
                                         {NULL, 0, NULL, 0}};
    br_args_t p;
    const int st = br_args_begin(&p, TOOL, argc, argv);
    if (st == BR_ARGS_HELP || st == BR_ARGS_VERSION) {
        if (st == BR_ARGS_VERSION) br_args_print_version(TOOL, stdout);
        else printf("usage: %s [--n N] [--seed S]\n" BR_ARGS_COMMON_USAGE, argv[0], argv[0]);
        return 0;
    }
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        const int bad = c == 'n'   ? br_arg_long(TOOL, p.opt, val, 1, MAX_N, &n)
                        : c == 's' ? br_arg_long(TOOL, p.opt, val, 0, 1000000000L, &seed)
                                   : 1;
        if (bad) {
            fprintf(stderr, "usage: %s [--n N] [--seed S]\n", argv[0]);
            return 2;
        }
    }
    static double rms[N_CTRL][MAX_N];
    static int ok[N_CTRL][MAX_N];
    int n_ok[N_CTRL] = {0};
    br_rng_t r = {(uint64_t)seed * 0x9E3779B97F4A7C15ull + 12345u, 0, 0.0};
    printf("%-5s %-3s %-28s", "plant", "n", "breakaway [um]");
    for (int k = 0; k < N_CTRL; k++) printf(" %12s", br_circle_ctrl_name(ctrls[k]));
    printf("\n");
    for (int j = 0; j < n; j++) {
        br_circle_cfg_t base = br_circle_cfg_hardware_like(BR_CTRL_HINF_ONLY);
        draw_plant(&base, &r);
        char el[64] = "";
        int w = 0;
        for (int i = 0; i < base.plant.gms.n && w < (int)sizeof el - 8; i++)
            w += snprintf(el + w, sizeof el - (size_t)w, "%s%.2g", i ? "," : "",
                          1e6 * base.plant.gms.alpha[i] * base.plant.Fs_N / base.plant.gms.k_Npm[i]);
        printf("%-5d %-3d %-28s", j, base.plant.gms.n, el);
        for (int k = 0; k < N_CTRL; k++) {
            br_circle_cfg_t c = br_circle_cfg_hardware_like(ctrls[k]);
            c.plant.gms = base.plant.gms;
            br_circle_result_t res;
            const int rc = br_circle_run(&c, NULL, NULL, &res);
            if (rc < 0) return 1;
            ok[k][j] = rc == 0;
            rms[k][j] = res.contour_rms_m;
            if (rc == 0) printf(" %12.3e", res.contour_rms_m);
            else printf(" %12s", "FAULT");
            n_ok[k] += ok[k][j];
        }
        printf("\n");
        fflush(stdout);
    }
    printf("%-38s", "median over the plants it ran on");
    for (int k = 0; k < N_CTRL; k++) {
        double v[MAX_N];
        int m = 0;
        for (int j = 0; j < n; j++)
            if (ok[k][j]) v[m++] = rms[k][j];
        if (m > 0) printf(" %12.3e", median(v, m));
        else printf(" %12s", "-");
    }
    printf("\n%-38s", "ran to the end (of N)");
    for (int k = 0; k < N_CTRL; k++) printf(" %9d/%-2ld", n_ok[k], n);
    /* paired: the QEC (index 2) against each other controller where both ran */
    printf("\n%-38s", "better than + QEC where both ran");
    for (int k = 0; k < N_CTRL; k++) {
        int both = 0, better = 0;
        for (int j = 0; j < n; j++)
            if (ok[k][j] && ok[2][j]) {
                both++;
                better += rms[k][j] < rms[2][j];
            }
        if (k == 2) printf(" %12s", "-");
        else printf(" %9d/%-2d", better, both);
    }
    printf("\n");
    return 0;
}
