/* SPDX-License-Identifier: Apache-2.0 */
/* make bench: host cost of the friction estimators, and their memory.
 *
 * 1. Records a realistic input: the x axis of the thesis circle (A sin(2 pi t / 8),
 *    A = 1e-4 m, 8 s) on the reference plant in closed loop, H-inf + PF at
 *    1.5 ms with the default PF (br_circle_pf_cfg_default, m = 1500), and
 *    H-inf + UKF at 1 ms (br_circle_ukf_cfg_default). A wrapper around the
 *    estimator records what it was given (counts, frac, u_{k-1}), what it
 *    returned (F_hat) and the plant's true friction at t_k.
 * 2. Replays each recording into a fresh filter (br_pf_step / br_ukf_step on
 *    the recorded inputs): one untimed warm-up replay, then --reps (PF) /
 *    --ukf-reps (UKF) replays whose steps k >= 1 (the priming step k = 0 has
 *    no prediction) are timed as one block with clock_gettime(CLOCK_MONOTONIC)
 *    and with the thread's CPU clock: block time / (steps m) = ns per
 *    particle-step; reported: the median over replays and its spread (min,
 *    max). One more replay times every step on its own (MONOTONIC) for the
 *    latency distribution (p50, p99, max). Every replay must reproduce the
 *    in-loop estimates bit for bit (the filters are deterministic).
 * 3. Memory: sizeof(br_pf_t) at BR_PF_MAX_PARTICLES and the part of it that
 *    m = 1500 uses, sizeof(br_ukf_t), sizeof(br_noise_table) (ROM).
 *
 * Usage: br_bench [--json FILE] [--record FILE] [--reps N] [--ukf-reps N]
 *   --record  writes the PF recording as CSV (for sim/bench/pf_numpy.py): a
 *             "# pf_cfg {...}" line with the filter's configuration, a header
 *             line, then k,counts,frac,u_prev_Nm,fnl_true_N,fhat_c_N,status. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "hal_sim/br_hal_sim.h"
#include "bristle_gen/est/br_noise_table.h"
#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_app.h"
#include "tool/br_args.h"
#include "tool/br_tool_limits.h"
#include "tool/br_outfile.h"

#define TOOL "br_bench"

#define BR_PI 3.14159265358979323846

#ifdef NDEBUG
#define BENCH_NDEBUG 1
#else
#define BENCH_NDEBUG 0
#endif
#ifndef BR_BENCH_BUILD
#define BR_BENCH_BUILD "unknown"
#endif

/* ---- recording -------------------------------------------------------- */

typedef struct {
    long n, cap;
    int32_t *counts;
    float *frac, *u_prev, *fhat;
    double *fnl_true;
    int *status;
} rec_t;

static int rec_push(rec_t *r, const br_meas_t *y, float u, float fhat, double fnl, int st)
{
    if (r->n == r->cap) {
        long cap = r->cap ? 2 * r->cap : 4096;
        int32_t *c = realloc(r->counts, (size_t)cap * sizeof *c);
        if (c) r->counts = c;
        float *f = realloc(r->frac, (size_t)cap * sizeof *f);
        if (f) r->frac = f;
        float *u2 = realloc(r->u_prev, (size_t)cap * sizeof *u2);
        if (u2) r->u_prev = u2;
        float *h = realloc(r->fhat, (size_t)cap * sizeof *h);
        if (h) r->fhat = h;
        double *t = realloc(r->fnl_true, (size_t)cap * sizeof *t);
        if (t) r->fnl_true = t;
        int *s = realloc(r->status, (size_t)cap * sizeof *s);
        if (s) r->status = s;
        if (!c || !f || !u2 || !h || !t || !s) return -1;
        r->cap = cap;
    }
    r->counts[r->n] = y->counts;
    r->frac[r->n] = y->frac;
    r->u_prev[r->n] = u;
    r->fhat[r->n] = fhat;
    r->fnl_true[r->n] = fnl;
    r->status[r->n] = st;
    r->n++;
    return 0;
}

static void rec_free(rec_t *r)
{
    free(r->counts);
    free(r->frac);
    free(r->u_prev);
    free(r->fhat);
    free(r->fnl_true);
    free(r->status);
    memset(r, 0, sizeof *r);
}

/* Estimator wrapper: passes the call on and records it. */
typedef struct {
    br_est_t inner;
    const br_plant_t *plant;
    rec_t *rec;
    int failed;
} rec_est_t;

static br_status_t rec_est_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    rec_est_t *r = ctx;
    br_status_t st = r->inner.step(r->inner.ctx, y, u_prev_Nm, F_hat_N);
    if (rec_push(r->rec, y, u_prev_Nm, *F_hat_N, r->plant->fnl_N, (int)st) != 0) r->failed = 1;
    return st;
}

/* One axis (x: phase 0) of the thesis circle c in closed loop with the given
 * estimator, recorded into rec. 0, or -1 with a message. */
