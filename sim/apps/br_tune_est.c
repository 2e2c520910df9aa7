/* Nelder-Mead tuning of an estimator's diagonal Q and R on the simulated
 * circle (thesis section 3.2): minimises the closed-loop contour RMS of the
 * H-inf + PF (or + UKF) circle over the log of the noise variances.
 *
 * Usage: br_tune_est --est pf|ukf --out HEADER [--log CSV] [--max-fev N]
 * Prints a progress line per iteration; writes the tuned variances as a
 * generated header (used by sim/circle/br_circle_est.c) and, with --log, the
 * progress (iteration, evaluations, best contour RMS, parameters) for Fig. 1.
 * The objective is penalised by the outlier steps (lost lock). The start is
 * the hand-tuned default of the machine file's estimator section; each log-variance may move 3 decades
 * either way (bounds by the change of variables of br_nm). The outputs are
 * written beside their names and renamed once the tuning succeeded
 * (br_outfile.h): a failed tuning writes nothing. See docs/tuning.md. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "tune/br_nm.h"
#include "bristle_gen/machine/br_machine.h"
#include "tools/br_args.h"
#include "tools/br_outfile.h"
#include "tools/br_tool_limits.h"

#define TOOL "br_tune_est"
#define MAX_P 5

typedef struct {
    int pf;                 /* 1: PF, 0: UKF */
    br_circle_cfg_t base;
    FILE *log;
    double best;
} tune_t;

/* The tuned parameters: PF (q_omega, q_z, q_gp, R); UKF (q_theta, q_omega, q_z, q_gp, R). */
static int n_params(const tune_t *t) { return t->pf ? 4 : 5; }

static float *param_ptr(br_circle_cfg_t *c, int pf, int i)
{
    if (pf) {
        return i < 3 ? &c->pf.est.q_var[i + 1] : &c->pf.est.r_var_rad2;
    }
    return i < 4 ? &c->ukf.est.q_var[i] : &c->ukf.est.r_var_rad2;
}

static const char *param_name(int pf, int i)
{
    static const char *const pfn[] = {"q_omega", "q_z", "q_gp", "r"};
    static const char *const ukn[] = {"q_theta", "q_omega", "q_z", "q_gp", "r"};
    if (i < 0 || i >= (pf ? 4 : 5)) return "?";
    return pf ? pfn[i] : ukn[i];
}

/* objective: contour RMS (m) of the circle with the variances e^x, times
 * (1 + outlier steps): a filter that loses lock and has to re-anchor is not an
 * acceptable tuning, however small its RMS */
static double objective(void *user, const double *x, int n)
{
    tune_t *t = user;
    br_circle_cfg_t c = t->base;
    for (int i = 0; i < n; i++) *param_ptr(&c, t->pf, i) = (float)exp(x[i]);
    br_circle_result_t r;
    if (br_circle_run(&c, NULL, NULL, &r) != 0) return INFINITY;
    return r.contour_rms_m * (1.0 + (double)r.outlier_steps);
}

static void progress(void *user, int iter, int nfev, const double *xb, double fb, int n)
{
    tune_t *t = user;
    printf("iter %3d  evals %4d  contour RMS %.4e m ", iter, nfev, fb);
    for (int i = 0; i < n; i++) printf(" %s=%.3g", param_name(t->pf, i), exp(xb[i]));
    printf("\n");
    fflush(stdout);
    if (t->log) {
        fprintf(t->log, "%d,%d,%.6e", iter, nfev, fb);
        for (int i = 0; i < n; i++) fprintf(t->log, ",%.6e", exp(xb[i]));
        fprintf(t->log, "\n");
    }
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to, "usage: %s --est pf|ukf --out HEADER [--log CSV] [--max-fev N]\n"
                "bounds: --max-fev 1 .. %d (docs/tools.md)\n", argv0, BR_TOOL_MAX_FEV);
    return 2;
}

