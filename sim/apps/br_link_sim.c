/* SPDX-License-Identifier: Apache-2.0 */
/* br_link_sim: the simulator's binding of the link (docs/link.md, "The
 * simulator's binding"). One axis of the machine this build is for
 * (BR_MACHINE) on the double-precision plant (br_hal_sim), run by the
 * production application (br_app with the machine's guards and drive
 * protections) behind the command service (br_svc), telemetry (br_tlm) and
 * the recorder (br_rec), exactly as an image runs them, with the link's byte
 * channel on a pseudo-terminal.
 *
 * Why a pseudo-terminal and not a pair of pipes: the host's tool opens it as
 * it opens a serial port (pyserial, a path under /dev/pts), so the path it
 * takes on a real axis is the one the simulator tests; the pty is raw (no
 * echo, no line discipline), and the master is non-blocking, so a period
 * never waits for the host: a read with nothing there is 0 bytes, a write
 * the pty has no room for is 0 bytes (the link keeps it queued, telemetry
 * drops and counts it).
 *
 * Time is simulated: one control period per tick of the plant. --speed 1
 * runs one period per period of wall time (a host streaming setpoints sees
 * a real axis's pace); --speed S runs S times faster; --speed 0 runs as fast
 * as the machine goes, with no pause. The axis starts disarmed (duty 0,
 * outputs off), in the middle of the machine's soft limits.
 *
 * Usage: br_link_sim [--est none|ukf|pf] [--plant thesis|hardware_like]
 *                    [--speed S] [--duration S] [--pty-path FILE]
 *                    [--tlm-every N] [--status-periods N] [--queue N]
 *                    [--hold-periods N] [--rec-capacity N] [--rec-pre N] [cause options]
 * Prints the slave's path on stdout at the start ("pty /dev/pts/N"), and at
 * the end one summary line of what ran and what the link counted. Runs until
 * --duration of simulated time or SIGINT / SIGTERM. */
#define _XOPEN_SOURCE 600
#define _DEFAULT_SOURCE /* cfmakeraw */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_rec.h"
#include "bristle/br_svc.h"
#include "bristle/br_tlm.h"
#include "circle/br_circle.h"
#include "hal_sim/br_hal_sim.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"
#include "bristle_gen/machine/br_machine.h"
#include "cause_args/br_cause_args.h"

#define TOOL "br_link_sim"
/* the bounds of the options (docs/tools.md) */
#define SPEED_MAX 1000.0
#define PERIODS_MAX 100000L

/* the stop request of a signal: the only state a handler may touch */
static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

typedef struct {
    const char *est, *plant, *pty_path;
    double speed, duration_s;
    long tlm_every, status_periods, queue, hold_periods, rec_capacity, rec_pre;
    br_plant_cfg_t causes; /* the cause options (br_cause_args.h) on the reference machine */
} opts_t;

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--est none|ukf|pf] [--plant thesis|hardware_like] [--speed S] [--duration S]\n"
            "          [--pty-path FILE] [--tlm-every N] [--status-periods N] [--queue N]\n"
            "          [--hold-periods N] [--rec-capacity N] [--rec-pre N] [cause options]\n" BR_ARGS_COMMON_USAGE
            "  --est             the estimator of the application (default ukf; none: H-infinity only, no parameters)\n"
            "  --plant           the simulated plant (default thesis: the machine's LuGre; hardware_like: Maxwell-slip)\n"
            "  --speed           simulated periods per wall-clock period, 0 .. %g (default 1; 0: no pause)\n"
            "  --duration        simulated seconds before the end, %g .. %g (default %g)\n"
            "  --pty-path        write the pseudo-terminal's path into FILE (atomically) once it is ready\n"
            "  --tlm-every       a telemetry sample every N periods, 1 .. %ld (default 1: the control rate)\n"
            "  --status-periods  a status and ref_status every N periods, 1 .. %ld (default 10)\n"
            "  --queue           the reference queue's places, 1 .. %u (default %u)\n"
            "  --hold-periods    underrun: periods the last reference goes on before braking, 0 .. %ld (default 20)\n"
            "  --rec-capacity    the recorder's samples, 1 .. %u (default 2000)\n"
            "  --rec-pre         of them before the trigger, 0 .. capacity - 1 (default capacity / 2)\n",
            argv0, argv0, SPEED_MAX, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, BR_TOOL_DURATION_MAX_S,
            PERIODS_MAX, PERIODS_MAX, (unsigned)BR_REFQ_MAX, (unsigned)BR_REFQ_MAX, PERIODS_MAX,
            (unsigned)BR_REC_CAPACITY_MAX);
    br_cause_usage(to, "(the application keeps the machine's model)");
    return 2;
}