static int record_axis(const br_circle_cfg_t *c, br_est_t est, rec_t *rec)
{
    br_plant_t plant;
    br_hal_sim_t port;
    br_hal_t hal;
    br_app_t app;
    const br_plant_state_t x0 = {0.0, 0.0, 0.0};
    if (br_plant_init(&plant, &c->plant, &x0) != 0) return -1;
    if (br_hal_sim_init(&port, &plant, c->dt_s, &hal) != BR_OK) return -1;
    const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(c);
    rec_est_t wrap = {est, &plant, rec, 0};
    const br_est_t e = {&wrap, rec_est_step, NULL, NULL};
    const br_app_cfg_t ac = {&cc, BR_APP_EST_EXTERN, NULL, NULL, &e,
                             br_app_guard_cfg(cc.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
                             br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE)};
    if (br_app_init(&app, &ac, &hal, NULL) != BR_OK || br_app_arm(&app) != BR_OK) {
        fprintf(stderr, "br_bench: application init failed\n");
        return -1;
    }
    const double L = c->plant.lead_mprad, rpc = 2.0 * BR_PI / c->plant.counts_per_rev;
    const double w = 2.0 * BR_PI / c->period_s;
    const long n = lround(c->duration_s / c->dt_s);
    for (long k = 0; k <= n; k++) {
        const double t = (double)k * c->dt_s;
        uint32_t tick;
        hal.tick_wait(hal.ctx, &tick);
        /* reference in counts + fraction and its velocity, as in sim/lib/circle */
        const double counts = c->radius_m * sin(w * t) / L / rpc, whole = floor(counts);
        const br_ref_t r = {(int32_t)whole, (float)(counts - whole), (float)(c->radius_m * w * cos(w * t) / L)};
        const br_status_t st = br_app_step(&app, &r);
        if (wrap.failed) {
            fprintf(stderr, "br_bench: out of memory while recording\n");
            return -1;
        }
        if (BR_FAILED(st)) {
            fprintf(stderr, "br_bench: axis step failed at t = %.4f s (status %d)\n", t, (int)st);
            return -1;
        }
    }
    return 0;
}

/* ---- timing ----------------------------------------------------------- */

static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + (int64_t)ts.tv_nsec;
}

/* CPU time of this thread: unlike CLOCK_MONOTONIC it stops while the thread
 * is descheduled, so it is the less noisy figure on a shared host */
static int64_t cpu_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + (int64_t)ts.tv_nsec;
}

/* mean cost of one now_ns() call: each timed step includes about one */
static double timer_overhead_ns(void)
{
    const int n = 200000;
    int64_t sink = 0;
    const int64_t t0 = now_ns();
    for (int i = 0; i < n; i++) sink += now_ns() & 1;
    const int64_t t1 = now_ns();
    return (double)(t1 - t0) / (double)n + 0.0 * (double)sink;
}

static int cmp_double(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* q-quantile (0..1) of v[0..n-1], sorting v in place (nearest rank). */
static double quantile(double *v, long n, double q)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    long i = lround(q * (double)(n - 1));
    return v[i < 0 ? 0 : (i >= n ? n - 1 : i)];
}

static double median_of(const double *v, int n)
{
    double s[256];
    int k = n < 256 ? n : 256;
    memcpy(s, v, (size_t)k * sizeof *s);
    qsort(s, (size_t)k, sizeof *s, cmp_double);
    return (k % 2) ? s[k / 2] : 0.5 * (s[k / 2 - 1] + s[k / 2]);
}

typedef struct {
    int reps;
    double per_rep_ns[256]; /* mean ns per step of each timed replay (CLOCK_MONOTONIC) */
    double per_rep_cpu_ns[256]; /* the same in thread CPU time */
    double step_p50_ns, step_p99_ns, step_max_ns;
    long steps_timed;       /* per replay */
    long mismatches;        /* estimates differing from the in-loop ones, over all replays */
    long outliers, errors;  /* statuses of the last replay */
    double fhat_rms_err_N;  /* replayed F_hat against the true friction, k >= 1 */
} timing_t;

typedef br_status_t (*init_fn)(void *state, const void *cfg);
typedef br_status_t (*step_fn)(void *state, const br_meas_t *y, float u, float *F_hat_N);

static br_status_t pf_init_w(void *s, const void *c) { return br_pf_init(s, c); }
static br_status_t pf_step_w(void *s, const br_meas_t *y, float u, float *F)
{
    br_pf_t *pf = s;
    br_status_t st = br_pf_step(pf, y, u);
    if (!BR_FAILED(st)) *F = pf->est.F_hat_N;
    return st;
}
static br_status_t ukf_init_w(void *s, const void *c) { return br_ukf_init(s, c); }
static br_status_t ukf_step_w(void *s, const br_meas_t *y, float u, float *F)
{
    br_ukf_t *ukf = s;
    br_status_t st = br_ukf_step(ukf, y, u);
    if (!BR_FAILED(st)) *F = ukf->est.F_hat_N;
    return st;
}

/* One replay of rec into a fresh filter. With lat == NULL the steps k >= 1
 * are timed as one block (*wall_ns, *cpu_ns: per step); otherwise each step
 * k >= 1 is timed on its own into lat[k - 1]. fhat_out (rec->n) receives the
 * estimates; the counts of statuses and of estimates differing from the
 * in-loop ones are added to tm. */
static int replay(void *state, const void *cfg, init_fn init, step_fn step, const rec_t *rec, double *lat,
                  double *wall_ns, double *cpu_ns_out, timing_t *tm, float *fhat_out)
{
    const long n = rec->n;
    if (init(state, cfg) != BR_OK) {
        fprintf(stderr, "br_bench: filter init failed\n");
        return -1;
    }
    float F = 0.0f;
    long nout = 0, nerr = 0, mism = 0;
    int64_t w0 = 0, c0 = 0;
    for (long k = 0; k < n; k++) {
        const br_meas_t y = {rec->counts[k], rec->frac[k]};
        if (k == 1 && lat == NULL) {
            c0 = cpu_ns();
            w0 = now_ns();
        }
        br_status_t st;
        if (lat != NULL && k > 0) {
            const int64_t t0 = now_ns();
            st = step(state, &y, rec->u_prev[k], &F);
            lat[k - 1] = (double)(now_ns() - t0);
        } else {
            st = step(state, &y, rec->u_prev[k], &F);
        }
        nout += (st == BR_W_OUTLIER);
        nerr += (BR_FAILED(st));
        mism += (F != rec->fhat[k]);
        fhat_out[k] = F;
    }
    if (lat == NULL) {
        const int64_t w1 = now_ns(), c1 = cpu_ns();
        *wall_ns = (double)(w1 - w0) / (double)(n - 1);
        *cpu_ns_out = (double)(c1 - c0) / (double)(n - 1);
    }
    tm->mismatches += mism;
    tm->outliers = nout;
    tm->errors = nerr;
    return 0;
}

