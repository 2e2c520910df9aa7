/* SPDX-License-Identifier: Apache-2.0 */
/* br_pil: the image in the loop (docs/link.md, "The image in the loop"). The
 * thesis circle with each axis's application on QEMU's Cortex-M7
 * (target/mps2/pil_main.c, one QEMU per axis) and the double-precision plant
 * here, in lockstep, period by period: br_circle_run_remote runs the plant,
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
 *                [--qemu PATH] [--timeout S] [--work DIR]
 * --compare runs the simulator's circle (br_circle_run, the same
 * configuration) too and compares the duty sequences bit for bit; exit 1 on a
 * difference (the first one printed). Prints the demo's table; a run the
 * firmware stopped is printed as a fault, never a figure (br_run_report.h). */
#define _DEFAULT_SOURCE /* mkdtemp */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bristle/br_link.h"
#include "bristle/br_link_pil.h"
#include "circle/br_circle.h"
#include "cause_args/br_cause_args.h"
#include "tool/br_args.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_pil"
#define SETUP_PERIODS 8u /* D: setpoints queued before the arm (the image's queue holds 64) */
#define TIMEOUT_MAX_S 3600.0

typedef struct {
    const char *image, *est, *qemu, *work;
    double duration_s, timeout_s;
    int compare;
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
            "  --compare   also run the simulator's circle and compare the duty sequences bit for bit\n"
            "  --qemu      qemu-system-arm to run (default $BR_QEMU, else qemu-system-arm on PATH)\n"
            "  --timeout   seconds to wait for one answer of the image, 1 .. %g (default 60)\n"
            "  --work      folder for the FIFOs and QEMU's logs (default a new one under /tmp, removed)\n"
            "  cause options  a cause in the host's plant: --offset F, --asym DFC,DFV, --ripple A,P[,PH],\n"
            "              --gradient S, --delay D, --drift R (docs/simlog.md; the image keeps its machine's model)\n",
            argv0, argv0, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, TIMEOUT_MAX_S);
    return 2;
}

