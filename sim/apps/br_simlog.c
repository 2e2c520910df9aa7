/* SPDX-License-Identifier: Apache-2.0 */
/* br_simlog: writes a log in the measured-log format (t,ref,pos,force;
 * ../shared/spec/measured-log.md) from the plant simulator, with any of the
 * causes a diagnosis names switched on. docs/simlog.md.
 *
 * Usage: br_simlog --out FILE [--traj ident|circle|backforth|sweep] [--cycles N] [--reversals N]
 *                  [--duration S] [--seed N] [--force-noise N] [--model MODEL.json]
 *                  [cause options] [--gms D1,..,DN] [--machine-out FILE] [--truth]
 * (the cause options: br_cause_args.h, printed by --help)
 *
 * --machine-out (identification run) writes the position loop as a machine
 * file for the diagnosis (its closed-loop re-simulation); named
 * <log>.machine.json beside the log, the diagnosis finds it by itself.
 *
 * Every option is checked (bounds: br_tool_limits.h) and the model read
 * before any output is touched; the outputs are written beside their names
 * and renamed at the end (br_outfile.h): a failed run writes nothing.
 */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cause_args/br_cause_args.h"
#include "gms_args/br_gms_args.h"
#include "circle/br_circle.h"
#include "ident/br_ident.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_rng.h"
#include "tool/br_tool_limits.h"
#include "plant/br_plant_json.h"

#define TOOL "br_simlog"
#define BR_PI 3.14159265358979323846

typedef struct {
    FILE *f;
    br_rng_t rng;
    double noise_N;
    int truth;
    long nonfinite; /* rows with a non-finite value: the run fails */
} out_t;

static void write_header(const out_t *o)
{
    fprintf(o->f, "t,ref,pos,force%s\n", o->truth ? ",pos_true,vel_true,fnl_true" : "");
}

static void write_row(out_t *o, double t, double ref, double pos, double force, double pos_true, double vel_true,
                      double fnl)
{
    const double f = o->noise_N > 0.0 ? force + o->noise_N * br_rng_gauss(&o->rng) : force;
    if (!(isfinite(t) && isfinite(ref) && isfinite(pos) && isfinite(f) && isfinite(pos_true) && isfinite(fnl) &&
          !isinf(vel_true)))
        o->nonfinite++;
    fprintf(o->f, "%.6f,%.10e,%.10e,%.8e", t, ref, pos, f);
    if (o->truth) {
        /* the circle's sample has no velocity: an empty cell */
        fprintf(o->f, ",%.10e,", pos_true);
        if (!isnan(vel_true)) fprintf(o->f, "%.8e", vel_true);
        fprintf(o->f, ",%.8e", fnl);
    }
    fputc('\n', o->f);
}

static void ident_sink(void *user, const br_log_row_t *r)
{
    write_row(user, r->t_s, r->ref_m, r->pos_m, r->force_N, r->pos_true_m, r->vel_true_mps, r->fnl_N);
}

typedef struct {
    out_t *o;
    double m_per_count, F_per_duty;
} circle_sink_t;

/* the x axis of the circle: encoder position, commanded force */
static void circle_sink(void *user, const br_circle_sample_t *s)
{
    circle_sink_t *c = user;
    const double pos = floor(s->pos_m[0] / c->m_per_count) * c->m_per_count;
    write_row(c->o, s->t_s, s->ref_m[0], pos, s->duty[0] * c->F_per_duty, s->pos_m[0], NAN, s->fnl_N[0]);
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --out FILE [--traj ident|circle|backforth|sweep] [--cycles N] [--reversals N]\n"
            "          [--duration S] [--seed N] [--force-noise N] [--model MODEL.json] [cause options]\n"
            "          [--gms D1,..,DN] [--gms-zeta Z] [--machine-out FILE] [--truth]\n"
            BR_ARGS_COMMON_USAGE
            "  --out FILE          the log (CSV t,ref,pos,force; with --truth the plant's truth too)\n"
            "  --traj T            ident: an identification run (default); circle: the circle's x axis;\n"
            "                      backforth: a slow back-and-forth; sweep: a frequency sweep\n"
            "  --cycles N          repetitions of the identification moves\n"
            "  --reversals N       N slow back-and-forth pairs (0.1 mm at 0.1 mm/s) after each cycle's moves:\n"
            "                      the reversal segment presliding_hysteresis needs (ident only)\n"
            "  --duration S        length of the circle, back-and-forth or sweep run (default 8 s)\n"
            "  --seed N            seed of the force noise\n"
            "  --force-noise N     standard deviation of the noise on the logged force\n"
            "  --model MODEL.json  the plant from a diagnosis's saved model\n"
            "  --machine-out FILE  the run's machine file (not with circle)\n",
            argv0, argv0);
    br_gms_usage(to);
    br_cause_usage(to, "");
    fprintf(to,
            "bounds: --cycles 1 .. %d, --reversals 1 .. %d, --duration %g .. %g s, --force-noise 0 .. %g N\n"
            "        (docs/tools.md)\n",
            BR_TOOL_CYCLES_MAX, BR_IDENT_REV_MAX_PAIRS, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S,
            BR_TOOL_NOISE_MAX_N);
    return 2;
}