/* One untimed warm-up replay, reps replays timed as blocks (mean cost per
 * step, wall and CPU time), then one replay timing every step (latency
 * distribution; a step then also carries about one clock read). */
static int time_replays(void *state, const void *cfg, init_fn init, step_fn step, const rec_t *rec, int reps,
                        timing_t *tm, float *fhat_out)
{
    const long n = rec->n;
    double *lat = malloc((size_t)(n - 1) * sizeof *lat);
    if (!lat) return -1;
    memset(tm, 0, sizeof *tm);
    tm->reps = reps;
    tm->steps_timed = n - 1;
    double w, c;
    int bad = replay(state, cfg, init, step, rec, NULL, &w, &c, tm, fhat_out) != 0;
    for (int r = 0; r < reps && !bad; r++) {
        bad = replay(state, cfg, init, step, rec, NULL, &tm->per_rep_ns[r], &tm->per_rep_cpu_ns[r], tm, fhat_out) != 0;
    }
    bad = bad || replay(state, cfg, init, step, rec, lat, &w, &c, tm, fhat_out) != 0;
    if (bad) {
        free(lat);
        return -1;
    }
    tm->step_p50_ns = quantile(lat, n - 1, 0.5);
    tm->step_p99_ns = quantile(lat, n - 1, 0.99);
    tm->step_max_ns = lat[n - 2];
    free(lat);
    double s2 = 0.0;
    for (long k = 1; k < n; k++) {
        const double e = (double)fhat_out[k] - rec->fnl_true[k];
        s2 += e * e;
    }
    tm->fhat_rms_err_N = sqrt(s2 / (double)(n - 1));
    return 0;
}

static void rep_stats(const double *per_rep, int reps, double scale, double *med, double *mn, double *mx)
{
    *med = median_of(per_rep, reps) * scale;
    *mn = *mx = per_rep[0] * scale;
    for (int r = 1; r < reps; r++) {
        const double v = per_rep[r] * scale;
        if (v < *mn) *mn = v;
        if (v > *mx) *mx = v;
    }
}

/* ---- machine ---------------------------------------------------------- */

static void cpu_model(char *buf, size_t len)
{
    snprintf(buf, len, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "model name", 10) == 0) {
            const char *p = strchr(line, ':');
            if (p) {
                p++;
                while (*p == ' ' || *p == '\t') p++;
                snprintf(buf, len, "%s", p);
                buf[strcspn(buf, "\n")] = '\0';
            }
            break;
        }
    }
    fclose(f);
}

/* 1-minute load average (-1 if unknown): other processes on the CPUs skew the timings */
static double loadavg1(void)
{
    double v = -1.0;
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) {
        if (fscanf(f, "%lf", &v) != 1) v = -1.0;
        fclose(f);
    }
    return v;
}

/* s as a JSON string body (quotes and backslashes escaped, controls dropped) */
static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') fputc('\\', f);
        if ((unsigned char)*s >= 0x20) fputc(*s, f);
    }
    fputc('"', f);
}

/* FNV-1a 64 over the table's bytes: pf_numpy.py checks its copy against it */
static uint64_t fnv1a(const void *p, size_t n)
{
    const unsigned char *b = p;
    uint64_t h = 14695981039346656037ull;
    for (size_t i = 0; i < n; i++) {
        h ^= b[i];
        h *= 1099511628211ull;
    }
    return h;
}

static void json_f4(FILE *f, const float *v)
{
    fprintf(f, "[%.9g, %.9g, %.9g, %.9g]", (double)v[0], (double)v[1], (double)v[2], (double)v[3]);
}

