/* SPDX-License-Identifier: Apache-2.0 */
/* br_pil_tune: the thesis's noise tuning from experiments only, on the target
 * (docs/link.md, "Tuning on the target"; issue 32 item 6). Nelder-Mead
 * (sim/lib/nm, br_tune_est's search space and settings: tune_space) over the
 * log of the estimator's noise variances, each evaluation a run of the image
 * in the loop (pil_loop): the variances written over the link while the axis
 * is disarmed, the arm, a segment of the thesis circle, the cost measured as
 * a user would on a real axis (the image's encoder counts against the
 * commanded circle: br_pil_meas_t), the disarm and the fault reset. The image
 * is built once; its QEMUs stay up for the whole tuning.
 *
 * Usage: br_pil_tune --image ELF [--est ukf|pf] [--max-fev N] [--duration S]
 *                    [--circle] [--out DIR] [--set NAME=VALUE] [--sim]
 *                    [--qemu PATH] [--timeout S] [--work DIR]
 * Evaluation 0 is the shipped tuning (the image's own br_<est>_tuned.h, no
 * write); the search starts from the machine file's hand-tuned variances,
 * as br_tune_est's does. A run the firmware stopped is a penalised
 * evaluation (BR_TUNE_GUARD_PENALTY_M x (1 + the share of the segment lost)),
 * printed as a FAULT, never a figure; so is a write the image refused.
 * --circle runs the shipped and the best setting on the whole circle at the
 * end. --sim runs every evaluation on the host simulator instead (the same
 * figures bit for bit when the image in the loop is the simulator's: the
 * check of the harness). --set writes a further parameter (by its link name,
 * bristle_gen/link/br_link_params.h) before every evaluation. Writes into
 * DIR (made if missing; its parent must exist): evals.csv (one row per
 * evaluation) and summary.md, renamed into place only when the tuning
 * succeeded (br_outfile.h; a search without a complete evaluation writes
 * nothing). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bristle/br_status.h"
#include "bristle_gen/link/br_link_params.h"
#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "nm/br_nm.h"
#include "pil_args/br_pil_args.h"
#include "pil_loop/br_pil_loop.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"
#include "tune_space/br_tune_space.h"

#define TOOL "br_pil_tune"
/* the default segment: the circle's first 0.5 s (docs/link.md, "Tuning on the target", says why) */
#define SEGMENT_S 0.5
#define MAX_SET 2

typedef struct {
    const char *image, *est, *out;
    double duration_s;
    br_pil_qemu_t q;
    long max_fev;
    int circle, sim;
    br_pil_param_t set[MAX_SET];
    int n_set;
} opts_t;

/* one evaluation's outcome */
typedef struct {
    double f;           /* the objective: measured contour RMS x (1 + outlier steps), or the penalty */
    br_pil_run_t run;
    int refused;        /* a parameter write was refused or not answered */
    unsigned long hash; /* FNV-1a of both axes' duty sequences: the trajectory's fingerprint */
} eval_t;

typedef struct {
    opts_t o;
    int pf;
    br_pil_loop_t L;
    br_circle_cfg_t seg;   /* the segment on the thesis circle, the image's filter */
    float *duty[2];        /* per period, for the fingerprint */
    long n_alloc;
    FILE *csv;
    int nfev, n_fault, dead;
    int best_eval;
    double best_f, best_meas_m, best_x[BR_TUNE_MAX_P];
} tune_t;

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --image ELF [--est ukf|pf] [--max-fev N] [--duration S] [--circle] [--out DIR]\n"
            "          [--set NAME=VALUE] [--sim] [--qemu PATH] [--timeout S] [--work DIR]\n" BR_ARGS_COMMON_USAGE
            "  --image     the image in the loop (build/cm7-release/target/mps2/br_pil_mps2.elf)\n"
            "  --est       the estimator whose noise variances are tuned (default ukf)\n"
            "  --max-fev   the search's evaluation budget, n + 1 .. %d (default 60)\n"
            "  --duration  the segment of the circle each evaluation runs, s (default %g)\n"
            "  --circle    at the end, the shipped and the best setting on the whole circle\n"
            "  --out       folder for evals.csv and summary.md (default: none written)\n"
            "  --set       a further parameter written before every evaluation (name=value; at most %d)\n"
            "  --sim       each evaluation on the host simulator (the harness's check), not the image\n" BR_PIL_USAGE,
            argv0, argv0, BR_TOOL_MAX_FEV, SEGMENT_S, MAX_SET);
    return 2;
}

