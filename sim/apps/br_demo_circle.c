/* SPDX-License-Identifier: Apache-2.0 */
/* make demo: the thesis's X-Y circle experiment on the simulator, with each
 * controller of thesis section 5, the static friction feedforward and the
 * true-friction limit; first on the plant the estimators model exactly (the
 * reference machine), then on the realistic plant (br_circle_cfg_realistic:
 * parameters away from the model, drift and noise), then on the hardware-like
 * plant (br_circle_cfg_hardware_like: Maxwell-slip presliding, a friction
 * outside the estimators' model class).
 *
 * Usage: br_demo_circle --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N]
 *                       [--radius-m R] [--feed-mm-min F] [--dir cw|ccw|both]
 *                       [--hw-law slip|clamp] [--hw-c-mps C]
 * Writes DIR/trace_<name>.csv per controller, DIR/gp_hist_hinf_pf.csv (the PF's
 * g_p particle histogram per step), the same with the prefix real_ for the
 * realistic plant and hw_ for the hardware-like one, and DIR/summary.json (the
 * realistic plant's under "realistic", the hardware-like one's under
 * "hardware_like"); prints the tables. A run on the hardware-like plant that
 * the firmware stopped is printed and written as a fault (time, cause; its
 * figures null, br_run_report.h); on the two LuGre plants every run must go
 * to the end, or nothing is written.
 * --hw-law, --hw-c-mps: the hardware-like plant's Maxwell-slip law (default
 * the slip law) and its attraction rate C (default BR_CIRCLE_HW_C_MPS).
 * --radius-m, --feed-mm-min, --dir: the circle (br_circle_args.h; default the
 * thesis's, clockwise); --dir both runs every controller clockwise, then
 * counter-clockwise into trace_ccw_<name>.csv, trace_real_ccw_<name>.csv and
 * summary.json's "ccw" (top level and under "realistic"): the pair of the
 * ISO 230-4 bi-directional figures (docs/circle-test.md).
 * --gains, --dt and --nsub override the generated H-inf gains, the thesis
 * periods and the plant's substeps (design and accuracy studies), within the
 * bounds of br_tool_limits.h. Every option is checked before a file is
 * touched; the files are written beside their names and renamed once every
 * run succeeded (br_outfile.h): a failed run writes nothing. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "circle/br_circle.h"
#include "circle_args/br_circle_args.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_demo_circle"

/* --hw-c-mps bounds: from a relaxation far slower than the circle to the clamp's neighbourhood */
#define HW_C_MIN_MPS 1.0e-5
#define HW_C_MAX_MPS 10.0

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
    {BR_CTRL_HINF_FF, "H-inf + FF", 0.0},
    {BR_CTRL_HINF_QEC, "H-inf + QEC", 0.0},
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
            int b = (int)((double)pf->x[BR_X_GP][j] / BR_HIST_W_N);
            if (b >= 0 && b < BR_HIST_BINS) h[b]++;
        }
        fprintf(k->hist, "%.6f,%d", s->t_s, a);
        for (int b = 0; b < BR_HIST_BINS; b++) fprintf(k->hist, ",%d", h[b]);
        fprintf(k->hist, "\n");
    }
}

/* the outputs, as temporary files until every run succeeded (br_outfile.h) */
/* the plants: [0] the reference machine (the estimators' model), [1] the realistic one,
 * [2] the hardware-like one (Maxwell-slip presliding) */
#define N_PLANTS 3
#define PLANT_HW 2
static const char *const plant_prefix[N_PLANTS] = {"", "real_", "hw_"};
/* the directions of a run: [0] the one --dir names (files unprefixed), [1] with
 * --dir both the counter-clockwise one */
#define N_DIRS 2
static const char *const dir_prefix[N_DIRS] = {"", "ccw_"};

typedef struct {
    br_outfile_t summary, trace[N_PLANTS][N_DIRS][N_ROWS], hist[N_PLANTS][N_DIRS];
} outputs_t;