/* The PF configuration, every float exact (%.9g round-trips float32). */
static void json_pf_cfg(FILE *f, const br_pf_cfg_t *c)
{
    const br_model_cfg_t *m = &c->est.model;
    fprintf(f,
            "{\"dt_s\": %.9g, \"J_kgm2\": %.9g, \"M_kg\": %.9g, \"lead_mprad\": %.9g, \"sigma2_Nspm\": %.9g, "
            "\"sigma0_Npm\": %.9g, \"sigma1_Nspm\": %.9g, \"Fc_N\": %.9g, \"Fs_N\": %.9g, \"vs_mps\": %.9g, "
            "\"n_particles\": %u, \"q_var\": ",
            (double)m->dt_s, (double)m->J_kgm2, (double)m->M_kg, (double)m->lead_mprad, (double)m->sigma2_Nspm,
            (double)m->lugre.sigma0_Npm, (double)m->lugre.sigma1_Nspm, (double)m->lugre.Fc_N,
            (double)m->lugre.Fs_N, (double)m->lugre.vs_mps, (unsigned)c->n_particles);
    json_f4(f, c->est.q_var);
    fprintf(f, ", \"r_var_rad2\": %.9g, \"gp0_N\": %.9g, \"x0_std\": ", (double)c->est.r_var_rad2, (double)c->est.gp0_N);
    json_f4(f, c->x0_std);
    fprintf(f,
            ", \"gp_min_N\": %.9g, \"gp_max_N\": %.9g, \"outlier_sigma\": %.9g, \"reanchor_after\": %u, "
            "\"rad_per_count\": %.9g, \"noise_len\": %u, \"noise_skip\": %u, \"noise_fnv1a64\": \"%016llx\", "
            "\"adapt\": {\"nis_ref\": %.9g, \"alpha\": %.9g, \"max_scale\": %.9g}, \"outlier_transient_rad\": %.9g",
            (double)c->est.gp_min_N, (double)c->est.gp_max_N, (double)c->est.outlier_sigma, (unsigned)c->est.reanchor_after,
            (double)c->est.rad_per_count, (unsigned)c->noise_len, (unsigned)c->noise_skip,
            (unsigned long long)fnv1a(c->noise, (size_t)c->noise_len * sizeof *c->noise), (double)c->adapt.nis_ref,
            (double)c->adapt.alpha, (double)c->adapt.max_scale, (double)c->est.outlier_transient_rad);
    /* the actuator delay and its identification (docs/modules/dlyid.md) */
    const br_dlyid_cfg_t *d = &c->est.delay_id;
    fprintf(f,
            ", \"delay_s\": %.9g, \"delay_id\": {\"n_cand\": %u, \"step_s\": %.9g, \"q_force_N2ps\": %.9g, "
            "\"memory_s\": %.9g, \"warmup_s\": %.9g, \"switch_ratio\": %.9g, \"steady_after_s\": %.9g, "
            "\"steady_memory_s\": %.9g, \"steady_switch_ratio\": %.9g}, \"load\": {\"q_N2\": %.9g, \"max_N\": %.9g}}",
            (double)m->causes.delay_s, (unsigned)d->n_cand, (double)d->step_s, (double)d->q_force_N2ps,
            (double)d->memory_s, (double)d->warmup_s, (double)d->switch_ratio, (double)d->steady_after_s,
            (double)d->steady_memory_s, (double)d->steady_switch_ratio, (double)c->load.q_N2, (double)c->load.max_N);
}

/* the recording into f (a br_outfile's temporary file, docs/tools.md) */
static void write_record(FILE *f, const char *plant, const br_pf_cfg_t *cfg, const rec_t *rec, const float *fhat)
{
    fprintf(f, "# br_bench PF recording: x axis of the thesis circle on the %s plant, H-inf + PF in closed loop\n# pf_cfg ",
            plant);
    json_pf_cfg(f, cfg);
    fprintf(f, "\nk,counts,frac,u_prev_Nm,fnl_true_N,fhat_c_N,status\n");
    for (long k = 0; k < rec->n; k++) {
        fprintf(f, "%ld,%ld,%.9g,%.9g,%.9g,%.9g,%d\n", k, (long)rec->counts[k], (double)rec->frac[k],
                (double)rec->u_prev[k], rec->fnl_true[k], (double)fhat[k], rec->status[k]);
    }
}

/* ---- the PF's two paths, its cost against m, the demo per controller ---- */

/* median thread-CPU ns per particle-step of reps replays of rec into a PF of
 * configuration c (one untimed warm-up); estimates not compared (m may
 * differ from the recording's) */
static int pf_cpu_per_particle(br_pf_t *pf, const br_pf_cfg_t *c, const rec_t *rec, int reps, float *fhat, double *out)
{
    timing_t tm;
    memset(&tm, 0, sizeof tm);
    double w, per[256];
    if (replay(pf, c, pf_init_w, pf_step_w, rec, NULL, &w, &per[0], &tm, fhat) != 0) return -1;
    for (int r = 0; r < reps; r++) {
        if (replay(pf, c, pf_init_w, pf_step_w, rec, NULL, &w, &per[r], &tm, fhat) != 0) return -1;
    }
    *out = median_of(per, reps) / (double)c->n_particles;
    return 0;
}

/* the particle counts of the scaling table */
static const uint32_t bench_m[] = {100u, 250u, 500u, 1000u, 1500u, 2048u};
#define BENCH_NM (sizeof bench_m / sizeof bench_m[0])

/* thread CPU time of one whole demo run (both axes, 8 s) per controller */
static const struct {
    br_circle_ctrl_t ctrl;
    const char *name;
    uint32_t scalar_path;
} bench_demo[] = {{BR_CTRL_HINF_ONLY, "hinf_only", 0u}, {BR_CTRL_HINF_UKF, "hinf_ukf", 0u},
                  {BR_CTRL_HINF_PF, "hinf_pf", 0u},    {BR_CTRL_HINF_PF, "hinf_pf_scalar", 1u},
                  {BR_CTRL_HINF_TRUE, "true_friction", 0u}};
#define BENCH_ND (sizeof bench_demo / sizeof bench_demo[0])

static int demo_cpu_s(size_t i, double *out)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(bench_demo[i].ctrl);
    c.pf.scalar_path = bench_demo[i].scalar_path;
    br_circle_result_t res;
    const int64_t c0 = cpu_ns();
    if (br_circle_run(&c, NULL, NULL, &res) != 0) return -1;
    *out = (double)(cpu_ns() - c0) * 1e-9;
    return 0;
}

