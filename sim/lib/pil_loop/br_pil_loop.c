/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's host side (br_pil_loop.h; docs/link.md). */
#define _DEFAULT_SOURCE /* mkdtemp */
#include "pil_loop/br_pil_loop.h"

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
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "bristle/br_link_pil.h"
#include "bristle_gen/link/br_link_msgs.h"

#define TOOL "br_pil"
#define SETUP_PERIODS 8u /* D: setpoints queued before the arm (the image's queue holds 64) */
/* after a run: the disarm and the fault reset, then periods at rest until the link's
 * backlog is taken (at most the D setpoints sent ahead of a period that faulted) */
#define AFTER_PERIODS (SETUP_PERIODS + 6u)
/* and at most this many until the outputs are off */
#define AFTER_MAX_PERIODS 100000u

static const char *const FILES[5] = {"link.in", "link.out", "plant.in", "plant.out", "qemu.log"};

/* The signals that stop a tool (Ctrl-C, kill, a closed terminal): while a loop is
 * open, their handler only records the signal; the loop's waits see it (a wait
 * returns EINTR, or at its next slice) and the run ends with -1, so that the tool
 * removes the work folders (br_pil_loop_close) and its temporary outputs before
 * br_pil_loop_end re-raises it. A process-wide flag: a signal handler reaches
 * nothing else (the one mutable global of the loop, async-signal-safe). */
static const int STOP_SIGNALS[3] = {SIGINT, SIGTERM, SIGHUP};
static volatile sig_atomic_t stop_signal;
static struct sigaction stop_saved[3];
static int stop_installed;
/* the longest single wait: a signal that lands between the flag's test and the wait is seen within it */
#define WAIT_SLICE_MS 100

static void on_stop_signal(int sig)
{
    stop_signal = sig;
}

static void stop_install(void)
{
    if (stop_installed) return;
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal; /* no SA_RESTART: a blocked read, write or poll returns EINTR */
    sigemptyset(&sa.sa_mask);
    for (int i = 0; i < 3; i++) sigaction(STOP_SIGNALS[i], &sa, &stop_saved[i]);
    stop_installed = 1;
}

static void stop_restore(void)
{
    if (!stop_installed) return;
    for (int i = 0; i < 3; i++) sigaction(STOP_SIGNALS[i], &stop_saved[i], NULL);
    stop_installed = 0;
}

