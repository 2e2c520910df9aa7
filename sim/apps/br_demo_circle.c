/* make demo: the thesis's X-Y circle experiment on the simulator, with each
 * controller of thesis section 5 and the true-friction limit.
 *
 * Usage: br_demo_circle --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N]
 * Writes DIR/trace_<name>.csv per controller, DIR/gp_hist_hinf_pf.csv (the PF's
 * g_p particle histogram per step) and DIR/summary.json; prints the table.
 * --gains, --dt and --nsub override the generated H-inf gains, the thesis
 * periods and the plant's substeps (design and accuracy studies). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "circle/br_circle.h"

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

static FILE *open_out(const char *dir, const char *name)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) fprintf(stderr, "br_demo_circle: cannot write %s: %s\n", path, strerror(errno));
    return f;
}

int main(int argc, char **argv)
{
    const char *out = NULL, *only = NULL;
    int have_gains = 0, nsub = 0;
    float K[3];
    double dt = 0.0;
    for (int i = 1; i < argc; i++) {
        int ok = i + 1 < argc;
        if (ok && strcmp(argv[i], "--out") == 0) {
            out = argv[++i];
        } else if (ok && strcmp(argv[i], "--only") == 0) {
            only = argv[++i];
        } else if (ok && strcmp(argv[i], "--gains") == 0) {
            have_gains = sscanf(argv[++i], "%f,%f,%f", &K[0], &K[1], &K[2]) == 3;
            if (!have_gains) {
                fprintf(stderr, "br_demo_circle: --gains needs three comma-separated numbers\n");
                return 2;
            }
        } else if (ok && strcmp(argv[i], "--dt") == 0) {
            if (sscanf(argv[++i], "%lf", &dt) != 1 || !(dt > 0.0)) {
                fprintf(stderr, "br_demo_circle: --dt needs a positive number of seconds\n");
                return 2;
            }
        } else if (ok && strcmp(argv[i], "--nsub") == 0) {
            if (sscanf(argv[++i], "%d", &nsub) != 1 || nsub < 1) {
                fprintf(stderr, "br_demo_circle: --nsub needs a positive integer\n");
                return 2;
            }
        } else {
            out = NULL;
            break;
        }
    }
    if (out == NULL) {
        fprintf(stderr, "usage: %s --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N]\n", argv[0]);
        return 2;
    }
    if (mkdir(out, 0775) != 0 && errno != EEXIST) {
        fprintf(stderr, "br_demo_circle: cannot create %s: %s\n", out, strerror(errno));
        return 1;
    }
    FILE *js = open_out(out, "summary.json");
    if (!js) return 1;
    fprintf(js, "{\n  \"experiment\": {\"radius_m\": 1e-4, \"period_s\": 8, \"duration_s\": 8}");
    printf("X-Y circle, radius 1.0e-04 m, period 8 s, 8 s simulated\n");
    printf("%-14s %8s %16s %16s %16s %12s %12s\n", "controller", "dt [ms]", "contour RMS [m]", "max error [m]",
           "thesis RMS [m]", "/ H-inf only", "F err [N]");
    double rms_hinf = 0.0;
    int ran = 0;
    for (unsigned r = 0; r < N_ROWS; r++) {
        const char *name = br_circle_ctrl_name(rows[r].ctrl);
        if (only && strcmp(only, name) != 0) continue;
        br_circle_cfg_t cfg = br_circle_cfg_thesis(rows[r].ctrl);
        if (have_gains) memcpy(cfg.K, K, sizeof K);
        if (dt > 0.0) {
            cfg.dt_s = dt;
            cfg.pf.est.model.dt_s = (float)dt;
            cfg.ukf.est.model.dt_s = (float)dt;
        }
        if (nsub > 0) cfg.plant.n_sub = nsub;
        char fname[256];
        snprintf(fname, sizeof fname, "trace_%s.csv", name);
        sinks_t k = {open_out(out, fname), NULL};
        if (!k.trace) return 1;
        br_circle_csv_header(k.trace);
        if (rows[r].ctrl == BR_CTRL_HINF_PF) {
            k.hist = open_out(out, "gp_hist_hinf_pf.csv");
            if (!k.hist) return 1;
            fprintf(k.hist, "# g_p particle histogram per step: t,axis, then %d bins of %g N from 0 N\n",
                    BR_HIST_BINS, BR_HIST_W_N);
        }
        br_circle_result_t res;
        int rc = br_circle_run(&cfg, demo_sink, &k, &res);
        fclose(k.trace);
        if (k.hist) fclose(k.hist);
        if (rc != 0) return 1;
        if (rows[r].ctrl == BR_CTRL_HINF_ONLY) rms_hinf = res.contour_rms_m;
        char thesis_js[32] = "null", thesis[32] = "-", ratio[32] = "-";
        if (rows[r].thesis_rms_m > 0.0) {
            snprintf(thesis_js, sizeof thesis_js, "%.6e", rows[r].thesis_rms_m);
            snprintf(thesis, sizeof thesis, "%.3e", rows[r].thesis_rms_m);
        }
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
        ran++;
    }
    fprintf(js, "\n}\n");
    fclose(js);
    if (!ran) {
        fprintf(stderr, "br_demo_circle: no controller named %s\n", only);
        return 2;
    }
    printf("wrote %s/summary.json and the traces\n", out);
    return 0;
}