static int parse(int argc, char **argv, opts_t *o, int *done)
{
    static const struct option opts[] = {{"est", required_argument, NULL, 'e'},
                                         {"plant", required_argument, NULL, 'p'},
                                         {"speed", required_argument, NULL, 's'},
                                         {"duration", required_argument, NULL, 'd'},
                                         {"pty-path", required_argument, NULL, 'o'},
                                         {"tlm-every", required_argument, NULL, 't'},
                                         {"status-periods", required_argument, NULL, 'S'},
                                         {"queue", required_argument, NULL, 'q'},
                                         {"hold-periods", required_argument, NULL, 'H'},
                                         {"rec-capacity", required_argument, NULL, 'c'},
                                         {"rec-pre", required_argument, NULL, 'r'},
                                         BR_CAUSE_LONGOPTS{0, 0, 0, 0}};
    *o = (opts_t){"ukf", "thesis", NULL, 1.0, BR_TOOL_DURATION_MAX_S, 1, 10, BR_REFQ_MAX, 20, 2000, -1,
                  br_plant_cfg_reference()};
    br_args_t p;
    *done = br_args_start(&p, TOOL, argc, argv, usage);
    if (*done) return 0;
    const char *v;
    for (int c; (c = br_args_next(&p, opts, &v)) != BR_ARGS_END;) {
        int bad = 0;
        switch (c) {
        case 'e':
            o->est = v;
            if (br_circle_ctrl_of_est(v, &(br_circle_ctrl_t){BR_CTRL_HINF_ONLY}) != 0) {
                fprintf(stderr, "%s: --est %s: must be none, ukf or pf\n", TOOL, v);
                bad = 1;
            }
            break;
        case 'p':
            o->plant = v;
            if (strcmp(v, "thesis") != 0 && strcmp(v, "hardware_like") != 0) {
                fprintf(stderr, "%s: --plant %s: must be thesis or hardware_like\n", TOOL, v);
                bad = 1;
            }
            break;
        case 's': bad = br_arg_double(TOOL, p.opt, v, 0.0, SPEED_MAX, &o->speed); break;
        case 'd':
            bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, &o->duration_s);
            break;
        case 'o': o->pty_path = v; break;
        case 't': bad = br_arg_long(TOOL, p.opt, v, 1, PERIODS_MAX, &o->tlm_every); break;
        case 'S': bad = br_arg_long(TOOL, p.opt, v, 1, PERIODS_MAX, &o->status_periods); break;
        case 'q': bad = br_arg_long(TOOL, p.opt, v, 1, BR_REFQ_MAX, &o->queue); break;
        case 'H': bad = br_arg_long(TOOL, p.opt, v, 0, PERIODS_MAX, &o->hold_periods); break;
        case 'c': bad = br_arg_long(TOOL, p.opt, v, 1, BR_REC_CAPACITY_MAX, &o->rec_capacity); break;
        case 'r': bad = br_arg_long(TOOL, p.opt, v, 0, BR_REC_CAPACITY_MAX - 1, &o->rec_pre); break;
        case BR_CAUSE_OPT: bad = br_cause_arg(p.opt, v, &o->causes) < 0; break;
        default: return usage(argv[0], stderr);
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (o->rec_pre < 0) o->rec_pre = o->rec_capacity / 2;
    if (o->rec_pre >= o->rec_capacity) {
        fprintf(stderr, "%s: --rec-pre %ld: must be below --rec-capacity %ld\n", TOOL, o->rec_pre, o->rec_capacity);
        return usage(argv[0], stderr);
    }
    return 0;
}

/* the byte channel on the pty's master: non-blocking both ways */
static size_t pty_read(void *ctx, uint8_t *buf, size_t n)
{
    const ssize_t r = read(*(const int *)ctx, buf, n);
    return r > 0 ? (size_t)r : 0u;
}

static size_t pty_write(void *ctx, const uint8_t *buf, size_t n)
{
    const ssize_t r = write(*(const int *)ctx, buf, n);
    return r > 0 ? (size_t)r : 0u;
}

/* a raw pseudo-terminal: the master non-blocking in *master, the slave kept
 * open in *slave (so the master never reads EIO while no host has it open),
 * its path in name. 0, or -1 with a message. */
static int open_pty(int *master, int *slave, char *name, size_t cap)
{
    *master = posix_openpt(O_RDWR | O_NOCTTY);
    if (*master < 0 || grantpt(*master) != 0 || unlockpt(*master) != 0) {
        fprintf(stderr, "%s: cannot open a pseudo-terminal: %s\n", TOOL, strerror(errno));
        return -1;
    }
    const char *sn = ptsname(*master);
    if (sn == NULL || strlen(sn) >= cap) {
        fprintf(stderr, "%s: no name for the pseudo-terminal\n", TOOL);
        return -1;
    }
    strcpy(name, sn);
    *slave = open(name, O_RDWR | O_NOCTTY);
    struct termios tio;
    if (*slave < 0 || tcgetattr(*slave, &tio) != 0) {
        fprintf(stderr, "%s: cannot open %s: %s\n", TOOL, name, strerror(errno));
        return -1;
    }
    cfmakeraw(&tio);
    if (tcsetattr(*slave, TCSANOW, &tio) != 0 || fcntl(*master, F_SETFL, O_NONBLOCK) != 0) {
        fprintf(stderr, "%s: cannot set %s raw and non-blocking: %s\n", TOOL, name, strerror(errno));
        return -1;
    }
    return 0;
}

/* the pty's path into FILE, atomically (docs/tools.md) */
static int write_pty_path(const char *path, const char *name)
{
    br_outfile_t of = {0};
    if (br_outfile_open(&of, TOOL, path) != 0) return -1;
    fprintf(of.f, "%s\n", name);
    return br_outfile_commit(&of, TOOL);
}

/* wall-clock pacing: sleep until the k-th period's time (speed > 0) */
static void pace(const struct timespec *t0, long k, double period_wall_s)
{
    const double at = (double)k * period_wall_s;
    struct timespec due = *t0;
    due.tv_sec += (time_t)floor(at);
    due.tv_nsec += (long)((at - floor(at)) * 1e9);
    if (due.tv_nsec >= 1000000000L) {
        due.tv_sec += 1;
        due.tv_nsec -= 1000000000L;
    }
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &due, NULL) == EINTR && !stop_requested) {
    }
}