static int parse(int argc, char **argv, opts_t *o, int *done)
{
    static const struct option opts[] = {{"image", required_argument, NULL, 'i'},
                                         {"est", required_argument, NULL, 'e'},
                                         {"duration", required_argument, NULL, 'd'},
                                         {"compare", no_argument, NULL, 'c'},
                                         {"qemu", required_argument, NULL, 'q'},
                                         {"timeout", required_argument, NULL, 't'},
                                         {"work", required_argument, NULL, 'w'},
                                         BR_CAUSE_LONGOPTS{0, 0, 0, 0}};
    const char *qe = getenv("BR_QEMU");
    *o = (opts_t){NULL, "all", (qe != NULL && qe[0] != '\0') ? qe : "qemu-system-arm", NULL, 0.0, 60.0, 0,
                  br_plant_cfg_reference()};
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
        case 'q': o->qemu = v; break;
        case 't': bad = br_arg_double(TOOL, p.opt, v, 1.0, TIMEOUT_MAX_S, &o->timeout_s); break;
        case 'w': o->work = v; break;
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

/* one axis's image: its QEMU, the four FIFO ends, the link's and the plant port's state */
typedef struct {
    pid_t pid;
    char dir[512];
    int link_in, link_out, plant_in, plant_out; /* the host's ends: in = to the image */
    uint16_t link_seq, plant_seq;
    uint32_t link_bytes; /* written on the link since the start */
    br_link_dec_t plant_dec, link_dec;
    int fault_cause;     /* from the link's fault report (-1: none seen) */
    uint32_t fault_tick;
} pil_axis_t;

typedef struct {
    const br_circle_cfg_t *c;
    pil_axis_t ax[2];
    long n;             /* the circle's last period */
    double timeout_s;
    float *duty[2];     /* the controller's duty per period, for --compare */
} pil_t;

/* the FIFO DIR/NAME, opened read-write (no open waits for the other end) */
static int fifo(const char *dir, const char *name, char *path, size_t cap)
{
    if (snprintf(path, cap, "%s/%s", dir, name) >= (int)cap) return -1;
    if (mkfifo(path, 0600) != 0 && errno != EEXIST) return -1;
    return open(path, O_RDWR | O_CLOEXEC);
}

static int axis_start(pil_axis_t *a, const opts_t *o, const char *est, const char *dir)
{
    char p[600], link[600], plant[600], log[600];
    snprintf(a->dir, sizeof a->dir, "%s", dir);
    a->link_in = fifo(dir, "link.in", p, sizeof p);
    a->link_out = fifo(dir, "link.out", p, sizeof p);
    a->plant_in = fifo(dir, "plant.in", p, sizeof p);
    a->plant_out = fifo(dir, "plant.out", p, sizeof p);
    if (a->link_in < 0 || a->link_out < 0 || a->plant_in < 0 || a->plant_out < 0) {
        fprintf(stderr, "%s: cannot make the FIFOs in %s: %s\n", TOOL, dir, strerror(errno));
        return -1;
    }
    (void)fcntl(a->link_out, F_SETFL, O_NONBLOCK);
    (void)fcntl(a->plant_out, F_SETFL, O_NONBLOCK);
    snprintf(link, sizeof link, "pipe:%s/link", dir);
    snprintf(plant, sizeof plant, "pipe:%s/plant", dir);
    snprintf(log, sizeof log, "%s/qemu.log", dir);
    char sh[600];
    snprintf(sh, sizeof sh, "enable=on,target=native,arg=pil,arg=%s", est);
    a->pid = fork();
    if (a->pid < 0) return -1;
    if (a->pid == 0) {
        const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execlp(o->qemu, o->qemu, "-M", "mps2-an500", "-display", "none", "-monitor", "none", "-serial", link,
               "-serial", plant, "-semihosting-config", sh, "-kernel", o->image, (char *)NULL);
        fprintf(stderr, "%s: cannot run %s: %s\n", TOOL, o->qemu, strerror(errno));
        _exit(127);
    }
    br_link_dec_init(&a->plant_dec);
    br_link_dec_init(&a->link_dec);
    a->link_seq = a->plant_seq = 1u;
    a->link_bytes = 0u;
    a->fault_cause = -1;
    return 0;
}

static void print_log(const pil_axis_t *a)
{
    char path[600], line[512];
    snprintf(path, sizeof path, "%s/qemu.log", a->dir);
    FILE *f = fopen(path, "r");
    if (f == NULL) return;
    while (fgets(line, sizeof line, f) != NULL) fprintf(stderr, "  qemu: %s", line);
    fclose(f);
}

static void axis_stop(pil_axis_t *a, int keep)
{
    if (a->pid > 0) {
        kill(a->pid, SIGTERM);
        waitpid(a->pid, NULL, 0);
        a->pid = 0;
    }
    const int fds[4] = {a->link_in, a->link_out, a->plant_in, a->plant_out};
    const char *names[5] = {"link.in", "link.out", "plant.in", "plant.out", "qemu.log"};
    for (int i = 0; i < 4; i++)
        if (fds[i] >= 0) close(fds[i]);
    a->link_in = a->link_out = a->plant_in = a->plant_out = -1;
    if (keep) return;
    char p[600];
    for (int i = 0; i < 5; i++) {
        snprintf(p, sizeof p, "%s/%s", a->dir, names[i]);
        unlink(p);
    }
    rmdir(a->dir);
}

static int write_all(int fd, const uint8_t *b, size_t n)
{
    while (n > 0) {
        const ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return -1;
        b += w;
        n -= (size_t)w;
    }
    return 0;
}

/* one frame on a FIFO; its bytes counted when on the link */
static int send_frame(int fd, uint16_t *seq, uint8_t id, const uint8_t *pay, size_t len, uint32_t *count)
{
    uint8_t fr[BR_LINK_FRAME_MAX];
    size_t n = 0;
    if (br_link_encode(fr, sizeof fr, id, (*seq)++, pay, len, &n) != BR_OK || write_all(fd, fr, n) != 0) return -1;
    if (count != NULL) *count += (uint32_t)n;
    return 0;
}

/* the link's reports so far: the fault report's cause and tick kept */
static void drain_link(pil_axis_t *a)
{
    uint8_t b[512];
    ssize_t r;
    while ((r = read(a->link_out, b, sizeof b)) > 0) {
        for (ssize_t i = 0; i < r; i++) {
            br_link_frame_t f;
            if (br_link_dec_push(&a->link_dec, b[i], &f) && f.id == BR_LINK_MSG_FAULT &&
                f.len == BR_LINK_MSG_FAULT_LEN) {
                a->fault_cause = f.payload[BR_LINK_MSG_FAULT_OFF_CAUSE];
                a->fault_tick = (uint32_t)f.payload[1] | (uint32_t)f.payload[2] << 8 |
                                (uint32_t)f.payload[3] << 16 | (uint32_t)f.payload[4] << 24;
            }
        }
    }
}

/* the setpoint of tick on the link: the circle's reference at period tick - D */
static int send_setpoint(pil_t *p, int axis, uint32_t tick)
{
    pil_axis_t *a = &p->ax[axis];
    double x;
    const long k = (long)tick - (long)SETUP_PERIODS;
    br_ref_t r = br_circle_axis_ref(p->c, axis, (double)k * p->c->dt_s, &x);
    if (!(r.ref_frac_counts < 1.0f)) {
        /* a fraction that rounded to 1 (a setpoint's is in [0, 1)): the same position as the next
         * whole count; --compare holds the application to the simulator's duty all the same */
        r.ref_counts += 1;
        r.ref_frac_counts = 0.0f;
    }
    const br_refq_item_t it = {BR_REFQ_SETPOINT, k == p->n ? BR_REFQ_FLAG_LAST : 0u, tick, 1u, r.ref_counts,
                               r.ref_frac_counts, r.ref_omega_radps, 0.0f, 0.0f};
    uint8_t pay[BR_LINK_MSG_SETPOINT_LEN];
    br_link_setpoint_pack(pay, &it);
    return send_frame(a->link_in, &a->link_seq, BR_LINK_MSG_SETPOINT, pay, sizeof pay, &a->link_bytes);
}

/* one period of the image: its tick and count out, its pil_out back */
static int exchange(pil_t *p, int axis, uint32_t tick, int32_t counts, br_link_pil_out_t *o)
{
    pil_axis_t *a = &p->ax[axis];
    const br_link_pil_tick_t t = {tick, counts, a->link_bytes};
    uint8_t pay[BR_LINK_MSG_PIL_TICK_LEN];
    br_link_pil_tick_pack(pay, &t);
    if (send_frame(a->plant_in, &a->plant_seq, BR_LINK_MSG_PIL_TICK, pay, sizeof pay, NULL) != 0) {
        fprintf(stderr, "%s: axis %d: cannot write to the image\n", TOOL, axis);
        return -1;
    }
    for (;;) {
        uint8_t b[64];
        const ssize_t r = read(a->plant_out, b, sizeof b);
        for (ssize_t i = 0; i < r; i++) {
            br_link_frame_t f;
            if (br_link_dec_push(&a->plant_dec, b[i], &f) && br_link_pil_out_unpack(&f, o) == BR_OK) {
                if (o->s.tick != tick || i + 1 != r) {
                    fprintf(stderr, "%s: axis %d: the image answered tick %u to tick %u\n", TOOL, axis,
                            (unsigned)o->s.tick, (unsigned)tick);
                    return -1;
                }
                drain_link(a);
                return 0;
            }
        }
        if (r > 0 || (r < 0 && errno == EINTR)) continue;
        struct pollfd pf = {a->plant_out, POLLIN, 0};
        if (poll(&pf, 1, (int)(p->timeout_s * 1000.0)) <= 0) {
            int ws;
            if (waitpid(a->pid, &ws, WNOHANG) == a->pid) {
                a->pid = 0;
                fprintf(stderr, "%s: axis %d: QEMU ended (status %d) at tick %u; its output:\n", TOOL, axis,
                        WIFEXITED(ws) ? WEXITSTATUS(ws) : -1, (unsigned)tick);
            } else {
                fprintf(stderr, "%s: axis %d: no answer from the image for %g s at tick %u; QEMU's output:\n",
                        TOOL, axis, p->timeout_s, (unsigned)tick);
            }
            print_log(a);
            return -1;
        }
    }
}

/* br_circle_remote_t's step: at k = 0 the setup periods and the arm first */
static int pil_step(void *user, int axis, long k, int32_t counts, br_circle_remote_out_t *out)
{
    pil_t *p = user;
    pil_axis_t *a = &p->ax[axis];
    br_link_pil_out_t o;
    if (k == 0) {
        for (uint32_t j = 0; j < SETUP_PERIODS; j++) {
            if (send_setpoint(p, axis, SETUP_PERIODS + j) != 0 || exchange(p, axis, j, counts, &o) != 0) return -1;
            if (o.on != 0u || o.port_duty != 0.0f) {
                fprintf(stderr, "%s: axis %d: the image's outputs were on before the arm\n", TOOL, axis);
                return -1;
            }
        }
        if (send_frame(a->link_in, &a->link_seq, BR_LINK_MSG_ARM, NULL, 0, &a->link_bytes) != 0) return -1;
    } else if (k - 1 + (long)SETUP_PERIODS <= p->n) {
        if (send_setpoint(p, axis, 2u * SETUP_PERIODS + (uint32_t)k - 1u) != 0) return -1;
    }
    if (exchange(p, axis, SETUP_PERIODS + (uint32_t)k, counts, &o) != 0) return -1;
    *out = (br_circle_remote_out_t){o.port_duty, o.s.status, o.s.fault, o.s.duty, o.s.F_hat_N, (o.s.flags >> 1) & 1};
    if (p->duty[axis] != NULL && k <= p->n) p->duty[axis][k] = o.s.duty;
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

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int run_one(const opts_t *o, br_circle_ctrl_t ctrl, const char *est, run_t *out)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(ctrl);
    br_causes_apply(&c.plant, &o->causes); /* the plant's truth; --compare's simulator runs the same plant */
    if (o->duration_s > 0.0) c.duration_s = o->duration_s;
    pil_t p;
    memset(&p, 0, sizeof p);
    p.c = &c;
    p.n = lround(c.duration_s / c.dt_s);
    p.timeout_s = o->timeout_s;
    for (int i = 0; i < 2; i++) {
        p.ax[i].link_in = p.ax[i].link_out = p.ax[i].plant_in = p.ax[i].plant_out = -1;
        p.duty[i] = calloc((size_t)p.n + 1, sizeof(float));
    }
    int rc = -1, started = 0;
    if (p.duty[0] == NULL || p.duty[1] == NULL) goto out;
    for (int i = 0; i < 2; i++) {
        char dir[512];
        if (o->work != NULL) {
            snprintf(dir, sizeof dir, "%s/%s_axis%d", o->work, est, i);
            if (mkdir(dir, 0700) != 0 && errno != EEXIST) {
                fprintf(stderr, "%s: cannot make %s: %s\n", TOOL, dir, strerror(errno));
                goto out;
            }
        } else {
            snprintf(dir, sizeof dir, "/tmp/br_pil_XXXXXX");
            if (mkdtemp(dir) == NULL) goto out;
        }
        if (axis_start(&p.ax[i], o, est, dir) != 0) goto out;
        started = i + 1;
    }
    const br_circle_remote_t remote = {pil_step, &p};
    const double t0 = now_s();
    const int r = br_circle_run_remote(&c, &remote, NULL, NULL, &out->res);
    out->wall_s = now_s() - t0;
    if (r < 0) goto out;
    out->same = -1;
    if (o->compare) {
        sim_log_t l = {{calloc((size_t)p.n + 1, sizeof(float)), calloc((size_t)p.n + 1, sizeof(float))}, 0};
        br_circle_result_t sr;
        out->same = 0;
        if (l.duty[0] != NULL && l.duty[1] != NULL && br_circle_run(&c, sim_sink, &l, &sr) >= 0) {
            /* the periods both ran: up to the fault's (its period's duty is not a sample) */
            const long m = out->res.fault_status != 0 ? out->res.n_samples : p.n + 1;
            long first = -1;
            int ax_first = 0;
            for (long k = 0; k < m && first < 0; k++)
                for (int i = 0; i < 2 && first < 0; i++)
                    if (memcmp(&l.duty[i][k], &p.duty[i][k], sizeof(float)) != 0 || l.n < m) {
                        first = k;
                        ax_first = i;
                    }
            out->same = first < 0 && sr.fault_status == out->res.fault_status;
            if (first >= 0)
                fprintf(stderr, "%s: %s: the duty differs first at period %ld, axis %d: image %.9g, simulator %.9g\n",
                        TOOL, est, first, ax_first, (double)p.duty[ax_first][first],
                        first < l.n ? (double)l.duty[ax_first][first] : NAN);
            else if (!out->same)
                fprintf(stderr, "%s: %s: the image's run and the simulator's end differently (status %d, %d)\n",
                        TOOL, est, out->res.fault_status, sr.fault_status);
            else
                printf("%s: %ld periods x 2 axes: the duty sequence is the simulator's bit for bit\n", est, m);
        }
        free(l.duty[0]);
        free(l.duty[1]);
    }
    rc = 0;
out:
    for (int i = 0; i < started; i++) axis_stop(&p.ax[i], o->work != NULL);
    free(p.duty[0]);
    free(p.duty[1]);
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
    signal(SIGPIPE, SIG_IGN);
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
            return 1;
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