static void json_timing_pf(FILE *f, const char *key, const br_circle_cfg_t *cpf, uint32_t m, const timing_t *t,
                           int reps, double med, double mn, double mx, double cmed, double cmin, double cmax)
{
    fprintf(f,
            "  \"%s\": {\"input\": \"x axis of the thesis circle, H-inf + PF closed loop\", \"dt_s\": %.9g, "
            "\"n_particles\": %u, \"steps_timed\": %ld, \"reps\": %d,\n"
            "    \"ns_per_particle_step\": {\"median\": %.3f, \"min\": %.3f, \"max\": %.3f, \"per_rep\": [",
            key, cpf->dt_s, m, t->steps_timed, reps, med, mn, mx);
    for (int r = 0; r < reps; r++) fprintf(f, "%s%.3f", r ? ", " : "", t->per_rep_ns[r] / (double)m);
    fprintf(f, "]},\n    \"cpu_ns_per_particle_step\": {\"median\": %.3f, \"min\": %.3f, \"max\": %.3f},\n", cmed,
            cmin, cmax);
    fprintf(f,
            "    \"step_us\": {\"median_rep_mean\": %.3f, \"p50\": %.3f, \"p99\": %.3f, \"max\": %.3f},\n"
            "    \"replay_mismatches\": %ld, \"fhat_rms_err_N\": %.6f, \"outlier_steps\": %ld, "
            "\"error_steps\": %ld},\n",
            med * (double)m * 1e-3, t->step_p50_ns * 1e-3, t->step_p99_ns * 1e-3, t->step_max_ns * 1e-3, t->mismatches,
            t->fhat_rms_err_N, t->outliers, t->errors);
}

/* --plant's circle configuration for the controller into c (NULL: the name's check only);
 * -1 for a name that is none of the three */
static int plant_cfg(const char *name, br_circle_ctrl_t ctrl, br_circle_cfg_t *c)
{
    br_circle_cfg_t (*const make[])(br_circle_ctrl_t) = {br_circle_cfg_thesis, br_circle_cfg_realistic,
                                                          br_circle_cfg_hardware_like};
    static const char *const names[] = {"thesis", "realistic", "hardware_like"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (strcmp(name, names[i]) == 0) {
            if (c) *c = make[i](ctrl);
            return 0;
        }
    }
    return -1;
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--json FILE] [--record FILE] [--reps N] [--ukf-reps N] [--plant thesis|realistic|hardware_like] [--thesis-gate]\n"
            "       [--plant-delay S] [--pf-load Q_N2_PER_S] [--pf-gate SIGMA]\n" BR_ARGS_COMMON_USAGE
            "  --json FILE         the figures as JSON (make bench: out/bench/bench.json)\n"
            "  --record FILE       the replayed stream's per-step record (CSV)\n"
            "  --reps N            repetitions of each PF timing, 1 .. 256 (default 7)\n"
            "  --ukf-reps N        repetitions of each UKF timing, 1 .. 256 (default 21)\n"
            "  --plant P           the recorded closed loop's plant: thesis (the estimators' own model,\n"
            "                      default), realistic (the demo's realistic plant, docs/demo.md) or\n"
            "                      hardware_like (the demo's Maxwell-slip plant, docs/demo.md)\n"
            "  --thesis-gate       the filters' outlier gate without the machine's transient term (eq. G1):\n"
            "                      the realistic plant's outliers then re-anchor the PF (for pf_numpy.py --check)\n"
            "  --plant-delay S     an actuator dead time in the recorded loop's plant, 0 .. 0.1 s (default 0):\n"
            "                      the delay identification finds it (for pf_numpy.py --check)\n"
            "  --pf-load Q         the recorded PF with its shared external force, random walk Q N^2/s\n"
            "                      (0 .. 1e9, 0: off; default the machine's; docs/modules/pf.md; for pf_numpy.py --check)\n"
            "  --pf-gate SIGMA     the recorded PF's outlier gate, sigmas (1 .. 1000; a narrow one gates steps:\n"
            "                      with --pf-load they are re-acquired as a load and undone, for pf_numpy.py --check)\n",
            argv0, argv0);
    return 2;
}

