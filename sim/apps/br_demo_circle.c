/* make demo: the thesis's X-Y circle experiment on the simulator, with each
 * controller of thesis section 5 and the true-friction limit.
 *
 * Usage: br_demo_circle --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N]
 * Writes DIR/trace_<name>.csv per controller, DIR/gp_hist_hinf_pf.csv (the PF's
 * g_p particle histogram per step) and DIR/summary.json; prints the table.
 * --gains, --dt and --nsub override the generated H-inf gains, the thesis
 * periods and the plant's substeps (design and accuracy studies), within the
 * bounds of br_tool_limits.h. Every option is checked before a file is
 * touched; the files are written beside their names and renamed once every
 * run succeeded (br_outfile.h): a failed run writes nothing. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "circle/br_circle.h"
#include "tools/br_args.h"
#include "tools/br_outfile.h"
#include "tools/br_tool_limits.h"

#define TOOL "br_demo_circle"

/* g_p histogram of the PF's particles: bins of BR_HIST_W_N from 0 N. */
#define BR_HIST_BINS 60
#define BR_HIST_W_N 0.5

typedef struct {
    br_circle_ctrl_t ctrl;
    const char *label;
    double thesis_rms_m; /* thesis section 5; 0 when the thesis has none */
} demo_row_t;

static const demo_row_t rows[] = {
    {BR_CTRL_HINF_ONLY, "H-inf only", 2.4e-6},
    {BR_CTRL_HINF_UKF, "H-inf + UKF", 1.3e-6},
    {BR_CTRL_HINF_PF, "H-inf + PF", 4.0e-7},
    {BR_CTRL_HINF_TRUE, "true friction", 0.0},
};
#define N_ROWS (sizeof rows / sizeof rows[0])

typedef struct {
    FILE *trace, *hist;
} sinks_t;

static void demo_sink(void *user, const br_circle_sample_t *s)
{
    sinks_t *k = user;
    br_circle_csv_sink(k->trace, s);
    if (!k->hist) return;
    for (int a = 0; a < 2; a++) {
        const br_pf_t *pf = s->pf[a];
        int h[BR_HIST_BINS] = {0};
        for (uint32_t j = 0; j < pf->cfg.n_particles; j++) {
            int b = (int)((double)pf->x[j][BR_X_GP] / BR_HIST_W_N);
            if (b >= 0 && b < BR_HIST_BINS) h[b]++;
        }
        fprintf(k->hist, "%.6f,%d", s->t_s, a);
        for (int b = 0; b < BR_HIST_BINS; b++) fprintf(k->hist, ",%d", h[b]);
        fprintf(k->hist, "\n");
    }
}

/* the outputs, as temporary files until every run succeeded (br_outfile.h) */
typedef struct {
    br_outfile_t summary, trace[N_ROWS], hist;
} outputs_t;

static void discard_all(outputs_t *o)
{
    br_outfile_discard(&o->summary);
    br_outfile_discard(&o->hist);
    for (unsigned r = 0; r < N_ROWS; r++) br_outfile_discard(&o->trace[r]);
}

static int open_in(br_outfile_t *f, const char *dir, const char *name)
{
    char path[BR_OUTFILE_PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) {
        fprintf(stderr, "%s: %s: path too long\n", TOOL, dir);
        return -1;
    }
    return br_outfile_open(f, TOOL, path);
}

static int commit_all(outputs_t *o, const int selected[N_ROWS], int pf_selected)
{
    int rc = 0;
    for (unsigned r = 0; r < N_ROWS; r++)
        if (selected[r] && rc == 0) rc = br_outfile_commit(&o->trace[r], TOOL);
    if (pf_selected && rc == 0) rc = br_outfile_commit(&o->hist, TOOL);
    if (rc == 0) rc = br_outfile_commit(&o->summary, TOOL); /* last: its presence says the rest is there */
    return rc;
}

