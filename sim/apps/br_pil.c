/* SPDX-License-Identifier: Apache-2.0 */
/* br_pil: the image in the loop (docs/link.md, "The image in the loop"). The
 * thesis circle with each axis's application on QEMU's Cortex-M7
 * (target/mps2/pil_main.c, one QEMU per axis) and the double-precision plant
 * here, in lockstep, period by period (pil_loop/br_pil_loop.h): br_circle_run_remote runs the plant,
 * the reference and the figures, and for each axis and period sends the
 * encoder count (pil_tick, on the board's UART1) and applies the duty the
 * image answers (pil_out); the reference goes as timed setpoints on the link
 * (UART0), with the arm. Each QEMU's UARTs are FIFOs (-serial pipe:).
 *
 * The image starts disarmed; D setup periods queue the first D setpoints
 * (the plant at rest, not advanced), then the arm request goes with the
 * circle's first period (k = 0, tick D), so the image's first armed period
 * is the simulator's first: the application restarts at the arm as the
 * simulator's does right after init (br_app_arm).
 *
 * Usage: br_pil --image ELF [--est none|ukf|pf|all] [--duration S] [--compare]
 *                [--qemu PATH] [--timeout S] [--work DIR] [cause options]
 * --compare runs the simulator's circle (br_circle_run, the same
 * configuration) too and compares the duty sequences bit for bit; exit 1 on a
 * difference (the first one printed). Prints the demo's table; a run the
 * firmware stopped is printed as a fault, never a figure (br_run_report.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "circle/br_circle.h"
#include "cause_args/br_cause_args.h"
#include "pil_args/br_pil_args.h"
#include "pil_loop/br_pil_loop.h"
#include "tool/br_args.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_pil"

typedef struct {
    const char *image, *est;
    double duration_s;
    int compare;
    br_pil_qemu_t q;
    br_plant_cfg_t causes; /* the cause options (br_cause_args.h) on the reference machine */
} opts_t;

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --image ELF [--est none|ukf|pf|all] [--duration S] [--compare] [--qemu PATH]\n"
            "          [--timeout S] [--work DIR] [cause options]\n" BR_ARGS_COMMON_USAGE
            "  --image     the image in the loop (build/cm7-release/target/mps2/br_pil_mps2.elf)\n"
            "  --est       the estimator: none (H-inf only), ukf, pf, or all three (default all)\n"
            "  --duration  simulated seconds of the circle, %g .. %g (default: the thesis's, one turn)\n"
            "  --compare   also run the simulator's circle and compare the duty sequences bit for bit\n" BR_PIL_USAGE,
            argv0, argv0, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S);
    br_cause_usage(to, "(the host's plant; the image keeps its machine's model)");
    return 2;
}

static int parse(int argc, char **argv, opts_t *o, int *done)
{
    static const struct option opts[] = {{"image", required_argument, NULL, 'i'},
                                         {"est", required_argument, NULL, 'e'},
                                         {"duration", required_argument, NULL, 'd'},
                                         {"compare", no_argument, NULL, 'c'},
                                         BR_PIL_LONGOPTS BR_CAUSE_LONGOPTS{0, 0, 0, 0}};
    *o = (opts_t){NULL, "all", 0.0, 0, br_pil_qemu_default(), br_plant_cfg_reference()};
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
            if (strcmp(v, "all") != 0 && br_circle_ctrl_of_est(v, &(br_circle_ctrl_t){BR_CTRL_HINF_ONLY}) != 0) {
                fprintf(stderr, "%s: --est %s: must be none, ukf, pf or all\n", TOOL, v);
                bad = 1;
            }
            break;
        case 'd':
            bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, &o->duration_s);
            break;
        case 'c': o->compare = 1; break;
        case BR_PIL_OPT: bad = br_pil_arg(TOOL, p.opt, v, &o->q) < 0; break;
        case BR_CAUSE_OPT: bad = br_cause_arg(p.opt, v, &o->causes) < 0; break;
        default: return usage(argv[0], stderr);
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (o->image == NULL) {
        fprintf(stderr, "%s: --image is required\n", TOOL);
        return usage(argv[0], stderr);
    }
    return 0;
}

/* the simulator's duties, for --compare */
typedef struct {
    float *duty[2];
    long n;
} sim_log_t;

static void sim_sink(void *user, const br_circle_sample_t *s)
{
    sim_log_t *l = user;
    if (l->n < 0) return;
    l->duty[0][l->n] = (float)s->duty[0];
    l->duty[1][l->n] = (float)s->duty[1];
    l->n++;
}

typedef struct {
    br_circle_result_t res;
    double wall_s;
    int same;          /* --compare: 1 identical, 0 differs, -1 not compared */
} run_t;