/* 1 when the wall clock has passed the end of period k (a late period) */
static int late(const struct timespec *t0, long k, double period_wall_s)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double el = (double)(now.tv_sec - t0->tv_sec) + 1e-9 * (double)(now.tv_nsec - t0->tv_nsec);
    return el > (double)(k + 1) * period_wall_s;
}

typedef struct {
    br_plant_t plant;
    br_hal_sim_t port;
    br_hal_t hal;
    br_circle_cfg_t c;
    br_ctrl_cfg_t cc;
    br_app_cfg_t ac;
    br_app_mem_t mem;
    br_app_t app;
    br_svc_t svc;
    br_tlm_t tlm;
    br_rec_t rec;
    br_rec_slot_t *slots;
} axis_t;

/* the axis: plant, HAL, application (disarmed), service, telemetry, recorder */
static int axis_init(axis_t *a, const opts_t *o, const br_byte_chan_t *chan)
{
    br_circle_ctrl_t ctrl = BR_CTRL_HINF_ONLY;
    (void)br_circle_ctrl_of_est(o->est, &ctrl); /* checked by parse */
    a->c = strcmp(o->plant, "thesis") == 0 ? br_circle_cfg_thesis(ctrl) : br_circle_cfg_hardware_like(ctrl);
    br_causes_apply(&a->c.plant, &o->causes); /* the plant's truth only */
    const br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t mc = br_app_motion_cfg(&mm);
    const double L = a->c.plant.lead_mprad, dt = a->c.dt_s;
    const br_plant_state_t x0 = {0.5 * ((double)mc.soft_min_m + (double)mc.soft_max_m) / L, 0.0, 0.0};
    if (br_plant_init(&a->plant, &a->c.plant, &x0) != 0 || br_hal_sim_init(&a->port, &a->plant, dt, &a->hal) != BR_OK) {
        fprintf(stderr, "%s: plant init failed\n", TOOL);
        return -1;
    }
    a->cc = br_circle_ctrl_cfg(&a->c);
    static const br_est_t no_ext = {NULL, NULL, NULL, NULL};
    a->ac = (br_app_cfg_t){&a->cc, BR_APP_EST_NONE, &a->c.pf, &a->c.ukf, &no_ext,
                           br_app_guard_cfg(a->cc.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F), mc};
    a->mem = (br_app_mem_t){NULL, NULL};
    if (ctrl == BR_CTRL_HINF_PF) {
        a->ac.est = BR_APP_EST_PF;
        a->mem.pf = calloc(1, sizeof *a->mem.pf);
        if (a->mem.pf == NULL) return -1;
    } else if (ctrl == BR_CTRL_HINF_UKF) {
        a->ac.est = BR_APP_EST_UKF;
        a->mem.ukf = calloc(1, sizeof *a->mem.ukf);
        if (a->mem.ukf == NULL) return -1;
    }
    br_refq_cfg_t q = {(uint32_t)o->queue, (float)dt, BR_MACHINE_RAD_PER_COUNT_F, mc.counts_per_m, mc.max_speed_mps,
                       mc.max_accel_mps2, (uint32_t)o->hold_periods, 0u};
    /* the fault one period after the braking from the machine's top speed (refq.md) */
    q.fault_periods = br_refq_fault_periods_min(&q);
    const br_svc_cfg_t sc = {BR_LINK_RX_BUDGET_MAX, BR_LINK_TX_BUF_BYTES, q, (uint32_t)o->status_periods, NULL, NULL,
                             BR_MACHINE_NAME};
    const br_tlm_cfg_t tc = {(uint32_t)o->tlm_every};
    a->slots = calloc((size_t)o->rec_capacity, sizeof *a->slots);
    if (a->slots == NULL) return -1;
    const br_rec_cfg_t rc = {a->slots, (uint32_t)o->rec_capacity, (uint32_t)o->rec_pre, 0.0f, 2u};
    br_status_t st = br_app_init(&a->app, &a->ac, &a->hal, &a->mem);
    if (st == BR_OK) st = br_svc_init(&a->svc, &sc, &a->app, &a->ac, &a->mem, chan);
    if (st == BR_OK) st = br_tlm_init(&a->tlm, &tc);
    if (st == BR_OK) st = br_rec_init(&a->rec, &rc);
    if (st != BR_OK) {
        fprintf(stderr, "%s: firmware init failed (status %d)\n", TOOL, (int)st);
        return -1;
    }
    return 0;
}