typedef struct {
    const char *out, *only;
    int have_gains;
    float K[3];
    double dt;
    long nsub;
} opts_t;

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N]\n"
            "bounds: --dt %g .. %g s, --nsub 1 .. %d, |gain| <= %g (docs/tools.md)\n",
            argv0, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, BR_TOOL_NSUB_MAX, BR_TOOL_GAIN_MAX);
    return 2;
}

static int parse_gains(const char *val, float K[3])
{
    int used = 0;
    if (sscanf(val, "%f,%f,%f%n", &K[0], &K[1], &K[2], &used) != 3 || val[used] != '\0') return -1;
    for (int k = 0; k < 3; k++)
        if (!isfinite(K[k]) || fabsf(K[k]) > (float)BR_TOOL_GAIN_MAX) return -1;
    return 0;
}

/* every option checked: 0, 1 (--help) or 2 (usage error, message printed) */
static int parse(int argc, char **argv, opts_t *o)
{
    if (br_args_want_help(argc, argv)) return 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (i + 1 >= argc) {
            fprintf(stderr, "%s: %s needs a value\n", TOOL, a);
            return 2;
        }
        const char *val = argv[++i];
        int bad = 0;
        if (strcmp(a, "--out") == 0) o->out = val;
        else if (strcmp(a, "--only") == 0) o->only = val;
        else if (strcmp(a, "--gains") == 0) {
            o->have_gains = 1;
            bad = parse_gains(val, o->K);
            if (bad) fprintf(stderr, "%s: --gains %s: three comma-separated numbers, |K| <= %g\n", TOOL, val,
                             BR_TOOL_GAIN_MAX);
        } else if (strcmp(a, "--dt") == 0) bad = br_arg_double(TOOL, a, val, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, &o->dt);
        else if (strcmp(a, "--nsub") == 0) bad = br_arg_long(TOOL, a, val, 1, BR_TOOL_NSUB_MAX, &o->nsub);
        else {
            fprintf(stderr, "%s: unknown option %s\n", TOOL, a);
            bad = 1;
        }
        if (bad) return 2;
    }
    if (!o->out) {
        fprintf(stderr, "%s: --out is required\n", TOOL);
        return 2;
    }
    if (o->only) {
        unsigned r = 0;
        while (r < N_ROWS && strcmp(o->only, br_circle_ctrl_name(rows[r].ctrl)) != 0) r++;
        if (r == N_ROWS) {
            fprintf(stderr, "%s: no controller named %s\n", TOOL, o->only);
            return 2;
        }
    }
    return 0;
}

static int finite_result(const br_circle_result_t *r)
{
    return isfinite(r->contour_rms_m) && isfinite(r->max_err_m) && isfinite(r->fhat_rms_err_N);
}

