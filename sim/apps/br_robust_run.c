/* SPDX-License-Identifier: Apache-2.0 */
/* br_robust_run: one plant of the robustness study (docs/robustness.md). The
 * thesis circle on a plant given as a model.json (the truth: the reference
 * machine's parameters drawn away from the nominal ones, maybe a cause), with
 * drift and noise during the run, for each controller:
 *
 *   hinf_only                 H-inf alone
 *   hinf_ff, hinf_ukf, hinf_pf  + feedforward / UKF / PF on the machine's nominal model
 *   hinf_true                 + the plant's true friction (the limit, an oracle)
 *   hinf_qec                  + the machine file's reversal (quadrant-error) pulse (docs/modules/qec.md)
 *   hinf_ff_id, hinf_ukf_id, hinf_pf_id  the same on the model a diagnosis identified
 *                             (--model: its parameters and causes)
 *
 * Usage: br_robust_run [--plant PLANT.json] [--model MODEL.json] [--drift F] [--force-noise N]
 *                      [--enc-noise P] [--seed N] [--only a,b,...] [--ff-veps V] [--dir DIR] [--json OUT]
 *                      [--pf-dt S] [--pf-n M] [--pf-proposal K] [--pf-load Q] [--ukf-load Q]
 *                      [--pf-gate SIGMA] [--pf-adapt-max S]
 *                      [--ahead P] [--machine-causes]
 *                      [--delay-id 0|1]
 *                      [--radius-m R] [--feed-mm-min F] [--direction cw|ccw]
 * --radius-m, --feed-mm-min, --direction: the circle (br_circle_args.h;
 * default the thesis's; --direction, since --dir is the trace folder).
 * --pf-dt, --pf-n: the PF runs at another period / with another particle
 * count (docs/robustness.md, "PF variants"; the tuned variances per step kept).
 * --pf-proposal: the PF's br_pf_cfg_t.proposal (0 the thesis's, 1 OPT, 2
 * OPT_HELD; docs/modules/pf.md).
 * --pf-load: the PF's shared external force with this random walk, N^2/s
 * (br_pf_cfg_t.load; 0: off; the default: the machine's).
 * --ukf-load: the UKF's external-force state with this random walk, N^2/s
 * (br_ukf_cfg_t.load; 0: off; the default: the machine's).
 * --pf-gate: the PF's outlier gate in sigmas (a study, docs/presliding-plants.md,
 * "The PF's gate"; the default: the machine's).
 * --pf-adapt-max: the PF's cfg.adapt.max_scale, its largest variance factor (1: no
 * inflation, the thesis filter; a study, docs/fleet.md; the default: the machine's).
 * --machine-causes: the UKF and the PF of the runs on the machine's model (not the
 * *_id ones) carry the machine file's causes, as the image does (br_machine_causes;
 * docs/fleet.md, "The estimators as the image has them"), not the thesis model; the
 * feedforward runs keep theirs (the image has none).
 * --ahead: every estimator's est.comp_ahead_periods (docs/modules/est.md).
 * --delay-id 0: the estimators without the machine's delay identification
 * (est.delay_id, docs/modules/dlyid.md); 1: with it (the default).
 * --dir writes trace_<name>.csv per run and gp_hist_<name>.csv per PF run
 * (the demo's formats). The JSON is written to a temporary file renamed at
 * the end (br_outfile.h): a failed run writes nothing. Exit 0, 1 (a run or a
 * file failed), 2 (usage). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "circle/br_circle.h"
#include "circle_args/br_circle_args.h"
#include "gms_args/br_gms_args.h"
#include "plant/br_plant_json.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_robust_run"
#define BR_HIST_BINS 60
#define BR_HIST_W_N 0.5

typedef struct {
    const char *name;
    br_circle_ctrl_t ctrl;
    int identified;
} run_t;

static const run_t runs[] = {
    {"hinf_only", BR_CTRL_HINF_ONLY, 0}, {"hinf_ff", BR_CTRL_HINF_FF, 0},       {"hinf_ukf", BR_CTRL_HINF_UKF, 0},
    {"hinf_pf", BR_CTRL_HINF_PF, 0},     {"hinf_true", BR_CTRL_HINF_TRUE, 0},   {"hinf_ff_id", BR_CTRL_HINF_FF, 1},
    {"hinf_ukf_id", BR_CTRL_HINF_UKF, 1}, {"hinf_pf_id", BR_CTRL_HINF_PF, 1},
    {"hinf_qec", BR_CTRL_HINF_QEC, 0},
};
#define N_RUNS (sizeof runs / sizeof runs[0])

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--plant PLANT.json] [--model MODEL.json] [--drift F] [--force-noise N] [--enc-noise P]\n"
            "       [--seed N] [--only a,b,...] [--ff-veps V] [--dir DIR] [--json OUT] [--pf-dt S] [--pf-n M]\n"
            "       [--pf-proposal K] [--pf-load Q] [--ukf-load Q] [--pf-gate SIGMA] [--pf-adapt-max S] [--ahead P] [--delay-id 0|1]\n"
            "       [--machine-causes] [--radius-m R] [--feed-mm-min F]\n"
            "       [--direction cw|ccw] [--gms D1,..,DN] [--gms-zeta Z]\n"
            BR_ARGS_COMMON_USAGE
            "  --plant PLANT.json  the simulated plant (a model.json; default the reference machine)\n"
            "  --model MODEL.json  the identified model the *_id runs' estimators and feedforward use\n"
            "  --drift F           friction drift over the run, as a fraction of the start's level\n"
            "  --force-noise N     standard deviation of a random force on the plant, N\n"
            "  --enc-noise P       probability of a one-count encoder error per sample\n"
            "  --seed N            seed of the run's noise\n"
            "  --only LIST         the runs to do, comma-separated\n"
            "  --ff-veps V         the feedforward's sign-smoothing velocity, m/s\n"
            "  --dir DIR           each run's trace (and the PF's g_p histograms) as CSV into DIR\n"
            "  --json OUT          the runs' figures as JSON\n"
            "  --pf-dt S           the PF runs' period, s\n"
            "  --pf-n M            the PF runs' particle count\n"
            "  --pf-proposal K     the PF runs' proposal: 0 the prior (thesis), 1 optimal for theta, 2 with omega's\n"
            "                      noise held over the period (docs/modules/pf.md)\n"
            "  --pf-load Q         the PF's shared external force, random walk Q N^2/s (0 .. 1e9, 0: off;\n"
            "                      default the machine file's; docs/modules/pf.md)\n"
            "  --ukf-load Q        the UKF's external-force state, random walk Q N^2/s (0 .. 1e9, 0: off;\n"
            "                      default the machine file's; docs/modules/ukf.md)\n"
            "  --pf-gate SIGMA     the PF's outlier gate, sigmas (%g .. %g; a study, docs/presliding-plants.md)\n"
            "  --pf-adapt-max S    the PF's largest noise-variance factor of cfg.adapt (1 .. 1e12; 1: none; no\n"
            "                      effect where the machine has cfg.adapt off; a study, docs/fleet.md)\n"
            "  --machine-causes    the UKF and the PF with the machine file's causes, as the image has them\n"
            "  --ahead P           the estimators' compensation lead, periods past the delay (docs/modules/est.md)\n"
            "  --delay-id 0|1      the estimators' delay identification off / as the machine has it (docs/modules/dlyid.md)\n"
            BR_CIRCLE_USAGE("--direction cw|ccw "),
            argv0, argv0, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA);
    br_gms_usage(to);
    fprintf(to, "runs:");
    for (unsigned r = 0; r < N_RUNS; r++) fprintf(to, " %s", runs[r].name);
    fprintf(to, " (the *_id ones need --model)\n");
    return 2;
}

typedef struct {
    FILE *trace, *hist;
} sinks_t;

static void sink(void *user, const br_circle_sample_t *s)
{
    sinks_t *k = user;
    if (k->trace) br_circle_csv_sink(k->trace, s);
    if (!k->hist) return;
    for (int a = 0; a < 2; a++) {
        const br_pf_t *pf = s->pf[a];
        int h[BR_HIST_BINS] = {0};
        for (uint32_t j = 0; j < pf->cfg.n_particles; j++) {
            const int b = (int)((double)pf->x[BR_X_GP][j] / BR_HIST_W_N);
            if (b >= 0 && b < BR_HIST_BINS) h[b]++;
        }
        fprintf(k->hist, "%.6f,%d", s->t_s, a);
        for (int b = 0; b < BR_HIST_BINS; b++) fprintf(k->hist, ",%d", h[b]);
        fprintf(k->hist, "\n");
    }
}

static int open_in(br_outfile_t *f, const char *dir, const char *pre, const char *name)
{
    char path[BR_OUTFILE_PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s%s.csv", dir, pre, name) >= (int)sizeof path) {
        fprintf(stderr, "%s: %s: path too long\n", TOOL, dir);
        return -1;
    }
    return br_outfile_open(f, TOOL, path);
}

int main(int argc, char **argv)
{
    const char *plant_path = NULL, *model_path = NULL, *json = NULL, *only = NULL, *dir = NULL;
    br_circle_real_t real = {0.0, 0.0, 0.0, 0u};
    double veps = -1.0, pf_dt = -1.0, ahead = -1.0, pf_load = -1.0, ukf_load = -1.0, pf_gate = 0.0, pf_adapt_max = 0.0;
    long pf_n = 0, pf_prop = -1, delay_id = -1;
    int machine_causes = 0;
    br_circle_path_t path = BR_CIRCLE_PATH_DEFAULT;
    br_gms_args_t gms = BR_GMS_ARGS_DEFAULT;
    static const struct option opts[] = {
        {"plant", required_argument, NULL, 'P'},  {"model", required_argument, NULL, 'm'},
        {"json", required_argument, NULL, 'j'},   {"only", required_argument, NULL, 'o'},
        {"dir", required_argument, NULL, 'd'},    {"drift", required_argument, NULL, 'D'},
        {"force-noise", required_argument, NULL, 'f'}, {"enc-noise", required_argument, NULL, 'e'},
        {"ff-veps", required_argument, NULL, 'v'}, {"pf-dt", required_argument, NULL, 't'},
        {"pf-n", required_argument, NULL, 'n'},   {"seed", required_argument, NULL, 's'},
        {"pf-proposal", required_argument, NULL, 'p'}, {"ahead", required_argument, NULL, 'a'},
        {"delay-id", required_argument, NULL, 'i'}, {"pf-load", required_argument, NULL, 'L'},
        {"ukf-load", required_argument, NULL, 'U'},
        {"pf-gate", required_argument, NULL, 'G'}, {"pf-adapt-max", required_argument, NULL, 'X'},
        {"machine-causes", no_argument, NULL, 'M'},
        BR_CIRCLE_LONGOPTS BR_GMS_LONGOPTS{NULL, 0, NULL, 0}};
    br_args_t ap;
    if (br_args_start(&ap, TOOL, argc, argv, usage)) return 0;
    const char *val;
    for (int o; (o = br_args_next(&ap, opts, &val)) != BR_ARGS_END;) {
        int bad = 0;
        long seed = 0;
        switch (o) {
        case 'P': plant_path = val; break;
        case 'm': model_path = val; break;
        case 'j': json = val; break;
        case 'o': only = val; break;
        case 'd': dir = val; break;
        case 'D': bad = br_arg_double(TOOL, ap.opt, val, -0.5, 0.5, &real.drift_frac); break;
        case 'f': bad = br_arg_double(TOOL, ap.opt, val, 0.0, 10.0, &real.force_noise_N); break;
        case 'e': bad = br_arg_double(TOOL, ap.opt, val, 0.0, 1.0, &real.enc_noise_p); break;
        case 'v': bad = br_arg_double(TOOL, ap.opt, val, 1e-9, 1e-3, &veps); break;
        case 't': bad = br_arg_double(TOOL, ap.opt, val, BR_TOOL_DT_MIN_S, BR_TOOL_DT_MAX_S, &pf_dt); break;
        case 'n': bad = br_arg_long(TOOL, ap.opt, val, 1, BR_TOOL_PARTICLES_MAX, &pf_n); break;
        case 'p': bad = br_arg_long(TOOL, ap.opt, val, 0, (long)BR_PF_PROPOSAL_OPT_HELD, &pf_prop); break;
        case 'a': bad = br_arg_double(TOOL, ap.opt, val, 0.0, (double)BR_EST_AHEAD_MAX_PERIODS, &ahead); break;
        case 'i': bad = br_arg_long(TOOL, ap.opt, val, 0, 1, &delay_id); break;
        case 'L': bad = br_arg_double(TOOL, ap.opt, val, 0.0, 1.0e9, &pf_load); break;
        case 'U': bad = br_arg_double(TOOL, ap.opt, val, 0.0, 1.0e9, &ukf_load); break;
        case 'G':
            bad = br_arg_double(TOOL, ap.opt, val, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA, &pf_gate);
            break;
        case 'M': machine_causes = 1; break;
        case 'X': bad = br_arg_double(TOOL, ap.opt, val, 1.0, 1.0e12, &pf_adapt_max); break;
        case BR_CIRCLE_OPT: bad = br_circle_arg(TOOL, ap.opt, val, 0, &path); break;
        case BR_GMS_OPT: bad = br_gms_arg(TOOL, ap.opt, val, &gms); break;
        case 's':
            bad = br_arg_long(TOOL, ap.opt, val, 0, 2147483647L, &seed);
            real.seed = (unsigned long long)seed;
            break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return usage(argv[0], stderr);
    }
    if (only) {
        for (const char *p = only; p && *p;) {
            const char *e = strchr(p, ',');
            const size_t len = e ? (size_t)(e - p) : strlen(p);
            unsigned r = 0;
            while (r < N_RUNS && !(strlen(runs[r].name) == len && strncmp(p, runs[r].name, len) == 0)) r++;
            if (r == N_RUNS) {
                fprintf(stderr, "%s: --only: no run named %.*s\n", TOOL, (int)len, p);
                return usage(argv[0], stderr);
            }
            if (runs[r].identified && !model_path) {
                fprintf(stderr, "%s: %s needs --model\n", TOOL, runs[r].name);
                return usage(argv[0], stderr);
            }
            p = e ? e + 1 : NULL;
        }
    }
    const br_circle_cfg_t thesis = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
    if (br_circle_path_check(TOOL, &path, &thesis) != 0 || br_gms_args_check(TOOL, &gms) != 0)
        return usage(argv[0], stderr);
    br_plant_cfg_t plant = thesis.plant, model = thesis.plant;
    char msg[512];
    if (plant_path && br_plant_cfg_from_model_json(plant_path, &thesis.plant, &plant, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", TOOL, msg);
        return 1;
    }
    if (model_path && br_plant_cfg_from_model_json(model_path, &thesis.plant, &model, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", TOOL, msg);
        return 1;
    }
    /* --gms: the plant's friction Maxwell-slip (the truth only; the identified model stays as read) */
    br_gms_args_apply(&gms, &plant);
    if (dir && mkdir(dir, 0775) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: cannot create %s: %s\n", TOOL, dir, strerror(errno));
        return 1;
    }
    br_outfile_t js = {0};
    if (json) {
        if (br_outfile_open(&js, TOOL, json) != 0) return 1;
        br_circle_cfg_t c0 = thesis;
        br_circle_use_path(&c0, path.radius_m, path.feed_mps, path.dir == BR_CIRCLE_DIR_CCW);
        fprintf(js.f, "{\n  \"generator\": \"br_robust_run (sim/apps/br_robust_run.c)\",\n");
        fprintf(js.f, "  \"circle\": {\"radius_m\": %.9g, \"period_s\": %.9g, \"direction\": \"%s\"},\n", c0.radius_m,
                c0.period_s, c0.dir < 0.0 ? "ccw" : "cw");
        /* the causes the estimators of the runs on the machine's model carry (the *_id runs: the model's) */
        fprintf(js.f, "  \"estimator_causes\": \"%s\",\n", machine_causes ? "machine" : "thesis");
        fprintf(js.f, "  \"controllers\": {");
    }
    int first = 1, rc = 0;
    for (unsigned r = 0; r < N_RUNS && rc == 0; r++) {
        if (only ? !br_arg_list_has(only, runs[r].name) : (runs[r].identified && !model_path)) continue;
        br_circle_cfg_t c = br_circle_cfg_thesis(runs[r].ctrl);
        c.plant = plant;
        c.real = real;
        br_circle_use_path(&c, path.radius_m, path.feed_mps, path.dir == BR_CIRCLE_DIR_CCW);
        if (veps > 0.0) c.ff.v_eps_mps = (float)veps;
        if (runs[r].ctrl == BR_CTRL_HINF_PF && pf_dt > 0.0) {
            c.dt_s = pf_dt;
            c.pf.est.model.dt_s = (float)pf_dt;
        }
        if (pf_n > 0) c.pf.n_particles = (uint32_t)pf_n;
        if (pf_prop >= 0) c.pf.proposal = (uint32_t)pf_prop;
        br_circle_use_ahead(&c, ahead);
        br_circle_use_delay_id(&c, delay_id);
        if (runs[r].identified) br_circle_use_model(&c, &model);
        else if (machine_causes) br_circle_use_machine_causes(&c);
        br_circle_use_pf_load(&c, pf_load);
        br_circle_use_ukf_load(&c, ukf_load);
        br_circle_use_pf_gate(&c, pf_gate);
        br_circle_use_pf_adapt_max(&c, pf_adapt_max);
        br_outfile_t tr = {0}, hi = {0};
        sinks_t k = {NULL, NULL};
        if (dir) {
            if (open_in(&tr, dir, "trace_", runs[r].name) != 0) {
                rc = 1;
                break;
            }
            k.trace = tr.f;
            br_circle_csv_header(k.trace);
            if (runs[r].ctrl == BR_CTRL_HINF_PF) {
                if (open_in(&hi, dir, "gp_hist_", runs[r].name) != 0) {
                    br_outfile_discard(&tr);
                    rc = 1;
                    break;
                }
                k.hist = hi.f;
                fprintf(k.hist, "# g_p particle histogram per step: t,axis, then %d bins of %g N from 0 N\n",
                        BR_HIST_BINS, BR_HIST_W_N);
            }
        }
        br_circle_result_t res;
        /* 1: the firmware stopped the axis safe (a fault), part of the result */
        const int st = br_circle_run(&c, dir ? sink : NULL, &k, &res);
        /* refused at init: a record of its own (br_run_report.h), not a failed tool */
        const int refused = st < 0 && res.fault_cause == BR_RUN_CAUSE_REFUSED_AT_INIT;
        if ((st < 0 && !refused) || !isfinite(res.contour_rms_m) || !isfinite(res.max_err_m)) {
            fprintf(stderr, "%s: run %s %s; nothing written\n", TOOL, runs[r].name,
                    st < 0 ? "failed" : "gave a non-finite result");
            br_outfile_discard(&tr);
            br_outfile_discard(&hi);
            rc = 1;
            break;
        }
        if ((tr.f && br_outfile_commit(&tr, TOOL) != 0) || (hi.f && br_outfile_commit(&hi, TOOL) != 0)) {
            rc = 1;
            break;
        }
        /* a faulted run is a fault (time, cause), never an RMS beside full runs (br_run_report.h) */
        const br_run_report_t rep = {res.contour_rms_m, res.max_err_m, res.fault_status, res.fault_cause,
                                     res.fault_t_s};
        br_run_print(stdout, runs[r].name, "contour", &rep);
        if (js.f) {
            fprintf(js.f, "%s\n    \"%s\": {", first ? "" : ",", runs[r].name);
            br_run_json(js.f, "contour_rms_m", "max_err_m", &rep);
            fprintf(js.f, ", \"fhat_rms_err_N\": %.6e, \"outlier_steps\": %d, \"last_outlier_t_s\": %.6g, "
                          "\"n_samples\": %ld}",
                    res.fhat_rms_err_N, res.outlier_steps, res.last_outlier_t_s, res.n_samples);
        }
        first = 0;
    }
    if (rc != 0) {
        br_outfile_discard(&js);
        return 1;
    }
    if (js.f) {
        fprintf(js.f, "\n  }\n}\n");
        if (br_outfile_commit(&js, TOOL) != 0) return 1;
    }
    return 0;
}
