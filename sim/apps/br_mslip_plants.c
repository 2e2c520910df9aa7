/* SPDX-License-Identifier: Apache-2.0 */
/* br_mslip_plants: every controller on drawn Maxwell-slip plants (docs/presliding-plants.md;
 * docs/modules/qec.md, "On drawn Maxwell-slip plants"). Plants drawn like the hardware-like
 * one (br_circle_cfg_hardware_like) with another presliding: 2-6 elements, each breaking
 * away at Fs at a displacement log-uniform in 0.3-30 um, shares uniform in [0.5, 1.5]
 * normalised to 1, element damping uniform in 300-4000 N s/m (the ranges of issue 30's
 * random plants), the slip law and C of the hardware-like plant; the rest of the machine as
 * it is. On each, the thesis circle with H-inf only, + static feedforward, + the reversal
 * pulse tuned once on the hardware-like plant (the machine file's), + UKF, + PF, all as
 * shipped, and the true friction at t_k (the limit). A run the firmware stopped is a fault
 * with its time and cause, never a figure (br_run_report.h); medians over the plants where
 * a controller ran.
 *
 * Plant j is the j-th draw of the seed's stream whatever --first and --n: a study runs
 * plants in any split (sim/studies/mslip_plants.py).
 *
 * --ff-el own|fit adds a column: the feedforward with Maxwell-slip elements (the plant's own,
 * or four fitted to its initial stiffness and Fs; docs/modules/ff-pred.md); --pred S adds the
 * prediction over S s to the UKF's, the PF's, the oracle's and that feedforward's compensation;
 * --oracle-late makes the oracle one period late.
 *
 * Usage: br_mslip_plants [--n N] [--first J] [--seed S] [--json OUT] [--ff-el own|fit] [--pred S] [--oracle-late]
 *                        [--hw] [--pf-trace FILE] [--posterior FILE --at T1,T2,..]
 *                        [--pf-q-scale FZ,FG] [--pf-gate SIGMA] [--pf-load Q]
 * Prints one line per plant (contour RMS in m, or FAULT) and the medians; --json writes
 * each plant's elements and runs (br_outfile.h: nothing is written unless every run was
 * made). --hw runs the demo's hardware-like plant itself (plant -1) instead of draws.
 * --pf-trace writes one row per PF step and axis of every PF run (br_circle_pftrace.h:
 * the cloud beside the truth, the best particle's miss and the gate); --posterior the
 * x axis's PF particles and UKF mean and sigma at the times --at. --pf-q-scale,
 * --pf-gate and --pf-load change the PF's z and g_p process noise (factors), its outlier
 * gate (sigmas) and its shared external force (random walk, N^2/s; docs/modules/pf.md)
 * on every plant, for studies; a figure with them is not the shipped PF's.
 * Exit 0, 1 (a run could not be made, or the output), 2 (usage). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"
#include "circle/br_circle_pftrace.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_rng.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_mslip_plants"
#define MAX_N 200
#define MAX_FIRST 100000
#define N_CTRL_MAX 7
#define QEC 2 /* ctrls[QEC]: the baseline of the paired line */
#define FF_EL 6 /* ctrls[FF_EL]: the feedforward with elements, a column only with --ff-el */

static const br_circle_ctrl_t ctrls[N_CTRL_MAX] = {BR_CTRL_HINF_ONLY, BR_CTRL_HINF_FF, BR_CTRL_HINF_QEC,
                                                   BR_CTRL_HINF_UKF,  BR_CTRL_HINF_PF, BR_CTRL_HINF_TRUE,
                                                   BR_CTRL_HINF_FF};

static const char *col_name(int k)
{
    return k == FF_EL ? "hinf_ff_el" : br_circle_ctrl_name(ctrls[k]);
}