int main(int argc, char **argv)
{
    opts_t opt = {NULL, NULL, 0, {0.0f, 0.0f, 0.0f}, 0.0, 0};
    const int p = parse(argc, argv, &opt);
    if (p == 1) {
        usage(argv[0], stdout);
        return 0;
    }
    if (p != 0) return usage(argv[0], stderr);
    const char *out = opt.out;
    if (mkdir(out, 0775) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: cannot create %s: %s\n", TOOL, out, strerror(errno));
        return 1;
    }
    int selected[N_ROWS] = {0}, pf_selected = 0;
    static outputs_t o; /* zeroed: nothing open */
    int rc = open_in(&o.summary, out, "summary.json");
    for (unsigned r = 0; r < N_ROWS && rc == 0; r++) {
        const char *name = br_circle_ctrl_name(rows[r].ctrl);
        selected[r] = !opt.only || strcmp(opt.only, name) == 0;
        if (!selected[r]) continue;
        char fname[256];
        snprintf(fname, sizeof fname, "trace_%s.csv", name);
        rc = open_in(&o.trace[r], out, fname);
        if (rc == 0 && rows[r].ctrl == BR_CTRL_HINF_PF) {
            pf_selected = 1;
            rc = open_in(&o.hist, out, "gp_hist_hinf_pf.csv");
        }
    }
    if (rc != 0) {
        discard_all(&o);
        return 1;
    }
    FILE *js = o.summary.f;
    fprintf(js, "{\n  \"experiment\": {\"radius_m\": 1e-4, \"period_s\": 8, \"duration_s\": 8}");
    printf("X-Y circle, radius 1.0e-04 m, period 8 s, 8 s simulated\n");
    printf("%-14s %8s %16s %16s %16s %12s %12s\n", "controller", "dt [ms]", "contour RMS [m]", "max error [m]",
           "thesis RMS [m]", "/ H-inf only", "F err [N]");
    double rms_hinf = 0.0;
    for (unsigned r = 0; r < N_ROWS; r++) {
        if (!selected[r]) continue;
        const char *name = br_circle_ctrl_name(rows[r].ctrl);
        br_circle_cfg_t cfg = br_circle_cfg_thesis(rows[r].ctrl);
        if (opt.have_gains) memcpy(cfg.K, opt.K, sizeof opt.K);
        if (opt.dt > 0.0) {
            cfg.dt_s = opt.dt;
            cfg.pf.est.model.dt_s = (float)opt.dt;
            cfg.ukf.est.model.dt_s = (float)opt.dt;
        }
        if (opt.nsub > 0) cfg.plant.n_sub = (int)opt.nsub;
        sinks_t k = {o.trace[r].f, rows[r].ctrl == BR_CTRL_HINF_PF ? o.hist.f : NULL};
        br_circle_csv_header(k.trace);
        if (k.hist)
            fprintf(k.hist, "# g_p particle histogram per step: t,axis, then %d bins of %g N from 0 N\n",
                    BR_HIST_BINS, BR_HIST_W_N);
        br_circle_result_t res;
        if (br_circle_run(&cfg, demo_sink, &k, &res) != 0) {
            fprintf(stderr, "%s: run %s failed; nothing written\n", TOOL, name);
            discard_all(&o);
            return 1;
        }
        if (!finite_result(&res)) {
            fprintf(stderr, "%s: run %s gave a non-finite result; nothing written\n", TOOL, name);
            discard_all(&o);
            return 1;
        }
        if (rows[r].ctrl == BR_CTRL_HINF_ONLY) rms_hinf = res.contour_rms_m;
        char thesis_js[32] = "null", thesis[32] = "-", ratio[32] = "-";
        if (rows[r].thesis_rms_m > 0.0) {
            snprintf(thesis_js, sizeof thesis_js, "%.6e", rows[r].thesis_rms_m);
            snprintf(thesis, sizeof thesis, "%.3e", rows[r].thesis_rms_m);
        }
        char fname[256];
        snprintf(fname, sizeof fname, "trace_%s.csv", name);
        fprintf(js,
                ",\n  \"%s\": {\"dt_s\": %.6g, \"contour_rms_m\": %.6e, \"max_err_m\": %.6e, "
                "\"thesis_contour_rms_m\": %s, \"fhat_rms_err_N\": %.6e, \"saturated_steps\": %d, "
                "\"outlier_steps\": %d, \"trace\": \"%s\"}",
                name, cfg.dt_s, res.contour_rms_m, res.max_err_m, thesis_js, res.fhat_rms_err_N, res.saturated_steps,
                res.outlier_steps, fname);
        if (rms_hinf > 0.0) snprintf(ratio, sizeof ratio, "%.3f", res.contour_rms_m / rms_hinf);
        printf("%-14s %8.1f %16.3e %16.3e %16s %12s %12.3f\n", rows[r].label, cfg.dt_s * 1e3, res.contour_rms_m,
               res.max_err_m, thesis, ratio, res.fhat_rms_err_N);
        fflush(stdout);
    }
    fprintf(js, "\n}\n");
    if (commit_all(&o, selected, pf_selected) != 0) {
        discard_all(&o);
        return 1;
    }
    printf("wrote %s/summary.json and the traces\n", out);
    return 0;
}