/* --compare: the simulator's same circle, its duties against the image's; 1 identical */
static int compare(const br_circle_cfg_t *c, const char *est, const br_circle_result_t *res, float *const duty[2])
{
    const long n = lround(c->duration_s / c->dt_s);
    sim_log_t l = {{calloc((size_t)n + 1, sizeof(float)), calloc((size_t)n + 1, sizeof(float))}, 0};
    br_circle_result_t sr;
    int same = 0;
    if (l.duty[0] != NULL && l.duty[1] != NULL && br_circle_run(c, sim_sink, &l, &sr) >= 0) {
        /* the periods both ran: up to the fault's (its period's duty is not a sample) */
        const long m = res->fault_status != 0 ? res->n_samples : n + 1;
        long first = -1;
        int ax_first = 0;
        for (long k = 0; k < m && first < 0; k++)
            for (int i = 0; i < 2 && first < 0; i++)
                if (memcmp(&l.duty[i][k], &duty[i][k], sizeof(float)) != 0 || l.n < m) {
                    first = k;
                    ax_first = i;
                }
        same = first < 0 && sr.fault_status == res->fault_status;
        if (first >= 0)
            fprintf(stderr, "%s: %s: the duty differs first at period %ld, axis %d: image %.9g, simulator %.9g\n", TOOL,
                    est, first, ax_first, (double)duty[ax_first][first],
                    first < l.n ? (double)l.duty[ax_first][first] : NAN);
        else if (!same)
            fprintf(stderr, "%s: %s: the image's run and the simulator's end differently (status %d, %d)\n", TOOL, est,
                    res->fault_status, sr.fault_status);
        else
            printf("%s: %ld periods x 2 axes: the duty sequence is the simulator's bit for bit\n", est, m);
    }
    free(l.duty[0]);
    free(l.duty[1]);
    return same;
}

static int run_one(const opts_t *o, br_circle_ctrl_t ctrl, const char *est, run_t *out)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(ctrl);
    br_causes_apply(&c.plant, &o->causes); /* the plant's truth; --compare's simulator runs the same plant */
    if (o->duration_s > 0.0) c.duration_s = o->duration_s;
    const long n = lround(c.duration_s / c.dt_s);
    float *duty[2] = {calloc((size_t)n + 1, sizeof(float)), calloc((size_t)n + 1, sizeof(float))};
    br_pil_loop_t L;
    memset(&L, 0, sizeof L);
    br_pil_run_t run;
    int rc = -1;
    if (duty[0] != NULL && duty[1] != NULL && br_pil_loop_open(&L, o->q.qemu, o->image, est, o->q.work, o->q.timeout_s) == 0 &&
        br_pil_loop_run(&L, &c, NULL, 0, duty, &run) == 0)
        rc = 0;
    br_pil_loop_close(&L); /* before --compare's simulator run: a signal then acts at once */
    if (rc == 0) {
        out->res = run.res;
        out->wall_s = run.wall_s;
        out->same = o->compare ? compare(&c, est, &run.res, duty) : -1;
    }
    free(duty[0]);
    free(duty[1]);
    return rc;
}

int main(int argc, char **argv)
{
    opts_t o;
    int done = 0;
    const int prc = parse(argc, argv, &o, &done);
    if (prc != 0 || done) return prc;
    if (access(o.image, R_OK) != 0) {
        fprintf(stderr, "%s: no image at %s (build the cm7-release preset)\n", TOOL, o.image);
        return 1;
    }
    static const struct {
        br_circle_ctrl_t ctrl;
        const char *est, *label;
    } rows[] = {{BR_CTRL_HINF_ONLY, "none", "H-inf only"},
                {BR_CTRL_HINF_UKF, "ukf", "H-inf + UKF"},
                {BR_CTRL_HINF_PF, "pf", "H-inf + PF"}};
    printf("X-Y circle on the image in the loop (QEMU mps2-an500, Cortex-M7) with the host plant\n");
    printf("%-14s %8s %16s %16s %12s %12s %10s %10s\n", "controller", "dt [ms]", "contour RMS [m]",
           "max error [m]", "/ H-inf only", "F err [N]", "= sim", "wall [s]");
    int rc = 0;
    double rms_hinf = 0.0;
    for (unsigned r = 0; r < sizeof rows / sizeof rows[0]; r++) {
        if (strcmp(o.est, "all") != 0 && strcmp(o.est, rows[r].est) != 0) continue;
        run_t run;
        if (run_one(&o, rows[r].ctrl, rows[r].est, &run) != 0) {
            fprintf(stderr, "%s: the run %s failed\n", TOOL, rows[r].est);
            return br_pil_loop_end(1);
        }
        const char *same = run.same < 0 ? "-" : run.same ? "yes" : "NO";
        if (run.same == 0) rc = 1;
        const double dt = br_circle_cfg_thesis(rows[r].ctrl).dt_s;
        if (run.res.fault_status != 0) {
            printf("%-14s %8.1f   FAULT at %.4f s (%s, status %d): no result %10s %10.1f\n", rows[r].label, dt * 1e3,
                   run.res.fault_t_s, br_run_fault_name(run.res.fault_cause), run.res.fault_status, same, run.wall_s);
            continue;
        }
        char ratio[32] = "-";
        if (rows[r].ctrl == BR_CTRL_HINF_ONLY) rms_hinf = run.res.contour_rms_m;
        if (rms_hinf > 0.0) snprintf(ratio, sizeof ratio, "%.3f", run.res.contour_rms_m / rms_hinf);
        printf("%-14s %8.1f %16.3e %16.3e %12s %12.3f %10s %10.1f\n", rows[r].label, dt * 1e3, run.res.contour_rms_m,
               run.res.max_err_m, ratio, run.res.fhat_rms_err_N, same, run.wall_s);
        fflush(stdout);
    }
    return rc;
}