/* --set NAME=VALUE: the link's parameter of that name */
static int parse_set(const char *v, opts_t *o)
{
    static const struct {
        const char *name;
        uint16_t id;
    } names[] = {
#define BR_PIL_TUNE_NAME(n, pid, ...) {#n, pid},
        BR_LINK_PARAM_TABLE(BR_PIL_TUNE_NAME)
#undef BR_PIL_TUNE_NAME
    };
    const char *eq = strchr(v, '=');
    char *end = NULL;
    const double x = eq != NULL ? strtod(eq + 1, &end) : NAN;
    if (eq == NULL || end == eq + 1 || *end != '\0' || !isfinite(x) || o->n_set == MAX_SET) {
        fprintf(stderr, "%s: --set %s: NAME=VALUE with a finite value, at most %d\n", TOOL, v, MAX_SET);
        return 1;
    }
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (strlen(names[i].name) == (size_t)(eq - v) && strncasecmp(names[i].name, v, (size_t)(eq - v)) == 0) {
            o->set[o->n_set++] = (br_pil_param_t){names[i].id, (float)x};
            return 0;
        }
    }
    fprintf(stderr, "%s: --set %s: no such parameter (docs/link.md, \"Parameters\")\n", TOOL, v);
    return 1;
}

static int parse(int argc, char **argv, opts_t *o, int *done)
{
    static const struct option opts[] = {{"image", required_argument, NULL, 'i'},
                                         {"est", required_argument, NULL, 'e'},
                                         {"max-fev", required_argument, NULL, 'n'},
                                         {"duration", required_argument, NULL, 'd'},
                                         {"circle", no_argument, NULL, 'c'},
                                         {"out", required_argument, NULL, 'o'},
                                         {"set", required_argument, NULL, 's'},
                                         {"sim", no_argument, NULL, 'S'},
                                         BR_PIL_LONGOPTS{0, 0, 0, 0}};
    memset(o, 0, sizeof *o);
    o->est = "ukf";
    o->q = br_pil_qemu_default();
    o->duration_s = SEGMENT_S;
    o->max_fev = 60;
    br_args_t p;
    *done = br_args_start(&p, TOOL, argc, argv, usage);
    if (*done) return 0;
    const char *v;
    for (int c; (c = br_args_next(&p, opts, &v)) != BR_ARGS_END;) {
        int bad = 0;
        switch (c) {
        case 'i': o->image = v; break;
        case 'e':
            o->est = v;
            bad = strcmp(v, "ukf") != 0 && strcmp(v, "pf") != 0;
            if (bad) fprintf(stderr, "%s: --est %s: ukf or pf\n", TOOL, v);
            break;
        case 'n': bad = br_arg_long(TOOL, p.opt, v, 1, BR_TOOL_MAX_FEV, &o->max_fev); break;
        case 'd':
            bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, &o->duration_s);
            break;
        case 'c': o->circle = 1; break;
        case 'o': o->out = v; break;
        case 's': bad = parse_set(v, o); break;
        case 'S': o->sim = 1; break;
        case BR_PIL_OPT: bad = br_pil_arg(TOOL, p.opt, v, &o->q) < 0; break;
        default: return usage(argv[0], stderr);
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (o->image == NULL && !o->sim) {
        fprintf(stderr, "%s: --image is required\n", TOOL);
        return usage(argv[0], stderr);
    }
    /* Nelder-Mead's first simplex takes n + 1 evaluations (br_nm.c refuses less) */
    const int np = br_tune_n_params(strcmp(o->est, "pf") == 0);
    if (o->max_fev < np + 1) {
        fprintf(stderr, "%s: --max-fev %ld: the search needs at least %d evaluations for --est %s\n", TOOL, o->max_fev,
                np + 1, o->est);
        return 2;
    }
    return 0;
}

/* the link's writes of the variances e^x (br_tune_space's order), in the link's units, then --set's */
static int writes_of(const tune_t *t, const double *x, br_pil_param_t *w)
{
    static const uint16_t ukf_ids[] = {BR_LINK_PARAM_Q_THETA_RAD2, BR_LINK_PARAM_Q_OMEGA_RAD2PS2, BR_LINK_PARAM_Q_Z_M2,
                                       BR_LINK_PARAM_Q_GP_N2, BR_LINK_PARAM_R_COUNTS2};
    const uint16_t *ids = t->pf ? &ukf_ids[1] : ukf_ids; /* the PF's are the UKF's without theta */
    const int n = br_tune_n_params(t->pf);
    const double rpc = (double)(t->pf ? t->seg.pf.est.rad_per_count : t->seg.ukf.est.rad_per_count);
    for (int i = 0; i < n; i++) {
        /* R: the filter's rad^2 as the link's counts^2 */
        const double v = exp(x[i]) / (i == n - 1 ? rpc * rpc : 1.0);
        w[i] = (br_pil_param_t){ids[i], (float)v};
    }
    for (int j = 0; j < t->o.n_set; j++) w[n + j] = t->o.set[j];
    return n + t->o.n_set;
}

/* --sim: the writes as the image takes them (br_param.c: a value, R times rpc^2, the gate's term times
 * rpc, in float) into c;
 * 0, or -1 for a parameter this harness does not set on the simulator */
static int apply_writes(br_circle_cfg_t *c, int pf, const br_pil_param_t *w, int n)
{
    br_est_cfg_t *e = pf ? &c->pf.est : &c->ukf.est;
    const float rpc2 = e->rad_per_count * e->rad_per_count;
    for (int i = 0; i < n; i++) {
        switch (w[i].id) {
        case BR_LINK_PARAM_Q_THETA_RAD2: e->q_var[0] = w[i].value; break;
        case BR_LINK_PARAM_Q_OMEGA_RAD2PS2: e->q_var[1] = w[i].value; break;
        case BR_LINK_PARAM_Q_Z_M2: e->q_var[2] = w[i].value; break;
        case BR_LINK_PARAM_Q_GP_N2: e->q_var[3] = w[i].value; break;
        case BR_LINK_PARAM_R_COUNTS2: e->r_var_rad2 = w[i].value * rpc2; break;
        case BR_LINK_PARAM_OUTLIER_SIGMA: e->outlier_sigma = w[i].value; break;
        case BR_LINK_PARAM_OUTLIER_TRANSIENT_COUNTS: e->outlier_transient_rad = w[i].value * e->rad_per_count; break;
        default: fprintf(stderr, "%s: --sim sets no parameter 0x%04x\n", TOOL, (unsigned)w[i].id); return -1;
        }
    }
    return 0;
}

/* --sim's sink: the duties and the measured contour error, from the encoder's counts */
typedef struct {
    br_pil_meas_t meas;
    float *duty[2];
    long n;
} sim_acc_t;

static void sim_sink(void *user, const br_circle_sample_t *s)
{
    sim_acc_t *a = user;
    a->duty[0][a->n] = (float)s->duty[0];
    a->duty[1][a->n] = (float)s->duty[1];
    a->n++;
    br_pil_meas_add(&a->meas, s->counts[0], s->counts[1]);
}

static unsigned long fingerprint(float *const duty[2], long n)
{
    unsigned long h = 2166136261ul;
    for (long k = 0; k < n; k++)
        for (int i = 0; i < 2; i++) {
            unsigned char b[sizeof(float)];
            memcpy(b, &duty[i][k], sizeof b);
            for (size_t j = 0; j < sizeof b; j++) h = ((h ^ b[j]) * 16777619ul) & 0xFFFFFFFFul;
        }
    return h;
}

/* one run of c with the writes w (n of them; none: the image's own setting); 0 or -1 (the loop is gone) */
static int run(tune_t *t, const br_circle_cfg_t *c, const br_pil_param_t *w, int n, eval_t *e)
{
    const long np = lround(c->duration_s / c->dt_s) + 1;
    if (np > t->n_alloc) {
        for (int i = 0; i < 2; i++) {
            free(t->duty[i]);
            t->duty[i] = calloc((size_t)np, sizeof(float));
            if (t->duty[i] == NULL) return -1;
        }
        t->n_alloc = np;
    }
    if (t->o.sim) {
        br_circle_cfg_t cs = *c;
        if (apply_writes(&cs, t->pf, w, n) != 0) return -1;
        sim_acc_t a = {{0}, {t->duty[0], t->duty[1]}, 0};
        br_pil_meas_init(&a.meas, c);
        if (br_circle_run(&cs, sim_sink, &a, &e->run.res) < 0) return -1;
        e->run.meas_rms_m = br_pil_meas_rms(&a.meas);
        e->run.meas_max_m = a.meas.emax;
        e->run.params_ok = 1;
        e->run.wall_s = 0.0;
    } else if (br_pil_loop_run(&t->L, c, w, n, t->duty, &e->run) != 0) {
        return -1;
    }
    const br_circle_result_t *r = &e->run.res;
    e->refused = !e->run.params_ok;
    e->hash = fingerprint(t->duty, r->fault_status != 0 ? r->n_samples : np);
    if (e->refused || r->fault_status != 0) {
        /* a stop counts 1 + the share of the run lost (br_tune_est's rule); a refusal as a stop at 0 s */
        const double lost = e->refused ? 1.0 : (c->duration_s - r->fault_t_s) / c->duration_s;
        e->f = BR_TUNE_GUARD_PENALTY_M * (1.0 + lost);
    } else {
        e->f = e->run.meas_rms_m * (1.0 + (double)r->outlier_steps);
    }
    return 0;
}

static void print_eval(FILE *f, const char *label, const eval_t *e)
{
    const br_circle_result_t *r = &e->run.res;
    if (e->refused) {
        fprintf(f, "%-8s REFUSED: a parameter write was refused or not answered: no result (objective %.4e)", label,
                e->f);
    } else if (r->fault_status != 0) {
        fprintf(f, "%-8s FAULT at %.4f s (%s, status %d): no result (objective %.4e)", label, r->fault_t_s,
                br_run_fault_name(r->fault_cause), r->fault_status, e->f);
    } else {
        fprintf(f, "%-8s measured contour RMS %.4e m, max %.4e m, outliers %d, objective %.4e", label,
                e->run.meas_rms_m, e->run.meas_max_m, r->outlier_steps, e->f);
    }
    fprintf(f, "  duty %08lx  wall %.1f s\n", e->hash, e->run.wall_s);
}

static void csv_row(tune_t *t, int k, const br_pil_param_t *w, int n, const eval_t *e)
{
    if (t->csv == NULL) return;
    const br_circle_result_t *r = &e->run.res;
    const int ok = !e->refused && r->fault_status == 0;
    fprintf(t->csv, "%d,%s", k, e->refused ? "refused" : r->fault_status != 0 ? br_run_fault_name(r->fault_cause) : "");
    for (int i = 0; i < br_tune_n_params(t->pf); i++) {
        if (n > 0) fprintf(t->csv, ",%.6e", (double)w[i].value);
        else fprintf(t->csv, ",");
    }
    if (ok) fprintf(t->csv, ",%.6e,%.6e,%d,%.6e", e->run.meas_rms_m, e->run.meas_max_m, r->outlier_steps,
                    r->contour_rms_m);
    else fprintf(t->csv, ",,,,");
    fprintf(t->csv, ",%.6e,%08lx,%.2f\n", e->f, e->hash, e->run.wall_s);
    fflush(t->csv);
}

static double objective(void *user, const double *x, int n)
{
    tune_t *t = user;
    (void)n;
    if (t->dead) return INFINITY;
    br_pil_param_t w[BR_TUNE_MAX_P + MAX_SET];
    const int nw = writes_of(t, x, w);
    eval_t e;
    if (run(t, &t->seg, w, nw, &e) != 0) {
        fprintf(stderr, "%s: evaluation %d: %s; the search stops\n", TOOL, t->nfev + 1,
                br_pil_loop_stopped() ? "stopped by a signal" : "the image did not answer");
        t->dead = 1;
        return INFINITY;
    }
    t->nfev++;
    char label[32];
    snprintf(label, sizeof label, "eval %d", t->nfev);
    printf("%s ", label);
    for (int i = 0; i < br_tune_n_params(t->pf); i++) printf(" %s=%.3g", br_tune_param_name(t->pf, i), exp(x[i]));
    printf("\n");
    print_eval(stdout, "", &e);
    fflush(stdout);
    csv_row(t, t->nfev, w, nw, &e);
    if (e.refused || e.run.res.fault_status != 0) {
        t->n_fault++;
    } else if (e.f < t->best_f) {
        t->best_f = e.f;
        t->best_eval = t->nfev;
        t->best_meas_m = e.run.meas_rms_m;
        memcpy(t->best_x, x, sizeof(double) * (size_t)br_tune_n_params(t->pf));
    }
    return e.f;
}

/* --circle: the whole circle with the writes w (n; none: the image's own setting) */
static int circle(tune_t *t, const char *label, const br_pil_param_t *w, int n, eval_t *e)
{
    const br_circle_cfg_t full = br_circle_cfg_thesis(t->pf ? BR_CTRL_HINF_PF : BR_CTRL_HINF_UKF);
    if (run(t, &full, w, n, e) != 0) return -1;
    printf("the whole circle (%.1f s), ", full.duration_s);
    print_eval(stdout, label, e);
    fflush(stdout);
    return 0;
}

/* the shipped setting against the best: on the segment (evaluation 0 and the best's), with --circle
 * on the whole circle too (cs: the shipped one's, run before any write) */
static int compare(tune_t *t, const eval_t *shipped, const eval_t *cs, FILE *md)
{
    const int n = br_tune_n_params(t->pf);
    br_pil_param_t w[BR_TUNE_MAX_P + MAX_SET];
    const int nw = writes_of(t, t->best_x, w);
    eval_t cb;
    const char *E = t->pf ? "PF" : "UKF";
    if (t->o.circle && circle(t, "best", w, nw, &cb) != 0) return -1;
    if (md == NULL) return 0;
    fprintf(md, "| H-inf + %s setting |", E);
    for (int i = 0; i < n; i++) fprintf(md, " %s%s |", br_tune_param_name(t->pf, i), i == n - 1 ? " [count^2]" : "");
    fprintf(md, " segment (%.3g s): objective |%s\n", t->seg.duration_s,
            t->o.circle ? " circle: measured contour RMS | circle: the plant's contour RMS |" : "");
    fprintf(md, "|---|");
    for (int i = 0; i < n + 1 + 2 * t->o.circle; i++) fprintf(md, "---|");
    fprintf(md, "\n");
    for (int row = 0; row < 2; row++) {
        br_circle_cfg_t c = t->seg;
        const char *best = t->o.sim ? "best of this search (--sim)" : "best on the target";
        fprintf(md, "| %s |", row == 0 ? "shipped (br_tune_est, the simulator)" : best);
        br_pil_param_t ws[BR_TUNE_MAX_P + MAX_SET];
        double xs[BR_TUNE_MAX_P];
        for (int i = 0; i < n; i++) xs[i] = log((double)*br_tune_param_ptr(&c, t->pf, i));
        (void)writes_of(t, row == 0 ? xs : t->best_x, ws); /* in the link's units: R in counts^2 */
        for (int i = 0; i < n; i++) fprintf(md, " %.3e |", (double)ws[i].value);
        if (row == 0 && (shipped->refused || shipped->run.res.fault_status != 0)) fprintf(md, " FAULT |");
        else fprintf(md, " %.4e m |", row == 0 ? shipped->f : t->best_f);
        if (t->o.circle) {
            const eval_t *e = row == 0 ? cs : &cb;
            if (e->refused || e->run.res.fault_status != 0) fprintf(md, " FAULT | FAULT |");
            else fprintf(md, " %.4e m | %.4e m |", e->run.meas_rms_m, e->run.res.contour_rms_m);
        }
        fprintf(md, "\n");
    }
    return 0;
}

int main(int argc, char **argv)
{
    static tune_t t;
    int done = 0;
    const int prc = parse(argc, argv, &t.o, &done);
    if (prc != 0 || done) return prc;
    if (!t.o.sim && access(t.o.image, R_OK) != 0) {
        fprintf(stderr, "%s: no image at %s (build the cm7-release preset)\n", TOOL, t.o.image);
        return 1;
    }
    t.pf = strcmp(t.o.est, "pf") == 0;
    /* the image's configuration: the circle's, the shipped (tuned) filter */
    t.seg = br_circle_cfg_thesis(t.pf ? BR_CTRL_HINF_PF : BR_CTRL_HINF_UKF);
    t.seg.duration_s = t.o.duration_s;
    /* the search's start and bounds: br_tune_est's (the hand-tuned variances, R's floor for the UKF) */
    br_circle_cfg_t start = t.seg;
    start.pf = br_circle_pf_cfg_default((float)start.dt_s);
    start.ukf = br_circle_ukf_cfg_default((float)start.dt_s);
    const int n = br_tune_n_params(t.pf);
    double x0[BR_TUNE_MAX_P], lo[BR_TUNE_MAX_P], hi[BR_TUNE_MAX_P];
    br_tune_space(&start, t.pf, !t.pf, x0, lo, hi);
    /* the outputs: temporary files beside their names, renamed when the tuning succeeded (br_outfile.h) */
    br_outfile_t csv_file = {0}, md_file = {0};
    FILE *md = NULL;
    if (t.o.out != NULL) {
        char p[1024];
        (void)mkdir(t.o.out, 0755); /* the folder itself; its parent must exist */
        snprintf(p, sizeof p, "%s/evals.csv", t.o.out);
        const int bad = br_outfile_open(&csv_file, TOOL, p);
        snprintf(p, sizeof p, "%s/summary.md", t.o.out);
        if (bad || br_outfile_open(&md_file, TOOL, p) != 0) {
            br_outfile_discard(&csv_file);
            return 1;
        }
        t.csv = csv_file.f;
        md = md_file.f;
        fprintf(t.csv, "eval,fault");
        for (int i = 0; i < n; i++) fprintf(t.csv, ",%s%s", br_tune_param_name(t.pf, i), i == n - 1 ? "_counts2" : "");
        fprintf(t.csv, ",meas_contour_rms_m,meas_max_m,outlier_steps,plant_contour_rms_m,objective,duty_fnv,wall_s\n");
    }
    int rc = 1;
    if (!t.o.sim && br_pil_loop_open(&t.L, t.o.q.qemu, t.o.image, t.o.est, t.o.q.work, t.o.q.timeout_s) != 0) goto out;
    printf("tuning %s on the %s: H-inf + %s, the circle's first %.3g s per evaluation\n", t.o.est,
           t.o.sim ? "host simulator (--sim)" : "image in the loop (QEMU mps2-an500, Cortex-M7)", t.pf ? "PF" : "UKF",
           t.seg.duration_s);
    eval_t shipped;
    t.best_f = INFINITY;
    if (run(&t, &t.seg, t.o.set, t.o.n_set, &shipped) != 0) goto out;
    printf("eval 0   shipped: the image's own br_%s_tuned.h, no variance written\n", t.o.est);
    print_eval(stdout, "", &shipped);
    csv_row(&t, 0, NULL, 0, &shipped);
    /* the shipped setting on the whole circle now: the image keeps the values last written (its
     * service's copy, applied at each arm), so after the search a run without writes would not be it */
    eval_t cs;
    if (t.o.circle && circle(&t, "shipped", t.o.set, t.o.n_set, &cs) != 0) goto out;
    br_nm_cfg_t cfg = br_tune_nm_cfg(n, lo, hi, (int)t.o.max_fev);
    br_nm_result_t r;
    if (br_nm_minimize(&cfg, objective, &t, x0, &r) != 0 || t.dead) goto out;
    printf("%d evaluations, %d of them faulted or refused%s\n", t.nfev, t.n_fault, r.converged ? ", converged" : " (budget reached)");
    if (!isfinite(t.best_f)) {
        printf("no setting ran to the end: no best\n");
        goto out;
    }
    printf("best: objective %.4e m (eval %d: measured contour RMS %.4e m) at", t.best_f, t.best_eval, t.best_meas_m);
    for (int i = 0; i < n; i++) printf(" %s=%.4g", br_tune_param_name(t.pf, i), exp(t.best_x[i]));
    printf("\n");
    if (shipped.refused || shipped.run.res.fault_status != 0) printf("shipped: FAULT, no result\n");
    else printf("shipped: objective %.4e m (best / shipped %.3f)\n", shipped.f, t.best_f / shipped.f);
    if (compare(&t, &shipped, &cs, md) != 0) goto out;
    rc = 0;
out:
    if (!t.o.sim) br_pil_loop_close(&t.L);
    /* evals.csv, then summary.md, only from a tuning that succeeded */
    if (rc == 0 && t.o.out != NULL &&
        (br_outfile_commit(&csv_file, TOOL) != 0 || br_outfile_commit(&md_file, TOOL) != 0))
        rc = 1;
    br_outfile_discard(&csv_file);
    br_outfile_discard(&md_file);
    free(t.duty[0]);
    free(t.duty[1]);
    return br_pil_loop_end(rc); /* killed by a signal: only now, the folders and outputs gone */
}