/* 1 (with a message) when a signal asked the tool to stop */
static int stopped(int axis)
{
    if (stop_signal == 0) return 0;
    fprintf(stderr, "%s: axis %d: stopped by signal %d; the work folders are removed\n", TOOL, axis, (int)stop_signal);
    return 1;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* the FIFO DIR/NAME, opened read-write (no open waits for the other end) */
static int fifo(const char *dir, const char *name)
{
    char path[600];
    if (snprintf(path, sizeof path, "%s/%s", dir, name) >= (int)sizeof path) return -1;
    if (mkfifo(path, 0600) != 0 && errno != EEXIST) return -1;
    return open(path, O_RDWR | O_CLOEXEC);
}

static int axis_start(br_pil_axis_t *a, const char *qemu, const char *image, const char *est, const char *dir)
{
    char link[600], plant[600], log[600], sh[600];
    snprintf(a->dir, sizeof a->dir, "%s", dir);
    a->link_in = fifo(dir, FILES[0]);
    a->link_out = fifo(dir, FILES[1]);
    a->plant_in = fifo(dir, FILES[2]);
    a->plant_out = fifo(dir, FILES[3]);
    if (a->link_in < 0 || a->link_out < 0 || a->plant_in < 0 || a->plant_out < 0) {
        fprintf(stderr, "%s: cannot make the FIFOs in %s: %s\n", TOOL, dir, strerror(errno));
        return -1;
    }
    (void)fcntl(a->link_out, F_SETFL, O_NONBLOCK);
    (void)fcntl(a->plant_out, F_SETFL, O_NONBLOCK);
    snprintf(link, sizeof link, "pipe:%s/link", dir);
    snprintf(plant, sizeof plant, "pipe:%s/plant", dir);
    snprintf(log, sizeof log, "%s/%s", dir, FILES[4]);
    snprintf(sh, sizeof sh, "enable=on,target=native,arg=pil,arg=%s", est);
    a->pid = fork();
    if (a->pid < 0) return -1;
    if (a->pid == 0) {
#ifdef __linux__
        /* a host killed mid-run takes its QEMU with it (it would wait for ticks for 2^32 polls) */
        (void)prctl(PR_SET_PDEATHSIG, SIGTERM);
#endif
        const int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execlp(qemu, qemu, "-M", "mps2-an500", "-display", "none", "-monitor", "none", "-serial", link, "-serial",
               plant, "-semihosting-config", sh, "-kernel", image, (char *)NULL);
        fprintf(stderr, "%s: cannot run %s: %s\n", TOOL, qemu, strerror(errno));
        _exit(127);
    }
    br_link_dec_init(&a->plant_dec);
    br_link_dec_init(&a->link_dec);
    a->link_seq = a->plant_seq = 1u;
    a->link_bytes = 0u;
    a->tick = 0u;
    a->fault_cause = -1;
    return 0;
}

static void print_log(const br_pil_axis_t *a)
{
    char path[600], line[512];
    snprintf(path, sizeof path, "%s/%s", a->dir, FILES[4]);
    FILE *f = fopen(path, "r");
    if (f == NULL) return;
    while (fgets(line, sizeof line, f) != NULL) fprintf(stderr, "  qemu: %s", line);
    fclose(f);
}

static void axis_stop(br_pil_axis_t *a, int keep)
{
    if (a->pid > 0) {
        kill(a->pid, SIGTERM);
        while (waitpid(a->pid, NULL, 0) < 0 && errno == EINTR) continue;
        a->pid = 0;
    }
    const int fds[4] = {a->link_in, a->link_out, a->plant_in, a->plant_out};
    for (int i = 0; i < 4; i++)
        if (fds[i] >= 0) close(fds[i]);
    a->link_in = a->link_out = a->plant_in = a->plant_out = -1;
    if (keep) return;
    char p[600];
    for (int i = 0; i < 5; i++) {
        snprintf(p, sizeof p, "%s/%s", a->dir, FILES[i]);
        unlink(p);
    }
    rmdir(a->dir);
}

static int write_all(int fd, const uint8_t *b, size_t n)
{
    while (n > 0) {
        const ssize_t w = write(fd, b, n);
        if (w < 0 && errno == EINTR && stop_signal == 0) continue;
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

/* a request on the link */
static int send_request(br_pil_axis_t *a, uint8_t id, const uint8_t *pay, size_t len)
{
    return send_frame(a->link_in, &a->link_seq, id, pay, len, &a->link_bytes);
}

static uint32_t u32_at(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* the link's reports so far: the fault report's cause and tick, the param_value answers */
static void drain_link(br_pil_axis_t *a)
{
    uint8_t b[512];
    ssize_t r;
    while ((r = read(a->link_out, b, sizeof b)) > 0) {
        for (ssize_t i = 0; i < r; i++) {
            br_link_frame_t f;
            if (!br_link_dec_push(&a->link_dec, b[i], &f)) continue;
            if (f.id == BR_LINK_MSG_FAULT && f.len == BR_LINK_MSG_FAULT_LEN) {
                a->fault_cause = f.payload[BR_LINK_MSG_FAULT_OFF_CAUSE];
                a->fault_tick = u32_at(&f.payload[BR_LINK_MSG_FAULT_OFF_TICK]);
            } else if (f.id == BR_LINK_MSG_PARAM_VALUE && f.len == BR_LINK_MSG_PARAM_VALUE_LEN &&
                       a->n_replies < BR_PIL_PARAMS_MAX) {
                const uint8_t *p = f.payload;
                const uint32_t v = u32_at(&p[BR_LINK_MSG_PARAM_VALUE_OFF_VALUE]);
                a->reply_id[a->n_replies] = (uint16_t)(p[0] | p[1] << 8);
                memcpy(&a->reply_value[a->n_replies], &v, sizeof v);
                a->reply_status[a->n_replies] = (int8_t)p[BR_LINK_MSG_PARAM_VALUE_OFF_STATUS];
                a->n_replies++;
            }
        }
    }
}

/* the setpoint of the circle's period k on the link, for tick base + k */
static int send_setpoint(br_pil_loop_t *L, int axis, long k)
{
    br_pil_axis_t *a = &L->ax[axis];
    double x;
    br_ref_t r = br_circle_axis_ref(L->c, axis, (double)k * L->c->dt_s, &x);
    if (!(r.ref_frac_counts < 1.0f)) {
        /* a fraction that rounded to 1 (a setpoint's is in [0, 1)): the same position as the next
         * whole count; --compare holds the application to the simulator's duty all the same */
        r.ref_counts += 1;
        r.ref_frac_counts = 0.0f;
    }
    const br_refq_item_t it = {BR_REFQ_SETPOINT, k == L->n ? BR_REFQ_FLAG_LAST : 0u, a->base + (uint32_t)k, 1u,
                               r.ref_counts, r.ref_frac_counts, r.ref_omega_radps, 0.0f, 0.0f};
    uint8_t pay[BR_LINK_MSG_SETPOINT_LEN];
    br_link_setpoint_pack(pay, &it);
    return send_request(a, BR_LINK_MSG_SETPOINT, pay, sizeof pay);
}

/* one period of the image: its tick and count out, its pil_out back */
static int exchange(br_pil_loop_t *L, int axis, int32_t counts, br_link_pil_out_t *o)
{
    br_pil_axis_t *a = &L->ax[axis];
    const uint32_t tick = a->tick++;
    const br_link_pil_tick_t t = {tick, counts, a->link_bytes};
    uint8_t pay[BR_LINK_MSG_PIL_TICK_LEN];
    br_link_pil_tick_pack(pay, &t);
    a->last_counts = counts;
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
        if (stopped(axis)) return -1;
        if (r > 0 || (r < 0 && errno == EINTR)) continue;
        struct pollfd pf = {a->plant_out, POLLIN, 0};
        int ready = 0;
        for (const double end_s = now_s() + L->timeout_s; ready == 0 && now_s() < end_s;) {
            ready = poll(&pf, 1, WAIT_SLICE_MS);
            if (ready < 0 && errno == EINTR) ready = 0;
            if (stopped(axis)) return -1;
        }
        if (ready <= 0) {
            int ws;
            if (waitpid(a->pid, &ws, WNOHANG) == a->pid) {
                a->pid = 0;
                fprintf(stderr, "%s: axis %d: QEMU ended (status %d) at tick %u; its output:\n", TOOL, axis,
                        WIFEXITED(ws) ? WEXITSTATUS(ws) : -1, (unsigned)tick);
            } else {
                fprintf(stderr, "%s: axis %d: no answer from the image for %g s at tick %u; QEMU's output:\n", TOOL,
                        axis, L->timeout_s, (unsigned)tick);
            }
            print_log(a);
            return -1;
        }
    }
}

/* a period with the axis disarmed: its outputs must be off */
static int exchange_off(br_pil_loop_t *L, int axis, int32_t counts)
{
    br_link_pil_out_t o;
    if (exchange(L, axis, counts, &o) != 0) return -1;
    if (o.on != 0u || o.port_duty != 0.0f) {
        fprintf(stderr, "%s: axis %d: the image's outputs were on before the arm\n", TOOL, axis);
        return -1;
    }
    return 0;
}

/* before the arm: the parameter writes, one a period, then the D setup periods queue the first
 * D setpoints (the plant at rest, not advanced) and the arm goes with the circle's first period */
static int before_arm(br_pil_loop_t *L, int axis, int32_t counts)
{
    br_pil_axis_t *a = &L->ax[axis];
    a->n_replies = 0;
    for (int j = 0; j < L->n_params; j++) {
        uint8_t pay[BR_LINK_MSG_PARAM_WRITE_LEN];
        uint32_t v;
        memcpy(&v, &L->params[j].value, sizeof v);
        pay[0] = (uint8_t)(L->params[j].id & 0xFFu);
        pay[1] = (uint8_t)(L->params[j].id >> 8);
        for (int b = 0; b < 4; b++) pay[BR_LINK_MSG_PARAM_WRITE_OFF_VALUE + b] = (uint8_t)(v >> (8 * b));
        if (send_request(a, BR_LINK_MSG_PARAM_WRITE, pay, sizeof pay) != 0 || exchange_off(L, axis, counts) != 0)
            return -1;
    }
    a->base = a->tick + SETUP_PERIODS;
    for (uint32_t j = 0; j < SETUP_PERIODS; j++) {
        if (send_setpoint(L, axis, (long)j) != 0 || exchange_off(L, axis, counts) != 0) return -1;
    }
    return send_request(a, BR_LINK_MSG_ARM, NULL, 0);
}

/* br_circle_remote_t's step */
static int pil_step(void *user, int axis, long k, int32_t counts, br_circle_remote_out_t *out)
{
    br_pil_loop_t *L = user;
    br_link_pil_out_t o;
    if (k == 0) {
        if (before_arm(L, axis, counts) != 0) return -1;
    } else if (k - 1 + (long)SETUP_PERIODS <= L->n) {
        if (send_setpoint(L, axis, k - 1 + (long)SETUP_PERIODS) != 0) return -1;
    }
    if (exchange(L, axis, counts, &o) != 0) return -1;
    *out = (br_circle_remote_out_t){o.port_duty, o.s.status, o.s.fault, o.s.duty, o.s.F_hat_N, (o.s.flags >> 1) & 1};
    if (L->duty[axis] != NULL && k <= L->n) L->duty[axis][k] = o.s.duty;
    /* the user's figure: the image's own counts against the commanded circle, both axes' once
     * the period's y is in (a period that faulted has no sample: br_circle's rule) */
    L->meas_counts[axis] = o.s.counts;
    if (axis == 1 && o.s.status >= 0 && out->fault == 0) br_pil_meas_add(&L->meas, L->meas_counts[0], L->meas_counts[1]);
    return 0;
}

/* after a run: disarm and fault reset, then periods at rest at the last count until the link's
 * backlog is taken and the outputs are off (a fault's braking ramp ends with them off) */
static int after_run(br_pil_loop_t *L, int axis)
{
    br_pil_axis_t *a = &L->ax[axis];
    if (send_request(a, BR_LINK_MSG_DISARM, NULL, 0) != 0 || send_request(a, BR_LINK_MSG_FAULT_RESET, NULL, 0) != 0)
        return -1;
    br_link_pil_out_t o = {0};
    for (uint32_t j = 0; j < AFTER_PERIODS || o.on != 0u; j++) {
        if (j == AFTER_MAX_PERIODS) {
            fprintf(stderr, "%s: axis %d: the outputs still on %u periods after the disarm\n", TOOL, axis, j);
            return -1;
        }
        if (exchange(L, axis, a->last_counts, &o) != 0) return -1;
    }
    return 0;
}

/* every write answered, with status 0 and the value written, in order (R comes back from rad^2:
 * v * rpc^2 / rpc^2 in float, within a relative 1e-6) */
static int params_reached(const br_pil_loop_t *L, const br_pil_axis_t *a)
{
    if (a->n_replies != L->n_params) return 0;
    for (int j = 0; j < L->n_params; j++) {
        const double w = (double)L->params[j].value, r = (double)a->reply_value[j];
        if (a->reply_id[j] != L->params[j].id || a->reply_status[j] != 0 || !(fabs(r - w) <= 1e-6 * fabs(w)))
            return 0;
    }
    return 1;
}

void br_pil_meas_init(br_pil_meas_t *m, const br_circle_cfg_t *c)
{
    *m = (br_pil_meas_t){c->plant.lead_mprad * 2.0 * M_PI / c->plant.counts_per_rev, c->radius_m, 0.0, 0.0, 0};
}

void br_pil_meas_add(br_pil_meas_t *m, int32_t x_counts, int32_t y_counts)
{
    const double x = ((double)x_counts + 0.5) * m->m_per_count, y = ((double)y_counts + 0.5) * m->m_per_count;
    const double e = hypot(x, y) - m->radius_m;
    m->sum2 += e * e;
    m->emax = fmax(m->emax, fabs(e));
    m->n++;
}

double br_pil_meas_rms(const br_pil_meas_t *m)
{
    return m->n > 0 ? sqrt(m->sum2 / (double)m->n) : 0.0;
}

int br_pil_loop_open(br_pil_loop_t *L, const char *qemu, const char *image, const char *est, const char *work,
                     double timeout_s)
{
    memset(L, 0, sizeof *L);
    L->timeout_s = timeout_s;
    L->keep = work != NULL;
    for (int i = 0; i < 2; i++) L->ax[i].link_in = L->ax[i].link_out = L->ax[i].plant_in = L->ax[i].plant_out = -1;
    signal(SIGPIPE, SIG_IGN);
    stop_install();
    for (int i = 0; i < 2; i++) {
        char dir[512];
        if (stopped(i)) return -1;
        if (work != NULL) {
            snprintf(dir, sizeof dir, "%s/%s_axis%d", work, est, i);
            if (mkdir(dir, 0700) != 0 && errno != EEXIST) {
                fprintf(stderr, "%s: cannot make %s: %s\n", TOOL, dir, strerror(errno));
                return -1;
            }
        } else {
            snprintf(dir, sizeof dir, "/tmp/br_pil_XXXXXX");
            if (mkdtemp(dir) == NULL) return -1;
        }
        L->started = i + 1;
        if (axis_start(&L->ax[i], qemu, image, est, dir) != 0) return -1;
    }
    return 0;
}

int br_pil_loop_run(br_pil_loop_t *L, const br_circle_cfg_t *c, const br_pil_param_t *params, int n_params,
                    float *duty[2], br_pil_run_t *out)
{
    if (n_params < 0 || n_params > BR_PIL_PARAMS_MAX || L->started != 2) return -1;
    L->c = c;
    L->n = lround(c->duration_s / c->dt_s);
    L->params = params;
    L->n_params = n_params;
    L->duty[0] = duty != NULL ? duty[0] : NULL;
    L->duty[1] = duty != NULL ? duty[1] : NULL;
    br_pil_meas_init(&L->meas, c);
    const br_circle_remote_t remote = {pil_step, L};
    const double t0 = now_s();
    if (br_circle_run_remote(c, &remote, NULL, NULL, &out->res) < 0) return -1;
    for (int i = 0; i < 2; i++)
        if (after_run(L, i) != 0) return -1;
    if (stopped(0)) return -1; /* a run the signal reached only in its last wait is no result either */
    out->wall_s = now_s() - t0;
    out->meas_rms_m = br_pil_meas_rms(&L->meas);
    out->meas_max_m = L->meas.emax;
    out->params_ok = params_reached(L, &L->ax[0]) && params_reached(L, &L->ax[1]);
    return 0;
}

void br_pil_loop_close(br_pil_loop_t *L)
{
    for (int i = 0; i < L->started; i++) axis_stop(&L->ax[i], L->keep);
    L->started = 0;
    stop_restore();
}

int br_pil_loop_stopped(void)
{
    return (int)stop_signal;
}

int br_pil_loop_end(int rc)
{
    if (stop_signal == 0) return rc;
    /* the signal's own action now (the handlers were restored at close): the exit status a killed tool has */
    signal((int)stop_signal, SIG_DFL);
    raise((int)stop_signal);
    return 128 + (int)stop_signal; /* a signal whose default action did not end the process */
}