/* the next plant's Maxwell-slip presliding into c (the draw described above) */
static void draw_plant(br_circle_cfg_t *c, br_rng_t *r)
{
    const int n = 2 + (int)floor(5.0 * br_rng_uniform(r)); /* 2..6 */
    double d[BR_GMS_MAX] = {0}, a[BR_GMS_MAX] = {0}, sum = 0.0;
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

static int usage(const char *argv0, FILE *f)
{
    fprintf(f,
            "usage: %s [--n N] [--first J] [--seed S] [--json OUT] [--ff-el own|fit] [--pred S] [--oracle-late]\n"
            "       [--hw] [--pf-trace FILE] [--posterior FILE --at T1,T2,..] [--pf-q-scale FZ,FG] [--pf-gate SIGMA]\n"
            "       [--pf-load Q]\n"
            "  --n N       how many plants (1 .. %d; default 10)\n"
            "  --first J   the first plant's index in the seed's stream (0 .. %d; default 0)\n"
            "  --seed S    the draw's seed (0 .. 1000000000; default 1)\n"
            "  --json OUT  each plant's elements and runs as JSON\n"
            "  --ff-el own|fit  a column hinf_ff_el: the feedforward with the plant's own elements or the fit\n"
            "  --pred S    the prediction over S s (0 .. %g; needs --ff-el) on the UKF, PF, oracle and hinf_ff_el\n"
            "  --oracle-late  the true friction one period late\n"
            "  --hw        the demo's hardware-like plant itself (plant -1), not draws\n"
            "  --pf-trace FILE   one row per PF step and axis of every PF run (CSV)\n"
            "  --posterior FILE  the x axis's PF particles and UKF mean and sigma at the times --at (CSV)\n"
            "  --at T1,T2,..     ascending times, s (at most %d)\n"
            "  --pf-q-scale FZ,FG  the PF's z and g_p process noise times FZ and FG (1e-6 .. 1e6; a study)\n"
            "  --pf-gate SIGMA   the PF's outlier gate, sigmas (1 .. 1000; a study)\n"
            "  --pf-load Q       the PF's shared external force, random walk Q N^2/s (0 .. 1e9; 0: off; default the machine's;\n"
            "                    a study, docs/modules/pf.md)\n" BR_ARGS_COMMON_USAGE,
            argv0, MAX_N, MAX_FIRST, (double)BR_FF_PRED_MAX_S, BR_PFTRACE_MAX_AT, argv0);
    return f == stdout ? 0 : 2;
}

static void json_plant(FILE *f, long idx, int comma, const br_gms_cfg_t *g, double Fs_N, const br_run_report_t *rep,
                       int n_ctrl)
{
    fprintf(f, "%s\n    {\"plant\": %ld, \"elements\": [", comma ? "," : "", idx);
    for (int i = 0; i < g->n; i++)
        fprintf(f, "%s{\"breakaway_m\": %.6e, \"share\": %.6f, \"k_Npm\": %.6e, \"sigma1_Nspm\": %.6g}",
                i ? ", " : "", g->alpha[i] * Fs_N / g->k_Npm[i], g->alpha[i], g->k_Npm[i], g->sigma1_Nspm[i]);
    fprintf(f, "],\n     \"runs\": {");
    for (int k = 0; k < n_ctrl; k++) {
        fprintf(f, "%s\"%s\": {", k ? ", " : "", col_name(k));
        br_run_json(f, "contour_rms_m", "max_err_m", &rep[k]);
        fprintf(f, "}");
    }
    fprintf(f, "}}");
}

int main(int argc, char **argv)
{
    long n = 10, first = 0, seed = 1;
    const char *json = NULL, *trace = NULL, *post = NULL;
    int ff_el = BR_CIRCLE_FF_EL_NONE, late = 0, hw = 0, have_at = 0;
    double pred_s = 0.0;
    float qs[2] = {1.0f, 1.0f};
    double gate = 0.0; /* 0: the machine file's */
    double pf_load = -1.0; /* 0: off; < 0: the machine file's */
    static br_pftrace_t tr;
    static const struct option opts[] = {{"ff-el", required_argument, NULL, 'E'},
                                         {"pred", required_argument, NULL, 'P'},
                                         {"oracle-late", no_argument, NULL, 'O'},
                                         {"n", required_argument, NULL, 'n'},
                                         {"first", required_argument, NULL, 'f'},
                                         {"seed", required_argument, NULL, 's'},
                                         {"json", required_argument, NULL, 'j'},
                                         {"hw", no_argument, NULL, 'w'},
                                         {"pf-trace", required_argument, NULL, 't'},
                                         {"posterior", required_argument, NULL, 'p'},
                                         {"at", required_argument, NULL, 'a'},
                                         {"pf-q-scale", required_argument, NULL, 'q'},
                                         {"pf-gate", required_argument, NULL, 'g'},
                                         {"pf-load", required_argument, NULL, 'L'},
                                         {NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        int bad = 1;
        if (c == 'n') bad = br_arg_long(TOOL, p.opt, val, 1, MAX_N, &n);
        else if (c == 'f') bad = br_arg_long(TOOL, p.opt, val, 0, MAX_FIRST, &first);
        else if (c == 's') bad = br_arg_long(TOOL, p.opt, val, 0, 1000000000L, &seed);
        else if (c == 'j') {
            json = val;
            bad = 0;
        } else if (c == 'E') {
            ff_el = strcmp(val, "own") == 0 ? BR_CIRCLE_FF_EL_OWN : strcmp(val, "fit") == 0 ? BR_CIRCLE_FF_EL_FIT : -1;
            bad = ff_el < 0;
        } else if (c == 'P') bad = br_arg_double(TOOL, p.opt, val, 0.0, (double)BR_FF_PRED_MAX_S, &pred_s);
        else if (c == 'O') {
            late = 1;
            bad = 0;
        } else if (c == 'w') hw = 1, bad = 0;
        else if (c == 't') trace = val, bad = 0;
        else if (c == 'p') post = val, bad = 0;
        else if (c == 'a') bad = br_pftrace_parse_at(TOOL, val, &tr), have_at = 1;
        else if (c == 'g') bad = br_arg_double(TOOL, p.opt, val, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA, &gate);
        else if (c == 'L') bad = br_arg_double(TOOL, p.opt, val, 0.0, 1.0e9, &pf_load);
        else if (c == 'q') {
            int used = 0;
            bad = sscanf(val, "%f,%f%n", &qs[0], &qs[1], &used) != 2 || val[used] != '\0' ||
                  !(qs[0] >= 1e-6f && qs[0] <= 1e6f && qs[1] >= 1e-6f && qs[1] <= 1e6f);
            if (bad) fprintf(stderr, "%s: --pf-q-scale %s: two comma-separated factors in [1e-6, 1e6]\n", TOOL, val);
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (pred_s > 0.0 && ff_el == BR_CIRCLE_FF_EL_NONE) {
        fprintf(stderr, "%s: --pred needs --ff-el own|fit\n", TOOL);
        return usage(argv[0], stderr);
    }
    if (!post != !have_at) {
        fprintf(stderr, "%s: --posterior and --at go together\n", TOOL);
        return usage(argv[0], stderr);
    }
    const int n_ctrl = ff_el != BR_CIRCLE_FF_EL_NONE ? N_CTRL_MAX : N_CTRL_MAX - 1;
    if (hw) n = 1, first = -1;
    br_outfile_t tro = {0}, po = {0};
    if (trace && br_outfile_open(&tro, TOOL, trace) != 0) return 1;
    if (post && br_outfile_open(&po, TOOL, post) != 0) {
        br_outfile_discard(&tro);
        return 1;
    }
    tr.trace = tro.f;
    tr.posterior = po.f;
    br_pftrace_headers(&tr);
    br_outfile_t js = {0};
    if (json && br_outfile_open(&js, TOOL, json) != 0) return 1;
    if (js.f) fprintf(js.f, "{\"seed\": %ld, \"first\": %ld, \"n\": %ld, \"plants\": [", seed, first, n);
    static double rms[N_CTRL_MAX][MAX_N];
    static int ok[N_CTRL_MAX][MAX_N];
    int n_ok[N_CTRL_MAX] = {0};
    br_rng_t r = {(uint64_t)seed * 0x9E3779B97F4A7C15ull + 12345u, 0, 0.0};
    for (long j = 0; j < first; j++) { /* the draws before the first plant, dropped (none with --hw) */
        br_circle_cfg_t skip = br_circle_cfg_hardware_like(BR_CTRL_HINF_ONLY);
        draw_plant(&skip, &r);
    }
    printf("%-5s %-3s %-28s", "plant", "n", "breakaway [um]");
    for (int k = 0; k < n_ctrl; k++) printf(" %12s", col_name(k));
    printf("\n");
    for (int j = 0; j < n; j++) {
        br_circle_cfg_t base = br_circle_cfg_hardware_like(BR_CTRL_HINF_ONLY);
        if (!hw) draw_plant(&base, &r);
        char el[64] = "";
        int w = 0;
        for (int i = 0; i < base.plant.gms.n && w < (int)sizeof el - 8; i++)
            w += snprintf(el + w, sizeof el - (size_t)w, "%s%.2g", i ? "," : "",
                          1e6 * base.plant.gms.alpha[i] * base.plant.Fs_N / base.plant.gms.k_Npm[i]);
        printf("%-5ld %-3d %-28s", first + j, base.plant.gms.n, el);
        br_run_report_t rep[N_CTRL_MAX];
        for (int k = 0; k < n_ctrl; k++) {
            br_circle_cfg_t c = br_circle_cfg_hardware_like(ctrls[k]);
            c.plant.gms = base.plant.gms;
            /* the feedforward's elements from this plant, the prediction on the estimators, the
             * oracle and the feedforward with elements (never on the static map's column) */
            if (k == FF_EL || (pred_s > 0.0 && ctrls[k] != BR_CTRL_HINF_FF)) br_circle_use_ff_el(&c, ff_el);
            if (k == FF_EL || ctrls[k] != BR_CTRL_HINF_FF) br_circle_use_pred(&c, pred_s, 1);
            c.oracle_late = late;
            c.pf.est.q_var[BR_X_Z] *= qs[0];
            c.pf.est.q_var[BR_X_GP] *= qs[1];
            br_circle_use_pf_gate(&c, gate);
            br_circle_use_pf_load(&c, pf_load);
            tr.label = first + j;
            tr.plant = &c.plant;
            tr.next_at = 0;
            const int traced = (tr.trace || tr.posterior) && (ctrls[k] == BR_CTRL_HINF_PF || ctrls[k] == BR_CTRL_HINF_UKF);
            br_circle_result_t res;
            const int rc = br_circle_run(&c, traced ? br_pftrace_sink : NULL, &tr, &res);
            if (rc < 0) {
                fprintf(stderr, "%s: plant %ld, %s: the run could not be made\n", TOOL, first + j, col_name(k));
                br_outfile_discard(&js);
                br_outfile_discard(&tro);
                br_outfile_discard(&po);
                return 1;
            }
            rep[k] = (br_run_report_t){res.contour_rms_m, res.max_err_m, res.fault_status, res.fault_cause,
                                       res.fault_t_s};
            ok[k][j] = rc == 0;
            rms[k][j] = res.contour_rms_m;
            if (rc == 0) printf(" %12.3e", res.contour_rms_m);
            else printf(" %12s", "FAULT");
            n_ok[k] += ok[k][j];
        }
        printf("\n");
        for (int k = 0; k < n_ctrl; k++) /* a stop's time and cause, never a figure */
            if (!ok[k][j]) br_run_print(stdout, col_name(k), "contour", &rep[k]);
        if (js.f) json_plant(js.f, first + j, j > 0, &base.plant.gms, base.plant.Fs_N, rep, n_ctrl);
        fflush(stdout);
    }
    if (js.f) {
        fprintf(js.f, "\n  ]}\n");
        if (br_outfile_commit(&js, TOOL) != 0) return 1;
    }
    if ((tro.f && br_outfile_commit(&tro, TOOL) != 0) || (po.f && br_outfile_commit(&po, TOOL) != 0)) return 1;
    printf("%-38s", "median over the plants it ran on");
    for (int k = 0; k < n_ctrl; k++) {
        double v[MAX_N];
        int m = 0;
        for (int j = 0; j < n; j++)
            if (ok[k][j]) v[m++] = rms[k][j];
        if (m > 0) printf(" %12.3e", median(v, m));
        else printf(" %12s", "-");
    }
    printf("\n%-38s", "ran to the end (of N)");
    for (int k = 0; k < n_ctrl; k++) printf(" %9d/%-2ld", n_ok[k], n);
    /* paired: the reversal pulse against each other controller where both ran */
    printf("\n%-38s", "better than + QEC where both ran");
    for (int k = 0; k < n_ctrl; k++) {
        int both = 0, better = 0;
        for (int j = 0; j < n; j++)
            if (ok[k][j] && ok[QEC][j]) {
                both++;
                better += rms[k][j] < rms[QEC][j];
            }
        if (k == QEC) printf(" %12s", "-");
        else printf(" %9d/%-2d", better, both);
    }
    printf("\n");
    return 0;
}