static void discard_all(outputs_t *o)
{
    br_outfile_discard(&o->summary);
    for (int pl = 0; pl < N_PLANTS; pl++)
        for (int d = 0; d < N_DIRS; d++) {
            br_outfile_discard(&o->hist[pl][d]);
            for (unsigned r = 0; r < N_ROWS; r++) br_outfile_discard(&o->trace[pl][d][r]);
        }
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

static int commit_all(outputs_t *o, const int selected[N_ROWS], int pf_selected, int n_dirs)
{
    int rc = 0;
    for (int pl = 0; pl < N_PLANTS; pl++)
        for (int d = 0; d < n_dirs; d++) {
            for (unsigned r = 0; r < N_ROWS; r++)
                if (selected[r] && rc == 0) rc = br_outfile_commit(&o->trace[pl][d][r], TOOL);
            if (pf_selected && rc == 0) rc = br_outfile_commit(&o->hist[pl][d], TOOL);
        }
    if (rc == 0) rc = br_outfile_commit(&o->summary, TOOL); /* last: its presence says the rest is there */
    return rc;
}

typedef struct {
    const char *out, *only;
    int have_gains;
    float K[3];
    double dt;
    long nsub;
    long pf_prop; /* -1: the machine's */
    double ahead; /* < 0: the machine's */
    double ukf_load; /* the UKF's external force's random walk, N^2/s (0: off; < 0: the machine's) */
    int ukf_mslip;   /* the UKF predicts with the hardware-like plant's element set */
    int pf_mslip;    /* the PF's particles carry the hardware-like plant's element set (every plant) */
    float ukf_qs[2]; /* factors on the UKF's z and g_p process noise (0: 1) */
    float pf_qs[2];  /* factors on the PF's z and g_p process noise (0: 1) */
    double pf_load;  /* the PF's shared external force's random walk, N^2/s (0: off; < 0: the machine's) */
    double pf_gp_tau; /* the PF's g_p along the Stribeck curve, time constant s (0: the machine's) */
    double pf_gate;   /* the PF's outlier gate, sigmas (0: the machine's) */
    br_circle_path_t path; /* the circle (default the thesis's) */
    int hw_clamp;          /* the hardware-like plant's clamp limit instead of the slip law */
    double hw_c_mps;       /* its slip law's C (<= 0: BR_CIRCLE_HW_C_MPS) */
    int ff_el;             /* the feedforward's elements: BR_CIRCLE_FF_EL_NONE, _OWN or _FIT */
    double pred_s;         /* the prediction's horizon, s (0: off) */
    int pred_anchor;       /* 1: the feedforward's elements, 2: the UKF's */
    int oracle_late;       /* the true friction one period late */
} opts_t;

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --out DIR [--only NAME] [--gains K0,K1,K2] [--dt S] [--nsub N] [--pf-proposal K]\n"
            "       [--ahead P] [--ukf-load Q_N2_PER_S] [--ukf-mslip] [--ukf-q-scale FZ,FG] [--pf-load Q_N2_PER_S]\n"
            "       [--pf-mslip] [--pf-q-scale FZ,FG] [--pf-gp-curve TAU_S] [--pf-gate SIGMA] [--radius-m R] [--feed-mm-min F] [--dir cw|ccw|both]\n"
            "       [--hw-law slip|clamp] [--hw-c-mps C] [--ff-el own|fit] [--pred S] [--pred-anchor ff|ukf]\n"
            "       [--oracle-late]\n" BR_ARGS_COMMON_USAGE
            "  --out DIR           where summary.json and the traces go\n"
            "  --only NAME         run one controller (hinf_only, hinf_ukf, hinf_pf, ...)\n"
            "  --gains K0,K1,K2    the H-inf gains instead of the generated ones\n"
            "  --dt S              control period\n"
            "  --nsub N            plant substeps per period\n"
            "  --pf-proposal K     the PF's proposal: 0 the prior (thesis), 1 optimal for theta, 2 with omega's\n"
            "                      noise held over the period (docs/modules/pf.md)\n"
            "  --ahead P           the estimators' compensation lead, periods past the delay\n"
            "                      (est.comp_ahead_periods, 0 .. %g; docs/modules/est.md)\n"
            "  --ukf-load Q        the UKF's external-force state, random walk Q N^2/s (0 .. 1e9, 0: off;\n"
            "                      default the machine file's; docs/modules/ukf.md)\n"
            "  --ukf-mslip         on the hardware-like plant, the UKF predicts with its Maxwell-slip\n"
            "                      elements (clamp form, docs/modules/ukf.md)\n"
            "  --ukf-q-scale FZ,FG the UKF's z and g_p process noise times FZ and FG (1e-6 .. 1e6)\n"
            "  --pf-load Q         the PF's shared external force, random walk Q N^2/s (0 .. 1e9, 0: off;\n"
            "                      default the machine file's; docs/modules/pf.md)\n"
            "  --pf-mslip          on every plant, the PF's particles carry the hardware-like plant's\n"
            "                      Maxwell-slip elements (clamp form, docs/modules/pf.md)\n"
            "  --pf-q-scale FZ,FG  the PF's z and g_p process noise times FZ and FG (1e-6 .. 1e6)\n"
            "  --pf-gp-curve TAU   the PF's g_p along the Stribeck curve, time constant TAU s (0 .. 100; docs/modules/pf.md)\n"
            "  --pf-gate SIGMA     the PF's outlier gate, sigmas (%g .. %g; a study, docs/presliding-plants.md)\n"
            BR_CIRCLE_USAGE("--dir cw|ccw|both  ") "                      (both: each controller both ways, the ISO 230-4 pair; --direction the same)\n"
            "  --hw-law slip|clamp the hardware-like plant's Maxwell-slip law (default slip, docs/demo.md)\n"
            "  --hw-c-mps C        its slip law's attraction rate C, m/s (default %g, %g .. %g)\n"
            "  --ff-el own|fit     the feedforward with Maxwell-slip elements: the plant's own (a LuGre plant:\n"
            "                      the fit) or four fitted to its initial stiffness and Fs (docs/modules/ff-pred.md)\n"
            "  --pred S            the compensation that predicts over S s (0 .. %g; needs --ff-el): the UKF's,\n"
            "                      the PF's, the oracle's and the feedforward's plus the elements' change\n"
            "  --pred-anchor ff|ukf the prediction's elements: the feedforward's (default) or the UKF's own\n"
            "                      (with --ukf-mslip; then on the hardware-like plant only)\n"
            "  --oracle-late       the true friction one period late instead of at t_k\n"
            "bounds: --dt %g .. %g s, --nsub 1 .. %d, |gain| <= %g, --radius-m %g .. %g m,\n"
            "        --feed-mm-min %g .. %g, a revolution %g .. %g s (docs/tools.md)\n",
            argv0, argv0, (double)BR_EST_AHEAD_MAX_PERIODS, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA,
            BR_CIRCLE_HW_C_MPS, HW_C_MIN_MPS, HW_C_MAX_MPS,
            (double)BR_FF_PRED_MAX_S,
            BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, BR_TOOL_NSUB_MAX,
            BR_TOOL_GAIN_MAX, BR_TOOL_RADIUS_MIN_M, BR_TOOL_RADIUS_MAX_M, BR_TOOL_FEED_MIN_MM_MIN,
            BR_TOOL_FEED_MAX_MM_MIN, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S);
    return 2;
}