int main(int argc, char **argv)
{
    const char *json_path = NULL, *rec_path = NULL;
    int reps = 7, ukf_reps = 21, thesis_gate = 0;
    double plant_delay_s = 0.0, pf_load = -1.0, pf_gate = 0.0;
    const char *plant = "thesis";
    static const struct option opts[] = {{"json", required_argument, NULL, 'j'},
                                         {"record", required_argument, NULL, 'r'},
                                         {"reps", required_argument, NULL, 'n'},
                                         {"ukf-reps", required_argument, NULL, 'u'},
                                         {"plant", required_argument, NULL, 'p'},
                                         {"thesis-gate", no_argument, NULL, 'g'},
                                         {"plant-delay", required_argument, NULL, 'd'},
                                         {"pf-load", required_argument, NULL, 'L'},
                                         {"pf-gate", required_argument, NULL, 'G'},
                                         {NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *v;
    for (int o; (o = br_args_next(&p, opts, &v)) != BR_ARGS_END;) {
        int bad = 0;
        long n = 0;
        switch (o) {
        case 'j': json_path = v; break;
        case 'r': rec_path = v; break;
        case 'n':
            bad = br_arg_long(TOOL, p.opt, v, 1, 256, &n);
            if (!bad) reps = (int)n;
            break;
        case 'u':
            bad = br_arg_long(TOOL, p.opt, v, 1, 256, &n);
            if (!bad) ukf_reps = (int)n;
            break;
        case 'p':
            plant = v;
            if (plant_cfg(v, BR_CTRL_HINF_PF, NULL) != 0) {
                fprintf(stderr, "%s: --plant: '%s' is none of thesis, realistic, hardware_like\n", TOOL, v);
                bad = 1;
            }
            break;
        case 'g': thesis_gate = 1; break;
        case 'd': bad = br_arg_double(TOOL, p.opt, v, 0.0, BR_PLANT_DELAY_MAX_S, &plant_delay_s); break;
        case 'L': bad = br_arg_double(TOOL, p.opt, v, 0.0, 1.0e9, &pf_load); break;
        case 'G': bad = br_arg_double(TOOL, p.opt, v, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA, &pf_gate); break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return usage(argv[0], stderr);
    }

    /* the outputs: checked before the run, written to temporary files, renamed when the run succeeded */
    br_outfile_t jout = {0}, rout = {0};
    if (json_path && br_outfile_open(&jout, TOOL, json_path) != 0) return 1;
    if (rec_path && br_outfile_open(&rout, TOOL, rec_path) != 0) {
        br_outfile_discard(&jout);
        return 1;
    }
    char cpu[256];
    cpu_model(cpu, sizeof cpu);
    const long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    const double load0 = loadavg1();
    printf("bench: %s, %ld CPUs online, load average %.2f; %s build (%s), gcc %s\n", cpu, ncpu, load0,
           BENCH_NDEBUG ? "release" : "NOT a release", BR_BENCH_BUILD, __VERSION__);
    const double tovh = timer_overhead_ns();
    printf("bench: clock_gettime(CLOCK_MONOTONIC) costs %.1f ns per call (read per step only in the latency replay)\n", tovh);
    if (!BENCH_NDEBUG) printf("bench: warning: built without NDEBUG, timings are not representative\n");

    br_pf_t *pf = calloc(1, sizeof *pf);
    br_ukf_t *ukf = calloc(1, sizeof *ukf);
    rec_t rpf = {0}, rukf = {0};
    float *fhat_pf = NULL, *fhat_ukf = NULL, *fhat_tmp = NULL;
    int rc = 1;
    if (!pf || !ukf) goto done;

    /* 1. recordings */
    br_circle_cfg_t cpf, cukf;
    (void)plant_cfg(plant, BR_CTRL_HINF_PF, &cpf);
    (void)plant_cfg(plant, BR_CTRL_HINF_UKF, &cukf);
    cpf.plant.delay_s = plant_delay_s;
    br_circle_use_pf_load(&cpf, pf_load);
    br_circle_use_pf_gate(&cpf, pf_gate);
    cukf.plant.delay_s = plant_delay_s;
    if (thesis_gate) {
        cpf.pf.est.outlier_transient_rad = 0.0f;
        cukf.ukf.est.outlier_transient_rad = 0.0f;
    }
    if (br_pf_init(pf, &cpf.pf) != BR_OK || br_ukf_init(ukf, &cukf.ukf) != BR_OK) {
        fprintf(stderr, "br_bench: filter init failed\n");
        goto done;
    }
    if (record_axis(&cpf, br_pf_est(pf), &rpf) != 0) goto done;
    if (record_axis(&cukf, br_ukf_est(ukf), &rukf) != 0) goto done;
    fhat_pf = malloc((size_t)rpf.n * sizeof *fhat_pf);
    fhat_ukf = malloc((size_t)rukf.n * sizeof *fhat_ukf);
    if (!fhat_pf || !fhat_ukf) goto done;

    /* 2. timing */
    const uint32_t m = cpf.pf.n_particles;
    timing_t tpf, tukf;
    if (time_replays(pf, &cpf.pf, pf_init_w, pf_step_w, &rpf, reps, &tpf, fhat_pf) != 0) goto done;
    if (time_replays(ukf, &cukf.ukf, ukf_init_w, ukf_step_w, &rukf, ukf_reps, &tukf, fhat_ukf) != 0) goto done;
    double pf_med, pf_min, pf_max, ukf_med, ukf_min, ukf_max;
    double pf_cmed, pf_cmin, pf_cmax, ukf_cmed, ukf_cmin, ukf_cmax;
    rep_stats(tpf.per_rep_ns, reps, 1.0 / (double)m, &pf_med, &pf_min, &pf_max);
    rep_stats(tukf.per_rep_ns, ukf_reps, 1e-3, &ukf_med, &ukf_min, &ukf_max);
    rep_stats(tpf.per_rep_cpu_ns, reps, 1.0 / (double)m, &pf_cmed, &pf_cmin, &pf_cmax);
    rep_stats(tukf.per_rep_cpu_ns, ukf_reps, 1e-3, &ukf_cmed, &ukf_cmin, &ukf_cmax);
    const double pf_step_med_us = pf_med * (double)m * 1e-3;
    /* the scalar reference path on the same recording, in the same run: its
     * replays must reproduce the closed loop's estimates (made by the vector
     * path) bit for bit too */
    br_pf_cfg_t cfg_scalar = cpf.pf;
    cfg_scalar.scalar_path = 1u;
    timing_t tpfs;
    /* (fhat_pf keeps the default path's estimates for the recording; the
     * other runs write theirs into fhat_tmp) */
    fhat_tmp = malloc((size_t)rpf.n * sizeof *fhat_tmp);
    if (!fhat_tmp) goto done;
    if (time_replays(pf, &cfg_scalar, pf_init_w, pf_step_w, &rpf, reps, &tpfs, fhat_tmp) != 0) goto done;
    double pfs_med, pfs_min, pfs_max, pfs_cmed, pfs_cmin, pfs_cmax;
    rep_stats(tpfs.per_rep_ns, reps, 1.0 / (double)m, &pfs_med, &pfs_min, &pfs_max);
    rep_stats(tpfs.per_rep_cpu_ns, reps, 1.0 / (double)m, &pfs_cmed, &pfs_cmin, &pfs_cmax);
    /* cost against m, both paths, and the demo per controller */
    double scale_vec[BENCH_NM], scale_sca[BENCH_NM], demo_s[BENCH_ND];
    for (size_t i = 0; i < BENCH_NM; i++) {
        br_pf_cfg_t c = cpf.pf;
        c.n_particles = bench_m[i];
        if (pf_cpu_per_particle(pf, &c, &rpf, 3, fhat_tmp, &scale_vec[i]) != 0) goto done;
        c.scalar_path = 1u;
        if (pf_cpu_per_particle(pf, &c, &rpf, 3, fhat_tmp, &scale_sca[i]) != 0) goto done;
    }
    for (size_t i = 0; i < BENCH_ND; i++) {
        if (demo_cpu_s(i, &demo_s[i]) != 0) goto done;
    }

    printf("PF recording: x axis of the thesis circle on the %s plant, H-inf + PF in closed loop, dt %.1f ms, %ld steps"
           "%s\n", plant, cpf.dt_s * 1e3, rpf.n, plant_delay_s > 0.0 ? ", an actuator delay in the plant" : "");
    printf("PF  m = %u: %.1f ns per particle-step (median of %d replays of %ld steps; min %.1f, max %.1f)\n", m, pf_med,
           reps, tpf.steps_timed, pf_min, pf_max);
    printf("    in thread CPU time: %.1f ns per particle-step (min %.1f, max %.1f)\n", pf_cmed, pf_cmin, pf_cmax);
    printf("    one step %.1f us (median replay) = %.1f %% of the %.1f ms period; single steps: p50 %.1f us, p99 %.1f us, "
           "max %.1f us\n",
           pf_step_med_us, 100.0 * pf_step_med_us * 1e-6 / cpf.dt_s, cpf.dt_s * 1e3, tpf.step_p50_ns * 1e-3,
           tpf.step_p99_ns * 1e-3, tpf.step_max_ns * 1e-3);
    printf("    replays reproduce the in-loop estimates: %s (%ld mismatches); F_hat RMS error vs true friction "
           "%.4f N; %ld outlier, %ld error steps\n",
           tpf.mismatches ? "NO" : "yes, bit for bit", tpf.mismatches, tpf.fhat_rms_err_N, tpf.outliers, tpf.errors);
    printf("PF scalar reference path (cfg.scalar_path = 1), same recording and run: %.1f ns per particle-step "
           "(median; min %.1f, max %.1f), thread CPU %.1f (min %.1f, max %.1f)\n",
           pfs_med, pfs_min, pfs_max, pfs_cmed, pfs_cmin, pfs_cmax);
    printf("    replays reproduce the in-loop estimates: %s (%ld mismatches)\n",
           tpfs.mismatches ? "NO" : "yes, bit for bit", tpfs.mismatches);
    printf("PF scalar / vector, thread CPU time: %.2fx (wall medians %.2fx)\n", pfs_cmed / pf_cmed, pfs_med / pf_med);
    printf("PF cost against m (thread CPU ns per particle-step, median of 3 replays; us per step at m):\n");
    printf("    %6s %10s %10s %10s %10s\n", "m", "vector", "scalar", "vec us", "sca us");
    for (size_t i = 0; i < BENCH_NM; i++) {
        printf("    %6u %10.1f %10.1f %10.1f %10.1f\n", (unsigned)bench_m[i], scale_vec[i], scale_sca[i],
               scale_vec[i] * bench_m[i] * 1e-3, scale_sca[i] * bench_m[i] * 1e-3);
    }
    printf("demo (br_circle_run, two axes, 8 s simulated, plant included), thread CPU time per controller:\n");
    for (size_t i = 0; i < BENCH_ND; i++) printf("    %-16s %8.3f s\n", bench_demo[i].name, demo_s[i]);
    printf("UKF recording: the same axis, H-inf + UKF in closed loop, dt %.1f ms, %ld steps\n", cukf.dt_s * 1e3,
           rukf.n);
    printf("UKF: %.3f us per step (median of %d replays of %ld steps; min %.3f, max %.3f); single steps: p50 %.3f us, "
           "p99 %.3f us, max %.1f us\n",
           ukf_med, ukf_reps, tukf.steps_timed, ukf_min, ukf_max, tukf.step_p50_ns * 1e-3, tukf.step_p99_ns * 1e-3,
           tukf.step_max_ns * 1e-3);
    printf("    in thread CPU time: %.3f us per step (min %.3f, max %.3f)\n", ukf_cmed, ukf_cmin, ukf_cmax);
    printf("    replays reproduce the in-loop estimates: %s (%ld mismatches); F_hat RMS error vs true friction "
           "%.4f N; %ld outlier, %ld error steps\n",
           tukf.mismatches ? "NO" : "yes, bit for bit", tukf.mismatches, tukf.fhat_rms_err_N, tukf.outliers,
           tukf.errors);

    const double load1 = loadavg1();
    /* 3. memory (host sizes; see docs/bench.md for the Cortex-M7 ones) */
    const size_t per_particle = (sizeof(((br_pf_t *)0)->x) + sizeof(((br_pf_t *)0)->kgp) +
                                 sizeof(((br_pf_t *)0)->fnl) + sizeof(((br_pf_t *)0)->l) +
                                 sizeof(((br_pf_t *)0)->W) + sizeof(((br_pf_t *)0)->idx) +
                                 sizeof(((br_pf_t *)0)->ms)) / /* the element slots, BR_PF_MS_SLOTS / m_max each */
                                BR_PF_MAX_PARTICLES;
    const size_t pf_bytes = sizeof(br_pf_t), pf_fixed = pf_bytes - per_particle * BR_PF_MAX_PARTICLES;
    const size_t pf_used = pf_fixed + per_particle * m;
    printf("RAM: br_pf_t %zu bytes at BR_PF_MAX_PARTICLES = %u (%zu bytes per particle + %zu fixed); "
           "m = %u uses %zu bytes (%.1f %%)\n",
           pf_bytes, (unsigned)BR_PF_MAX_PARTICLES, per_particle, pf_fixed, m, pf_used,
           100.0 * (double)pf_used / (double)pf_bytes);
    printf("     br_ukf_t %zu bytes\n", sizeof(br_ukf_t));
    printf("ROM: br_noise_table %zu bytes (%u float32 samples)\n", sizeof br_noise_table, (unsigned)BR_NOISE_LEN);

    if (rout.f) write_record(rout.f, plant, &cpf.pf, &rpf, fhat_pf);
    if (jout.f) {
        FILE *f = jout.f;
        fprintf(f, "{\n  \"plant\": \"%s\",\n  \"machine\": {\"cpu_model\": ", plant);
        json_str(f, cpu);
        fprintf(f, ", \"cpus_online\": %ld, \"compiler\": ", ncpu);
        json_str(f, "gcc " __VERSION__);
        fprintf(f, ", \"build\": ");
        json_str(f, BR_BENCH_BUILD);
        fprintf(f,
                ", \"ndebug\": %s, \"loadavg1_start\": %.2f, \"loadavg1_end\": %.2f, "
                "\"clock_monotonic_call_ns\": %.1f},\n",
                BENCH_NDEBUG ? "true" : "false", load0, load1, tovh);
        json_timing_pf(f, "pf", &cpf, m, &tpf, reps, pf_med, pf_min, pf_max, pf_cmed, pf_cmin, pf_cmax);
        json_timing_pf(f, "pf_scalar", &cpf, m, &tpfs, reps, pfs_med, pfs_min, pfs_max, pfs_cmed, pfs_cmin, pfs_cmax);
        fprintf(f, "  \"ratio_pf_scalar_over_pf_cpu\": %.3f, \"ratio_pf_scalar_over_pf_wall\": %.3f,\n",
                pfs_cmed / pf_cmed, pfs_med / pf_med);
        fprintf(f, "  \"pf_scaling\": {\"metric\": \"thread CPU ns per particle-step, median of 3 replays\", \"rows\": [");
        for (size_t i = 0; i < BENCH_NM; i++) {
            fprintf(f, "%s\n    {\"m\": %u, \"pf\": %.3f, \"pf_scalar\": %.3f}", i ? "," : "", (unsigned)bench_m[i],
                    scale_vec[i], scale_sca[i]);
        }
        fprintf(f, "]},\n  \"demo_cpu_s\": {");
        for (size_t i = 0; i < BENCH_ND; i++) fprintf(f, "%s\"%s\": %.4f", i ? ", " : "", bench_demo[i].name, demo_s[i]);
        fprintf(f, "},\n");
        fprintf(f,
                "  \"ukf\": {\"input\": \"x axis of the thesis circle, H-inf + UKF closed loop\", \"dt_s\": %.9g, "
                "\"steps_timed\": %ld, \"reps\": %d,\n"
                "    \"us_per_step\": {\"median\": %.4f, \"min\": %.4f, \"max\": %.4f, \"p50\": %.4f, \"p99\": %.4f, "
                "\"max_step\": %.3f},\n"
                "    \"cpu_us_per_step\": {\"median\": %.4f, \"min\": %.4f, \"max\": %.4f},\n"
                "    \"replay_mismatches\": %ld, \"fhat_rms_err_N\": %.6f, \"outlier_steps\": %ld, "
                "\"error_steps\": %ld},\n",
                cukf.dt_s, tukf.steps_timed, ukf_reps, ukf_med, ukf_min, ukf_max, tukf.step_p50_ns * 1e-3,
                tukf.step_p99_ns * 1e-3, tukf.step_max_ns * 1e-3, ukf_cmed, ukf_cmin, ukf_cmax, tukf.mismatches, tukf.fhat_rms_err_N,
                tukf.outliers, tukf.errors);
        fprintf(f,
                "  \"memory_host\": {\"pf_t_bytes\": %zu, \"pf_max_particles\": %u, \"pf_bytes_per_particle\": %zu, "
                "\"pf_fixed_bytes\": %zu, \"pf_used_bytes_at_m\": %zu, \"ukf_t_bytes\": %zu, "
                "\"noise_table_rom_bytes\": %zu, \"noise_len\": %u},\n",
                pf_bytes, (unsigned)BR_PF_MAX_PARTICLES, per_particle, pf_fixed, pf_used, sizeof(br_ukf_t),
                sizeof br_noise_table, (unsigned)BR_NOISE_LEN);
        fprintf(f, "  \"pf_cfg\": ");
        json_pf_cfg(f, &cpf.pf);
        fprintf(f, "\n}\n");
    }
    rc = (tpf.mismatches || tpfs.mismatches || tukf.mismatches || tpf.errors || tukf.errors) ? 1 : 0;
    if (rc) fprintf(stderr, "br_bench: a replay differed from the closed loop or failed\n");
    /* committed only when the run succeeded, the JSON last */
    if (rc == 0 && rout.f && br_outfile_commit(&rout, TOOL) != 0) rc = 1;
    if (rc == 0 && jout.f && br_outfile_commit(&jout, TOOL) != 0) rc = 1;
done:
    br_outfile_discard(&rout);
    br_outfile_discard(&jout);
    free(pf);
    free(ukf);
    free(fhat_pf);
    free(fhat_ukf);
    free(fhat_tmp);
    rec_free(&rpf);
    rec_free(&rukf);
    return rc;
}
