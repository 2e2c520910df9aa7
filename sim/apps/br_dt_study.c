/* SPDX-License-Identifier: Apache-2.0 */
/* Sampling-time study (thesis section 3.3, Fig. 2): offline friction
 * estimation by the PF on a logged H-inf-only circle, at periods
 * dt = 0.5 ... 3.0 ms.
 *
 * The log: the H-inf-only circle run at 0.5 ms (both axes: encoder counts,
 * applied torque, true friction). At dt = N x 0.5 ms the PF sees every N-th
 * count and, as its input, the mean torque over the N sub-periods (the same
 * impulse). Its process-noise variances are the demo's, scaled by dt / 1.5 ms
 * (a fixed continuous-time intensity). Particle count: m = K dt[ms]
 * (--m-per-ms K, thesis K = 1000), or a CPU budget: m = F dt / c (--budget F
 * --cost-ns c: the fraction F of a core, c ns per particle-step), at most
 * BR_PF_MAX_PARTICLES. Each setting runs S times with the ROM table read from
 * S different starting positions (Monte-Carlo realisations). Error: RMS of
 * (F_hat - true f_nl) over both axes after 0.5 s, split into the bias of the
 * seed-mean estimate (discretisation and model error) and the spread of the
 * seeds around it (Monte-Carlo error).
 *
 * Usage: br_dt_study [--m-per-ms K | --budget F --cost-ns c] [--seeds S]
 * Prints one JSON object per dt (one line each). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "circle/br_circle.h"
#include "circle/br_circle_est.h"
#include "bristle_gen/est/br_est_machine.h"
#include "tool/br_args.h"
#include "bristle_gen/machine/br_machine.h"

#define TOOL "br_dt_study"
#define DT0_S 0.5e-3
#define N_DT 6
#define SKIP_S 0.5
#define MAX_SEEDS 16

typedef struct {
    long n, cap;
    int32_t *counts[2];
    double *tau[2], *fnl[2];
} log_t;

static void log_sink(void *user, const br_circle_sample_t *s)
{
    log_t *g = user;
    if (g->n >= g->cap) return;
    for (int a = 0; a < 2; a++) {
        g->counts[a][g->n] = s->counts[a];
        g->tau[a][g->n] = s->duty[a] * BR_MACHINE_TAU_PER_DUTY_NM;
        g->fnl[a][g->n] = s->fnl_N[a];
    }
    g->n++;
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--m-per-ms K | --budget F --cost-ns c] [--seeds S]\n" BR_ARGS_COMMON_USAGE
            "  --m-per-ms K        particles per ms of control period\n"
            "  --budget F          fraction of the period the PF may use, with --cost-ns\n"
            "  --cost-ns c         cost of one particle step, ns\n"
            "  --seeds S           noise seeds per period\n"
            "bounds: K 1e-3 .. 1e6, F 1e-6 .. 1, c 1e-3 .. 1e9 ns, S 2 .. %d\n",
            argv0, argv0, MAX_SEEDS);
    return 2;
}

int main(int argc, char **argv)
{
    double m_per_ms = 1000.0, budget = 0.0, cost_ns = 0.0;
    long seeds = 4;
    static const struct option opts[] = {{"m-per-ms", required_argument, NULL, 'm'},
                                         {"budget", required_argument, NULL, 'b'},
                                         {"cost-ns", required_argument, NULL, 'c'},
                                         {"seeds", required_argument, NULL, 's'},
                                         {NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *v;
    for (int o; (o = br_args_next(&p, opts, &v)) != BR_ARGS_END;) {
        int bad = 0;
        switch (o) {
        case 'm': bad = br_arg_double(TOOL, p.opt, v, 1e-3, 1e6, &m_per_ms); break;
        case 'b': bad = br_arg_double(TOOL, p.opt, v, 1e-6, 1.0, &budget); break;
        case 'c': bad = br_arg_double(TOOL, p.opt, v, 1e-3, 1e9, &cost_ns); break;
        case 's': bad = br_arg_long(TOOL, p.opt, v, 2, MAX_SEEDS, &seeds); break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return usage(argv[0], stderr);
    }
    if ((budget > 0) != (cost_ns > 0)) {
        fprintf(stderr, "%s: --budget and --cost-ns go together\n", TOOL);
        return usage(argv[0], stderr);
    }
    /* 1. the log: H-inf-only circle at 0.5 ms */
    br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    c.dt_s = DT0_S;
    log_t g;
    g.cap = lround(c.duration_s / DT0_S) + 1;
    g.n = 0;
    for (int a = 0; a < 2; a++) {
        g.counts[a] = malloc((size_t)g.cap * sizeof(int32_t));
        g.tau[a] = malloc((size_t)g.cap * sizeof(double));
        g.fnl[a] = malloc((size_t)g.cap * sizeof(double));
        if (!g.counts[a] || !g.tau[a] || !g.fnl[a]) return 1;
    }
    br_circle_result_t res;
    if (br_circle_run(&c, log_sink, &g, &res) != 0) return 1;
    br_pf_t *pf = malloc(sizeof *pf);
    double *fhat = malloc((size_t)g.cap * sizeof(double) * MAX_SEEDS);
    if (!pf || !fhat) return 1;
    /* 2. the PF at each period */
    for (int N = 1; N <= N_DT; N++) {
        const double dt = N * DT0_S;
        double m_real = budget > 0 ? budget * dt / (cost_ns * 1e-9) : m_per_ms * dt * 1e3;
        uint32_t m = (uint32_t)fmin(floor(m_real + 0.5), (double)BR_PF_MAX_PARTICLES);
        const long K = (g.n - 1) / N; /* PF steps: samples k N, k = 0..K */
        double bias2 = 0.0, mc2 = 0.0, tot2 = 0.0;
        long cnt = 0;
        int outliers = 0;
        for (int a = 0; a < 2; a++) {
            for (int s = 0; s < seeds; s++) {
                br_pf_cfg_t pc = br_circle_pf_cfg_tuned((float)dt);
                pc.n_particles = m;
                /* the variances are per step of the PF's period */
                for (int i = 0; i < BR_NX; i++) pc.est.q_var[i] *= (float)(dt / BR_EST_PF_PERIOD_S);
                if (br_pf_init(pf, &pc) != BR_OK) return 1;
                pf->noise_pos = ((uint32_t)s * 1031u) & (pc.noise_len - 1u); /* realisation s */
                double u = 0.0;
                for (long k = 0; k <= K; k++) {
                    const br_meas_t y = {g.counts[a][k * N], 0.5f};
                    br_status_t st = br_pf_step(pf, &y, (float)u);
                    if (st == BR_W_OUTLIER) outliers++;
                    else if (st != BR_OK) return 1;
                    fhat[(size_t)s * (size_t)g.cap + (size_t)k] = (double)br_pf_estimate(pf)->F_hat_N;
                    u = 0.0; /* mean torque over the next N sub-periods */
                    for (int j = 0; j < N && k * N + j < g.n; j++) u += g.tau[a][k * N + j] / N;
                }
            }
            for (long k = 0; k <= K; k++) {
                if (k * dt < SKIP_S) continue;
                double mean = 0.0;
                for (int s = 0; s < seeds; s++) mean += fhat[(size_t)s * (size_t)g.cap + (size_t)k] / seeds;
                const double e = mean - g.fnl[a][k * N];
                bias2 += e * e;
                for (int s = 0; s < seeds; s++) {
                    const double f = fhat[(size_t)s * (size_t)g.cap + (size_t)k];
                    mc2 += (f - mean) * (f - mean) / seeds;
                    tot2 += (f - g.fnl[a][k * N]) * (f - g.fnl[a][k * N]) / seeds;
                }
                cnt++;
            }
        }
        const double rms = sqrt(tot2 / cnt), bias = sqrt(bias2 / cnt), mc = sqrt(mc2 / cnt);
        if (cnt == 0 || !isfinite(rms) || !isfinite(bias) || !isfinite(mc)) {
            fprintf(stderr, "%s: dt = %g s gave a non-finite error\n", TOOL, dt);
            return 1;
        }
        printf("{\"dt_s\": %.6g, \"particles\": %u, \"rms_err_N\": %.6e, \"bias_N\": %.6e, \"mc_N\": %.6e, "
               "\"outliers\": %d, \"seeds\": %d}\n",
               dt, m, rms, bias, mc, outliers, (int)seeds);
        fflush(stdout);
    }
    free(pf);
    free(fhat);
    for (int a = 0; a < 2; a++) {
        free(g.counts[a]);
        free(g.tau[a]);
        free(g.fnl[a]);
    }
    return 0;
}