static void axis_free(axis_t *a)
{
    free(a->mem.pf);
    free(a->mem.ukf);
    free(a->slots);
}

/* one control period, as an image runs it: the tick (the plant advances one
 * period with the duty held), the service (link, request, reference,
 * br_app_step, reports), the sample to telemetry and the recorder, the
 * recorder's requests, a bounded share of a dump. 0, or -1 on an error that
 * is the binding's (not a fault of the axis, which the service reports). */
static int axis_period(axis_t *a)
{
    uint32_t tick;
    a->hal.tick_wait(a->hal.ctx, &tick);
    const br_status_t st = br_svc_step(&a->svc);
    if (st == BR_E_NULL || st == BR_E_STATE) {
        fprintf(stderr, "%s: br_svc_step returned %d\n", TOOL, (int)st);
        return -1;
    }
    br_rec_sample_t s;
    (void)br_rec_sample_take(&s, &a->app, a->svc.tick - 1u, st);
    (void)br_tlm_step(&a->tlm, &a->svc.link, &s); /* a drop is counted (n_dropped) */
    if (br_rec_push(&a->rec, &s) != BR_OK) return -1;
    (void)br_rec_command(&a->rec, &a->svc.cmd);
    const br_status_t ds = br_rec_dump_step(&a->rec, &a->svc.link);
    return BR_FAILED(ds) ? -1 : 0;
}

int main(int argc, char **argv)
{
    opts_t o;
    int done = 0;
    const int prc = parse(argc, argv, &o, &done);
    if (prc != 0 || done) return prc;
    int master = -1, slave = -1, rc = 1;
    char name[256];
    axis_t *a = calloc(1, sizeof *a);
    if (a == NULL || open_pty(&master, &slave, name, sizeof name) != 0) goto out;
    const br_byte_chan_t chan = {&master, pty_read, pty_write};
    if (axis_init(a, &o, &chan) != 0) goto out;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    printf("pty %s\n", name);
    fflush(stdout);
    if (o.pty_path != NULL && write_pty_path(o.pty_path, name) != 0) goto out;
    const double dt = a->c.dt_s, period_wall_s = o.speed > 0.0 ? dt / o.speed : 0.0;
    const long n = lround(o.duration_s / dt);
    long k = 0, n_late = 0;
    struct timespec t0;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (; k < n && !stop_requested; k++) {
        if (period_wall_s > 0.0) pace(&t0, k, period_wall_s);
        if (axis_period(a) != 0) goto out;
        if (period_wall_s > 0.0 && late(&t0, k, period_wall_s)) n_late++;
    }
    const br_link_counters_t *lc = &a->svc.link.dec.cnt;
    fprintf(stderr,
            "%s: %ld periods (%.3f s simulated), %ld late; link rx %lu frames, %lu replayed, %lu bad crc, "
            "tx %lu frames, %lu busy; telemetry %lu sent, %lu dropped; arm refused %lu; ended %s; "
            "last fault latched: %s (tick %lu)\n",
            TOOL, k, (double)k * dt, n_late, (unsigned long)lc->rx_frames, (unsigned long)lc->rx_replayed,
            (unsigned long)lc->rx_bad_crc, (unsigned long)lc->tx_frames, (unsigned long)lc->tx_busy,
            (unsigned long)a->tlm.n_sent, (unsigned long)a->tlm.n_dropped, (unsigned long)a->svc.cnt.arm_refused,
            a->svc.armed ? "armed" : br_run_fault_name((int)a->svc.fault), br_run_fault_name((int)a->svc.fault_cause),
            (unsigned long)a->svc.fault_tick);
    rc = 0;
out:
    if (a != NULL) axis_free(a);
    free(a);
    if (slave >= 0) close(slave);
    if (master >= 0) close(master);
    return rc;
}