int main(int argc, char **argv)
{
    const char *est = NULL, *out = NULL, *log_path = NULL;
    long max_fev = 0;
    if (br_args_want_help(argc, argv)) {
        usage(argv[0], stdout);
        return 0;
    }
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[++i] : NULL;
        int bad = v == NULL;
        if (bad) fprintf(stderr, "%s: %s needs a value\n", TOOL, a);
        else if (strcmp(a, "--est") == 0) est = v;
        else if (strcmp(a, "--out") == 0) out = v;
        else if (strcmp(a, "--log") == 0) log_path = v;
        else if (strcmp(a, "--max-fev") == 0) bad = br_arg_long(TOOL, a, v, 1, BR_TOOL_MAX_FEV, &max_fev);
        else {
            fprintf(stderr, "%s: unknown option %s\n", TOOL, a);
            bad = 1;
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (!est || !out || (strcmp(est, "pf") != 0 && strcmp(est, "ukf") != 0)) return usage(argv[0], stderr);
    if (log_path && strcmp(log_path, out) == 0) {
        fprintf(stderr, "%s: --log and --out name the same file\n", TOOL);
        return 2;
    }
    /* the outputs: temporary files beside their names until the tuning succeeded (br_outfile.h) */
    br_outfile_t header_file, log_file = {0};
    if (br_outfile_open(&header_file, TOOL, out) != 0) return 1;
    if (log_path && br_outfile_open(&log_file, TOOL, log_path) != 0) {
        br_outfile_discard(&header_file);
        return 1;
    }
    tune_t t;
    t.pf = strcmp(est, "pf") == 0;
    t.base = br_circle_cfg_thesis(t.pf ? BR_CTRL_HINF_PF : BR_CTRL_HINF_UKF);
    /* start from the hand-tuned variances, not from the last tuning's result */
    t.base.pf = br_circle_pf_cfg_default((float)t.base.dt_s);
    t.base.ukf = br_circle_ukf_cfg_default((float)t.base.dt_s);
    t.log = log_file.f;
    const int n = n_params(&t);
    double x0[MAX_P], lo[MAX_P], hi[MAX_P];
    for (int i = 0; i < n; i++) {
        x0[i] = log((double)*param_ptr(&t.base, t.pf, i));
        lo[i] = x0[i] - 3.0 * log(10.0);
        hi[i] = x0[i] + 3.0 * log(10.0);
    }
    if (t.log) {
        fprintf(t.log, "iter,nfev,contour_rms_m");
        for (int i = 0; i < n; i++) fprintf(t.log, ",%s", param_name(t.pf, i));
        fprintf(t.log, "\n");
    }
    const double f0 = objective(&t, x0, n);
    printf("tuning %s: start contour RMS %.4e m (the hand-tuned default)\n", est, f0);
    if (t.log) {
        fprintf(t.log, "0,1,%.6e", f0);
        for (int i = 0; i < n; i++) fprintf(t.log, ",%.6e", exp(x0[i]));
        fprintf(t.log, "\n");
    }
    br_nm_cfg_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.n = n;
    cfg.init_step = 0.25; /* about 0.7 decade of each variance from the start */
    cfg.xatol = 0.01;     /* about 3 % of each variance */
    cfg.fatol = 1e-12;    /* 1 pm of contour RMS */
    cfg.max_fev = max_fev > 0 ? (int)max_fev : (t.pf ? 120 : 400);
    cfg.lo = lo;
    cfg.hi = hi;
    cfg.progress = progress;
    br_nm_result_t r;
    int ok = br_nm_minimize(&cfg, objective, &t, x0, &r) == 0 && isfinite(f0) && isfinite(r.f);
    for (int i = 0; ok && i < n; i++) ok = isfinite(r.x[i]);
    if (!ok) {
        fprintf(stderr, "%s: the tuning failed or gave a non-finite result; nothing written\n", TOOL);
        br_outfile_discard(&header_file);
        br_outfile_discard(&log_file);
        return 1;
    }
    printf("tuned %s: contour RMS %.4e m (start %.4e m, %.1f %% lower) after %d evaluations%s\n", est, r.f, f0,
           100.0 * (1.0 - r.f / f0), r.nfev, r.converged ? "" : " (budget reached)");
    FILE *h = header_file.f;
    const char *E = t.pf ? "PF" : "UKF";
    fprintf(h, "/* generated by sim/apps/br_tune_est.c (make tune) -- do not edit */\n");
    fprintf(h, "/* start: the hand-tuned variances of %s (its estimator section) */\n", BR_MACHINE_FILE);
    fprintf(h, "/* Nelder-Mead on the H-inf + %s circle: contour RMS %.4e m (start %.4e m), %d evaluations%s */\n",
            E, r.f, f0, r.nfev, r.converged ? "" : ", budget reached");
    fprintf(h, "#ifndef BR_%s_TUNED_H\n#define BR_%s_TUNED_H\n\n", E, E);
    for (int i = 0; i < n; i++) {
        fprintf(h, "#define BR_%s_TUNED_%s (%.9ef)\n", E, param_name(t.pf, i), (double)(float)exp(r.x[i]));
    }
    fprintf(h, "\n#endif\n");
    int rc = br_outfile_commit(&header_file, TOOL);
    if (rc == 0 && log_path) rc = br_outfile_commit(&log_file, TOOL);
    br_outfile_discard(&header_file);
    br_outfile_discard(&log_file);
    return rc == 0 ? 0 : 1;
}