/* --ukf-q-scale / --pf-q-scale FZ,FG: two factors in [1e-6, 1e6] */
static int parse_q_scale(const char *opt, const char *val, float qs[2])
{
    int used = 0;
    const int bad = sscanf(val, "%f,%f%n", &qs[0], &qs[1], &used) != 2 || val[used] != '\0' ||
                    !(qs[0] >= 1e-6f && qs[0] <= 1e6f && qs[1] >= 1e-6f && qs[1] <= 1e6f);
    if (bad) fprintf(stderr, "%s: %s %s: two comma-separated factors in [1e-6, 1e6]\n", TOOL, opt, val);
    return bad;
}

static int parse_gains(const char *val, float K[3])
{
    int used = 0;
    if (sscanf(val, "%f,%f,%f%n", &K[0], &K[1], &K[2], &used) != 3 || val[used] != '\0') return -1;
    for (int k = 0; k < 3; k++)
        if (!isfinite(K[k]) || fabsf(K[k]) > (float)BR_TOOL_GAIN_MAX) return -1;
    return 0;
}

/* every option checked: 0, 1 (--help or --version answered) or 2 (usage error, message printed) */
static int parse(int argc, char **argv, opts_t *o)
{
    static const struct option opts[] = {{"out", required_argument, NULL, 'o'},
                                         {"only", required_argument, NULL, 'y'},
                                         {"gains", required_argument, NULL, 'g'},
                                         {"dt", required_argument, NULL, 'd'},
                                         {"nsub", required_argument, NULL, 'n'},
                                         {"pf-proposal", required_argument, NULL, 'p'},
                                         {"ahead", required_argument, NULL, 'a'},
                                         {"ukf-load", required_argument, NULL, 'l'},
                                         {"ukf-mslip", no_argument, NULL, 'e'},
                                         {"ukf-q-scale", required_argument, NULL, 'q'},
                                         {"pf-load", required_argument, NULL, 'L'},
                                         {"pf-mslip", no_argument, NULL, 'M'},
                                         {"pf-q-scale", required_argument, NULL, 'Q'},
                                         {"pf-gp-curve", required_argument, NULL, 'G'},
                                         {"pf-gate", required_argument, NULL, 'T'},
                                         {"hw-law", required_argument, NULL, 'w'},
                                         {"hw-c-mps", required_argument, NULL, 'c'},
                                         {"ff-el", required_argument, NULL, 'E'},
                                         {"pred", required_argument, NULL, 'P'},
                                         {"pred-anchor", required_argument, NULL, 'A'},
                                         {"oracle-late", no_argument, NULL, 'O'},
                                         BR_CIRCLE_LONGOPTS BR_CIRCLE_LONGOPT_DIR{NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 1;
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        int bad = 0;
        switch (c) {
        case 'o': o->out = val; break;
        case 'y': o->only = val; break;
        case 'g':
            o->have_gains = 1;
            bad = parse_gains(val, o->K);
            if (bad) fprintf(stderr, "%s: --gains %s: three comma-separated numbers, |K| <= %g\n", TOOL, val,
                             BR_TOOL_GAIN_MAX);
            break;
        case 'd': bad = br_arg_double(TOOL, p.opt, val, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, &o->dt); break;
        case 'n': bad = br_arg_long(TOOL, p.opt, val, 1, BR_TOOL_NSUB_MAX, &o->nsub); break;
        case 'p': bad = br_arg_long(TOOL, p.opt, val, 0, (long)BR_PF_PROPOSAL_OPT_HELD, &o->pf_prop); break;
        case 'a': bad = br_arg_double(TOOL, p.opt, val, 0.0, (double)BR_EST_AHEAD_MAX_PERIODS, &o->ahead); break;
        case 'l': bad = br_arg_double(TOOL, p.opt, val, 0.0, 1.0e9, &o->ukf_load); break;
        case 'e': o->ukf_mslip = 1; break;
        case 'M': o->pf_mslip = 1; break;
        case 'q': bad = parse_q_scale(p.opt, val, o->ukf_qs); break;
        case 'Q': bad = parse_q_scale(p.opt, val, o->pf_qs); break;
        case 'L': bad = br_arg_double(TOOL, p.opt, val, 0.0, 1.0e9, &o->pf_load); break;
        case 'G': bad = br_arg_double(TOOL, p.opt, val, 0.0, 100.0, &o->pf_gp_tau); break;
        case 'T':
            bad = br_arg_double(TOOL, p.opt, val, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA, &o->pf_gate);
            break;
        case BR_CIRCLE_OPT: bad = br_circle_arg(TOOL, p.opt, val, 1, &o->path); break;
        case 'w':
            o->hw_clamp = strcmp(val, "clamp") == 0;
            bad = !o->hw_clamp && strcmp(val, "slip") != 0;
            if (bad) fprintf(stderr, "%s: --hw-law %s: slip or clamp\n", TOOL, val);
            break;
        case 'c': bad = br_arg_double(TOOL, p.opt, val, HW_C_MIN_MPS, HW_C_MAX_MPS, &o->hw_c_mps); break;
        case 'E':
            o->ff_el = strcmp(val, "own") == 0 ? BR_CIRCLE_FF_EL_OWN : strcmp(val, "fit") == 0 ? BR_CIRCLE_FF_EL_FIT : -1;
            bad = o->ff_el < 0;
            if (bad) fprintf(stderr, "%s: --ff-el %s: own or fit\n", TOOL, val);
            break;
        case 'P': bad = br_arg_double(TOOL, p.opt, val, 0.0, (double)BR_FF_PRED_MAX_S, &o->pred_s); break;
        case 'A':
            o->pred_anchor = strcmp(val, "ukf") == 0 ? 2 : strcmp(val, "ff") == 0 ? 1 : -1;
            bad = o->pred_anchor < 0;
            if (bad) fprintf(stderr, "%s: --pred-anchor %s: ff or ukf\n", TOOL, val);
            break;
        case 'O': o->oracle_late = 1; break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return 2;
    }
    if (!o->out) {
        fprintf(stderr, "%s: --out is required\n", TOOL);
        return 2;
    }
    if (o->pred_s > 0.0 && o->ff_el == BR_CIRCLE_FF_EL_NONE) {
        fprintf(stderr, "%s: --pred needs the feedforward's elements (--ff-el own|fit)\n", TOOL);
        return 2;
    }
    if (o->pred_anchor == 2 && !o->ukf_mslip) {
        fprintf(stderr, "%s: --pred-anchor ukf needs --ukf-mslip\n", TOOL);
        return 2;
    }
    const br_circle_cfg_t thesis = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    if (br_circle_path_check(TOOL, &o->path, &thesis) != 0) return 2;
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

/* JSON numbers of the experiment: the shortest text that reads back as v, in
 * exponent form ("1e-4", the thesis radius as summary.json always wrote it)
 * or in %g form ("8") */
static void json_exp(char *buf, size_t n, double v)
{
    char t[40];
    for (int p = 0; p <= 16; p++) {
        snprintf(t, sizeof t, "%.*e", p, v);
        if (strtod(t, NULL) == v) break;
    }
    char *e = strchr(t, 'e');
    const long ex = strtol(e + 1, NULL, 10);
    *e = '\0';
    snprintf(buf, n, "%se%ld", t, ex);
}

static void json_g(char *buf, size_t n, double v)
{
    for (int p = 1; p <= 17; p++) {
        snprintf(buf, n, "%.*g", p, v);
        if (strtod(buf, NULL) == v) return;
    }
}

/* the configuration of one run on plant pl */
static br_circle_cfg_t plant_cfg(int pl, br_circle_ctrl_t ctrl, const opts_t *o)
{
    br_circle_cfg_t c = (pl == 0) ? br_circle_cfg_thesis(ctrl)
                        : (pl == 1) ? br_circle_cfg_realistic(ctrl) : br_circle_cfg_hardware_like(ctrl);
    /* the PF's particles with the hardware-like element set (every plant) */
    br_circle_use_pf_mslip(&c, o->pf_mslip);
    if (pl == PLANT_HW) {
        if (o->hw_clamp) c.plant.gms.clamp = 1;
        if (o->hw_c_mps > 0.0) c.plant.gms.C_mps = o->hw_c_mps;
        /* the UKF's model with the plant's own element set (this plant only) */
        br_circle_use_ukf_mslip(&c, o->ukf_mslip);
    }
    /* the feedforward's elements (from the plant's presliding) and the prediction; the
     * UKF anchor only where the UKF has the elements */
    br_circle_use_ff_el(&c, o->ff_el);
    if (o->pred_anchor != 2 || pl == PLANT_HW) br_circle_use_pred(&c, o->pred_s, o->pred_anchor);
    c.oracle_late = o->oracle_late;
    return c;
}

/* the hardware-like plant's header line and its summary.json "plant" object */
static void hw_describe(FILE *js, const opts_t *o)
{
    const br_circle_cfg_t c = plant_cfg(PLANT_HW, BR_CTRL_HINF_ONLY, o);
    const br_gms_cfg_t *g = &c.plant.gms;
    const double pre = br_gms_presliding_m(g, c.plant.Fs_N);
    double k0 = 0.0;
    for (int i = 0; i < g->n; i++) k0 += g->k_Npm[i];
    char law[48];
    if (g->clamp) snprintf(law, sizeof law, "the clamp limit");
    else snprintf(law, sizeof law, "the slip law, C %g m/s", g->C_mps);
    printf("\nhardware-like plant (docs/demo.md): the reference machine with Maxwell-slip presliding instead of "
           "its LuGre: %d elements, %s,\nbreakaway at Fs", g->n, law);
    for (int i = 0; i < g->n; i++) printf(" %.3g", 1e6 * g->alpha[i] * c.plant.Fs_N / g->k_Npm[i]);
    printf(" um, initial stiffness %.3g N/m, presliding %.3g um; the estimators' models stay LuGre\n", k0, 1e6 * pre);
    fprintf(js, ",\n  \"hardware_like\": {\n    \"plant\": {\"friction\": \"maxwell_slip\", \"law\": \"%s\", ",
            g->clamp ? "clamp" : "slip");
    if (g->clamp) fprintf(js, "\"C_mps\": null");
    else fprintf(js, "\"C_mps\": %.6g", g->C_mps);
    fprintf(js, ", \"delta\": %.6g, \"initial_stiffness_Npm\": %.6g, \"presliding_m\": %.6g, \"elements\": [",
            g->delta, k0, pre);
    for (int i = 0; i < g->n; i++)
        fprintf(js, "%s{\"breakaway_m\": %.6g, \"share\": %.6g, \"k_Npm\": %.6g, \"sigma1_Nspm\": %.6g}",
                i ? ", " : "", g->alpha[i] * c.plant.Fs_N / g->k_Npm[i], g->alpha[i], g->k_Npm[i],
                g->sigma1_Nspm[i]);
    fprintf(js, "]}");
}

int main(int argc, char **argv)
{
    opts_t opt = {NULL, NULL, 0, {0.0f, 0.0f, 0.0f}, 0.0, 0, -1, -1.0, -1.0, 0, 0, {0.0f, 0.0f}, {0.0f, 0.0f}, -1.0, 0.0, 0.0,
                  BR_CIRCLE_PATH_DEFAULT, 0, 0.0, BR_CIRCLE_FF_EL_NONE, 0.0, 1, 0};
    const int p = parse(argc, argv, &opt);
    if (p == 1) return 0; /* --help or --version answered */
    if (p != 0) return usage(argv[0], stderr);
    const char *out = opt.out;
    if (mkdir(out, 0775) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: cannot create %s: %s\n", TOOL, out, strerror(errno));
        return 1;
    }
    /* the directions run: the one --dir names, or clockwise then counter-clockwise */
    const int n_dirs = opt.path.dir == BR_CIRCLE_DIR_BOTH ? 2 : 1;
    const int ccw_of[N_DIRS] = {opt.path.dir == BR_CIRCLE_DIR_CCW, 1};
    int selected[N_ROWS] = {0}, pf_selected = 0;
    static outputs_t o; /* zeroed: nothing open */
    int rc = open_in(&o.summary, out, "summary.json");
    for (int pl = 0; pl < N_PLANTS; pl++) {
        for (int d = 0; d < n_dirs; d++) {
            for (unsigned r = 0; r < N_ROWS && rc == 0; r++) {
                const char *name = br_circle_ctrl_name(rows[r].ctrl);
                selected[r] = !opt.only || strcmp(opt.only, name) == 0;
                if (!selected[r]) continue;
                char fname[256];
                snprintf(fname, sizeof fname, "trace_%s%s%s.csv", plant_prefix[pl], dir_prefix[d], name);
                rc = open_in(&o.trace[pl][d][r], out, fname);
                if (rc == 0 && rows[r].ctrl == BR_CTRL_HINF_PF) {
                    pf_selected = 1;
                    snprintf(fname, sizeof fname, "gp_hist_%s%shinf_pf.csv", plant_prefix[pl], dir_prefix[d]);
                    rc = open_in(&o.hist[pl][d], out, fname);
                }
            }
        }
    }
    if (rc != 0) {
        discard_all(&o);
        return 1;
    }
    FILE *js = o.summary.f;
    br_circle_cfg_t ex = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    br_circle_use_path(&ex, opt.path.radius_m, opt.path.feed_mps, ccw_of[0]);
    char jr[48], jp[48], jd[48], jf[48], pr[48];
    json_exp(jr, sizeof jr, ex.radius_m);
    json_g(jp, sizeof jp, ex.period_s);
    json_g(jd, sizeof jd, ex.duration_s);
    json_g(jf, sizeof jf, br_circle_feed_mps(&ex) * 60000.0);
    for (int k = 1; k <= 6; k++) { /* the radius as printed: 1.0e-04 for the thesis's */
        snprintf(pr, sizeof pr, "%.*e", k, ex.radius_m);
        if (strtod(pr, NULL) == ex.radius_m) break;
    }
    const char *dir_name[2] = {"cw", "ccw"};
    fprintf(js, "{\n  \"experiment\": {\"radius_m\": %s, \"period_s\": %s, \"duration_s\": %s", jr, jp, jd);
    fprintf(js, ", \"feed_mm_min\": %s, \"direction\": \"%s\", \"directions\": [\"%s\"%s]}", jf,
            dir_name[ccw_of[0]], dir_name[ccw_of[0]], n_dirs == 2 ? ", \"ccw\"" : "");
    printf("X-Y circle, radius %s m, period %g s, %g s simulated\n", pr, ex.period_s, ex.duration_s);
    printf("%s, feed %.4g mm/min%s\n", ccw_of[0] ? "counter-clockwise" : "clockwise (the thesis's)",
           br_circle_feed_mps(&ex) * 60000.0, n_dirs == 2 ? "; then each counter-clockwise (--dir both)" : "");
    for (int pl = 0; pl < N_PLANTS; pl++) {
        if (pl == 0) {
            printf("plant = the estimators' and the feedforward's model (the reference machine's numbers):"
                   " the best case, docs/demo.md\n");
        } else if (pl == PLANT_HW) {
            hw_describe(js, &opt);
        } else {
            const br_circle_cfg_t rc0 = br_circle_cfg_realistic(BR_CTRL_HINF_ONLY);
            const br_plant_cfg_t *rp = &rc0.plant;
            printf("\nrealistic plant (docs/demo.md): the models stay the reference machine's; the plant has "
                   "sigma0 x0.6, sigma1 x1.5, Fc x1.12, Fs x0.90, vs x1.8, sigma2 x1.15, mass x1.05,\n"
                   "friction drift %+.0f %% over the run, force noise %.2g N per period, encoder one count off "
                   "with probability %.0e\n",
                   100.0 * rc0.real.drift_frac, rc0.real.force_noise_N, rc0.real.enc_noise_p);
            fprintf(js,
                    ",\n  \"realistic\": {\n    \"plant\": {\"sigma0_Npm\": %.6g, \"sigma1_Nspm\": %.6g, "
                    "\"Fc_N\": %.6g, \"Fs_N\": %.6g, \"vs_mps\": %.6g, \"sigma2_Nspm\": %.6g, \"J_kgm2\": %.6g, "
                    "\"M_kg\": %.6g, \"drift_frac\": %.6g, \"force_noise_N\": %.6g, \"enc_noise_p\": %.6g, "
                    "\"seed\": %llu}",
                    rp->sigma0_Npm, rp->sigma1_Nspm, rp->Fc_N, rp->Fs_N, rp->vs_mps, rp->sigma2_Nspm, rp->J_kgm2,
                    rp->M_kg, rc0.real.drift_frac, rc0.real.force_noise_N, rc0.real.enc_noise_p, rc0.real.seed);
        }
        for (int d = 0; d < n_dirs; d++) {
            /* the second direction's runs: an object "ccw" beside the first's */
            const char *ind = d == 0 ? (pl == 0 ? "  " : "    ") : (pl == 0 ? "    " : "      ");
            const char *sep = ",";
            if (d == 1) {
                printf("counter-clockwise (--dir both):\n");
                fprintf(js, ",\n%s\"ccw\": {", pl == 0 ? "  " : "    ");
                sep = "";
            }
            printf("%-14s %8s %16s %16s %16s %12s %12s\n", "controller", "dt [ms]", "contour RMS [m]",
                   "max error [m]", "thesis RMS [m]", "/ H-inf only", "F err [N]");
            double rms_hinf = 0.0;
            for (unsigned r = 0; r < N_ROWS; r++) {
                if (!selected[r]) continue;
                const char *name = br_circle_ctrl_name(rows[r].ctrl);
                br_circle_cfg_t cfg = plant_cfg(pl, rows[r].ctrl, &opt);
                br_circle_use_path(&cfg, opt.path.radius_m, opt.path.feed_mps, ccw_of[d]);
                if (opt.have_gains) memcpy(cfg.K, opt.K, sizeof opt.K);
                if (opt.dt > 0.0) {
                    cfg.dt_s = opt.dt;
                    cfg.pf.est.model.dt_s = (float)opt.dt;
                    cfg.ukf.est.model.dt_s = (float)opt.dt;
                }
                if (opt.nsub > 0) cfg.plant.n_sub = (int)opt.nsub;
                if (opt.pf_prop >= 0) cfg.pf.proposal = (uint32_t)opt.pf_prop;
                br_circle_use_ahead(&cfg, opt.ahead);
                br_circle_use_ukf_load(&cfg, opt.ukf_load);
                if (opt.pf_qs[0] > 0.0f) {
                    cfg.pf.est.q_var[BR_X_Z] *= opt.pf_qs[0];
                    cfg.pf.est.q_var[BR_X_GP] *= opt.pf_qs[1];
                }
                if (opt.ukf_qs[0] > 0.0f) {
                    cfg.ukf.est.q_var[BR_X_Z] *= opt.ukf_qs[0];
                    cfg.ukf.est.q_var[BR_X_GP] *= opt.ukf_qs[1];
                }
                br_circle_use_pf_load(&cfg, opt.pf_load);
                br_circle_use_pf_gp_curve(&cfg, opt.pf_gp_tau);
                br_circle_use_pf_gate(&cfg, opt.pf_gate);
                sinks_t k = {o.trace[pl][d][r].f, rows[r].ctrl == BR_CTRL_HINF_PF ? o.hist[pl][d].f : NULL};
                br_circle_csv_header(k.trace);
                if (k.hist)
                    fprintf(k.hist, "# g_p particle histogram per step: t,axis, then %d bins of %g N from 0 N\n",
                            BR_HIST_BINS, BR_HIST_W_N);
                br_circle_result_t res;
                if (br_circle_run(&cfg, demo_sink, &k, &res) < 0) {
                    fprintf(stderr, "%s: run %s failed; nothing written\n", TOOL, name);
                    discard_all(&o);
                    return 1;
                }
                if (!finite_result(&res)) {
                    fprintf(stderr, "%s: run %s gave a non-finite result; nothing written\n", TOOL, name);
                    discard_all(&o);
                    return 1;
                }
                char thesis_js[32] = "null", thesis[32] = "-", ratio[32] = "-";
                if (rows[r].thesis_rms_m > 0.0) {
                    snprintf(thesis_js, sizeof thesis_js, "%.6e", rows[r].thesis_rms_m);
                    snprintf(thesis, sizeof thesis, "%.3e", rows[r].thesis_rms_m);
                }
                char fname[256];
                snprintf(fname, sizeof fname, "trace_%s%s%s.csv", plant_prefix[pl], dir_prefix[d], name);
                if (pl == PLANT_HW || opt.pf_mslip || opt.ff_el != BR_CIRCLE_FF_EL_NONE || opt.oracle_late) {
                    /* a plant outside the estimators' model class (or, with --pf-mslip, a model
                     * outside the plant's; with --ff-el, --pred or --oracle-late a compensation
                     * never checked to go round): a run may stop, and is then a fault with its time and
                     * cause, never a figure (br_run_report.h) */
                    const br_run_report_t rep = {res.contour_rms_m, res.max_err_m, res.fault_status,
                                                 res.fault_cause, res.fault_t_s};
                    fprintf(js, "%s\n%s\"%s\": {\"dt_s\": %.6g, ", sep, ind, name, cfg.dt_s);
                    br_run_json(js, "contour_rms_m", "max_err_m", &rep);
                    if (res.fault_status != 0) {
                        fprintf(js, ", \"thesis_contour_rms_m\": %s, \"trace\": \"%s\"}", thesis_js, fname);
                        sep = ",";
                        printf("%-14s %8.1f   FAULT at %.4f s (%s, status %d): no result\n", rows[r].label,
                               cfg.dt_s * 1e3, res.fault_t_s, br_run_fault_name(res.fault_cause), res.fault_status);
                        fflush(stdout);
                        continue;
                    }
                    fprintf(js,
                            ", \"thesis_contour_rms_m\": %s, \"fhat_rms_err_N\": %.6e, \"saturated_steps\": %d, "
                            "\"outlier_steps\": %d, \"trace\": \"%s\"}",
                            thesis_js, res.fhat_rms_err_N, res.saturated_steps, res.outlier_steps, fname);
                } else if (res.fault_status != 0) {
                    /* the LuGre plants' runs go to the end: a faulted run is no result (docs/tools.md) */
                    fprintf(stderr, "%s: run %s faulted at %.4f s (%s, status %d): no result; nothing written\n",
                            TOOL, name, res.fault_t_s, br_run_fault_name(res.fault_cause), res.fault_status);
                    discard_all(&o);
                    return 1;
                } else {
                    fprintf(js,
                            "%s\n%s\"%s\": {\"dt_s\": %.6g, \"contour_rms_m\": %.6e, \"max_err_m\": %.6e, "
                            "\"thesis_contour_rms_m\": %s, \"fhat_rms_err_N\": %.6e, \"saturated_steps\": %d, "
                            "\"outlier_steps\": %d, \"trace\": \"%s\"}",
                            sep, ind, name, cfg.dt_s, res.contour_rms_m, res.max_err_m, thesis_js,
                            res.fhat_rms_err_N, res.saturated_steps, res.outlier_steps, fname);
                }
                if (rows[r].ctrl == BR_CTRL_HINF_ONLY) rms_hinf = res.contour_rms_m;
                sep = ",";
                if (rms_hinf > 0.0) snprintf(ratio, sizeof ratio, "%.3f", res.contour_rms_m / rms_hinf);
                printf("%-14s %8.1f %16.3e %16.3e %16s %12s %12.3f\n", rows[r].label, cfg.dt_s * 1e3,
                       res.contour_rms_m, res.max_err_m, thesis, ratio, res.fhat_rms_err_N);
                fflush(stdout);
            }
            if (d == 1) fprintf(js, "\n%s}", pl == 0 ? "  " : "    ");
        }
        if (pl > 0) fprintf(js, "\n  }");
    }
    fprintf(js, "\n}\n");
    if (commit_all(&o, selected, pf_selected, n_dirs) != 0) {
        discard_all(&o);
        return 1;
    }
    printf("wrote %s/summary.json and the traces\n", out);
    return 0;
}