/* the machine file of docs/diagnose.md: the position loop of the log */
static void write_machine(FILE *f, const br_ident_cfg_t *c)
{
    fprintf(f,
            "{\n  \"generator\": \"br_simlog (sim/apps/br_simlog.c); generated, do not edit\",\n"
            "  \"name\": \"br_simlog identification run\",\n"
            "  \"controller\": {\"type\": \"emps_pd\", \"dt_s\": %.9g, \"kp_1ps\": %.9g, \"kv\": %.9g, "
            "\"gain_N\": %.9g, \"u_max\": %.9g}\n}\n",
            c->dt_s, c->pd.kp_1ps, c->pd.kv, c->pd.gain_N, c->pd.u_max);
}

typedef struct {
    const char *out, *traj, *model, *machine_out;
    long cycles, seed, reversals;
    int truth;
    double duration, noise;
    br_plant_cfg_t causes;
    br_gms_args_t gms;             /* --gms, --gms-zeta: the plant's Maxwell-slip friction */
} opts_t;


/* every option checked: 0, 1 (--help or --version answered) or 2 (usage error, message printed) */
static int parse(int argc, char **argv, opts_t *o)
{
    static const struct option opts[] = {{"truth", no_argument, NULL, 't'},
                                         {"out", required_argument, NULL, 'o'},
                                         {"traj", required_argument, NULL, 'j'},
                                         {"model", required_argument, NULL, 'm'},
                                         {"machine-out", required_argument, NULL, 'M'},
                                         {"cycles", required_argument, NULL, 'c'},
                                         {"seed", required_argument, NULL, 's'},
                                         {"duration", required_argument, NULL, 'd'},
                                         {"force-noise", required_argument, NULL, 'n'},
                                         {"reversals", required_argument, NULL, 'r'},
                                         BR_GMS_LONGOPTS BR_CAUSE_LONGOPTS{NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 1;
    const char *val;
    for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        int bad = 0;
        switch (c) {
        case BR_CAUSE_OPT: bad = br_cause_arg(p.opt, val, &o->causes) < 0; break;
        case 't': o->truth = 1; break;
        case 'o': o->out = val; break;
        case 'j': o->traj = val; break;
        case 'm': o->model = val; break;
        case 'M': o->machine_out = val; break;
        case 'c': bad = br_arg_long(TOOL, p.opt, val, 1, BR_TOOL_CYCLES_MAX, &o->cycles); break;
        case 'r': bad = br_arg_long(TOOL, p.opt, val, 1, BR_IDENT_REV_MAX_PAIRS, &o->reversals); break;
        case 's': bad = br_arg_long(TOOL, p.opt, val, 0, LONG_MAX, &o->seed); break;
        case 'd':
            bad = br_arg_double(TOOL, p.opt, val, BR_TOOL_DURATION_MIN_S, BR_TOOL_DURATION_MAX_S, &o->duration);
            break;
        case 'n': bad = br_arg_double(TOOL, p.opt, val, 0.0, BR_TOOL_NOISE_MAX_N, &o->noise); break;
        case BR_GMS_OPT: bad = br_gms_arg(TOOL, p.opt, val, &o->gms) != 0; break;
        default: bad = 1; break; /* BR_ARGS_BAD: reported */
        }
        if (bad) return 2;
    }
    if (!o->out) {
        fprintf(stderr, "%s: --out is required\n", TOOL);
        return 2;
    }
    if (strcmp(o->traj, "ident") != 0 && strcmp(o->traj, "circle") != 0 && strcmp(o->traj, "backforth") != 0 &&
        strcmp(o->traj, "sweep") != 0) {
        fprintf(stderr, "%s: --traj %s: must be ident, circle, backforth or sweep\n", TOOL, o->traj);
        return 2;
    }
    if (o->machine_out && strcmp(o->traj, "circle") == 0) {
        fprintf(stderr, "%s: --machine-out does not apply to --traj circle (its loop is the H-inf controller)\n",
                TOOL);
        return 2;
    }
    if (o->cycles > 0 && strcmp(o->traj, "ident") != 0) {
        fprintf(stderr, "%s: --cycles applies to --traj ident only (the others take --duration)\n", TOOL);
        return 2;
    }
    if (br_gms_args_check(TOOL, &o->gms) != 0) return 2;
    if (o->reversals > 0 && strcmp(o->traj, "ident") != 0) {
        fprintf(stderr, "%s: --reversals applies to --traj ident only\n", TOOL);
        return 2;
    }
    if (o->machine_out && strcmp(o->machine_out, o->out) == 0) {
        fprintf(stderr, "%s: --machine-out and --out name the same file\n", TOOL);
        return 2;
    }
    return 0;
}

int main(int argc, char **argv)
{
    opts_t opt = {NULL, "ident", NULL, NULL, 0, 1, 0, 0, 8.0, 0.0, br_plant_cfg_reference(), BR_GMS_ARGS_DEFAULT};
    const int p = parse(argc, argv, &opt);
    if (p == 1) return 0; /* --help or --version answered */
    if (p != 0) return usage(argv[0], stderr);

    br_plant_cfg_t plant = br_plant_cfg_reference();
    char msg[512];
    if (opt.model && br_plant_cfg_from_model_json(opt.model, &plant, &plant, msg, sizeof msg) != 0) {
        fprintf(stderr, "%s: %s\n", TOOL, msg);
        return 1;
    }
    /* the plant: the reference machine or a saved model, then the cause options on top */
    br_causes_apply(&plant, &opt.causes);
    br_gms_args_apply(&opt.gms, &plant);

    /* the outputs: temporary files beside their names until the run succeeded */
    br_outfile_t log_file, machine_file = {0};
    if (br_outfile_open(&log_file, TOOL, opt.out) != 0) return 1;
    if (opt.machine_out && br_outfile_open(&machine_file, TOOL, opt.machine_out) != 0) {
        br_outfile_discard(&log_file);
        return 1;
    }
    out_t o = {log_file.f, {(unsigned long long)opt.seed * 0x2545F4914F6CDD1Dull + 1u, 0, 0.0}, opt.noise, opt.truth,
               0};
    write_header(&o);
    int rc;
    if (strcmp(opt.traj, "circle") != 0) {
        /* the EMPS-form loop on moves or a sweep */
        br_ident_cfg_t c = strcmp(opt.traj, "backforth") == 0 ? br_ident_cfg_backforth(&plant, opt.duration)
                           : strcmp(opt.traj, "sweep") == 0   ? br_ident_cfg_sweep(&plant, opt.duration)
                                                              : br_ident_cfg_default(&plant);
        if (opt.cycles > 0) c.cycles = (int)opt.cycles;
        /* --reversals N: N slow back-and-forth pairs after each cycle's moves (parse checked N) */
        if (opt.reversals > 0 && br_ident_add_reversals(&c, (int)opt.reversals) != 0) rc = -1;
        else
            rc = br_ident_run(&c, &plant, ident_sink, &o);
        if (rc == 0 && opt.machine_out) write_machine(machine_file.f, &c);
    } else {
        br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
        c.plant = plant;
        c.duration_s = opt.duration;
        br_circle_result_t res;
        circle_sink_t cs = {&o, plant.lead_mprad * 2.0 * BR_PI / plant.counts_per_rev,
                            plant.tau_per_duty_Nm / plant.lead_mprad};
        rc = br_circle_run(&c, circle_sink, &cs, &res);
    }
    if (rc == 0 && o.nonfinite > 0) {
        fprintf(stderr, "%s: the simulation went non-finite (%ld rows)\n", TOOL, o.nonfinite);
        rc = -1;
    }
    if (rc == 0) rc = br_outfile_commit(&log_file, TOOL);
    if (rc == 0 && opt.machine_out) rc = br_outfile_commit(&machine_file, TOOL);
    br_outfile_discard(&log_file);
    br_outfile_discard(&machine_file);
    if (rc != 0) {
        fprintf(stderr, "%s: failed; nothing written\n", TOOL);
        return 1;
    }
    return 0;
}
