/* br_simlog: writes a log in the measured-log format (t,ref,pos,force;
 * ../shared/spec/measured-log.md) from the plant simulator, with any of the
 * causes a diagnosis names switched on. docs/simlog.md.
 *
 * Usage: br_simlog --out FILE [--traj ident|circle] [--cycles N] [--duration S]
 *                  [--seed N] [--force-noise N] [--model MODEL.json]
 *                  [--offset F] [--asym DFC,DFV] [--ripple A,P[,PHASE]]
 *                  [--gradient S] [--delay D] [--machine-out FILE]
 *                  [--truth]
 *
 * --machine-out (identification run) writes the position loop as a machine
 * file for the diagnosis (its closed-loop re-simulation); named
 * <log>.machine.json beside the log, the diagnosis finds it by itself.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "simlog/br_cause_args.h"
#include "circle/br_circle.h"
#include "simlog/br_ident.h"
#include "plant/br_plant_json.h"

#define BR_PI 3.14159265358979323846

/* splitmix64 and Box-Muller: seeded force noise, the same on every machine */
typedef struct {
    uint64_t s;
    int have;
    double spare;
} rng_t;

static double rng_uniform(rng_t *r)
{
    uint64_t z = (r->s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return ((double)(z >> 11) + 0.5) / 9007199254740992.0; /* (0, 1) */
}

static double rng_gauss(rng_t *r)
{
    if (r->have) {
        r->have = 0;
        return r->spare;
    }
    const double u = rng_uniform(r), v = rng_uniform(r);
    const double m = sqrt(-2.0 * log(u));
    r->spare = m * sin(2.0 * BR_PI * v);
    r->have = 1;
    return m * cos(2.0 * BR_PI * v);
}

typedef struct {
    FILE *f;
    rng_t rng;
    double noise_N;
    int truth;
} out_t;

static void write_header(const out_t *o)
{
    fprintf(o->f, "t,ref,pos,force%s\n", o->truth ? ",pos_true,vel_true,fnl_true" : "");
}

static void write_row(out_t *o, double t, double ref, double pos, double force, double pos_true, double vel_true,
                      double fnl)
{
    const double f = o->noise_N > 0.0 ? force + o->noise_N * rng_gauss(&o->rng) : force;
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

static int usage(const char *argv0)
{
    fprintf(stderr,
            "usage: %s --out FILE [--traj ident|circle] [--cycles N] [--duration S] [--seed N]\n"
            "          [--force-noise N] [--model MODEL.json] [--offset F] [--asym DFC,DFV]\n"
            "          [--ripple A,P[,PHASE]] [--gradient S] [--delay D] [--machine-out FILE] [--truth]\n",
            argv0);
    return 2;
}

/* the machine file of docs/diagnose.md: the position loop of the log */
static int write_machine(const char *path, const br_ident_cfg_t *c)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "br_simlog: cannot write %s: %s\n", path, strerror(errno));
        return -1;
    }
    fprintf(f,
            "{\n  \"generator\": \"br_simlog (sim/apps/br_simlog.c); generated, do not edit\",\n"
            "  \"name\": \"br_simlog identification run\",\n"
            "  \"controller\": {\"type\": \"emps_pd\", \"dt_s\": %.9g, \"kp_1ps\": %.9g, \"kv\": %.9g, "
            "\"gain_N\": %.9g, \"u_max\": %.9g}\n}\n",
            c->dt_s, c->pd.kp_1ps, c->pd.kv, c->pd.gain_N, c->pd.u_max);
    return fclose(f) == 0 ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *out = NULL, *traj = "ident", *model = NULL, *machine_out = NULL;
    int cycles = 0, truth = 0;
    double duration = 8.0, noise = 0.0;
    unsigned long long seed = 1;
    br_plant_cfg_t causes = br_plant_cfg_reference();
    int bad = 0;
    for (int i = 1; i < argc && !bad; i++) {
        const char *a = argv[i], *val = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--truth") == 0) {
            truth = 1;
            continue;
        }
        if (!val) {
            bad = 1;
            break;
        }
        i++;
        char *end = NULL;
        const int ca = br_cause_arg(a, val, &causes);
        if (ca != 0) bad = ca < 0;
        else if (strcmp(a, "--out") == 0) out = val;
        else if (strcmp(a, "--traj") == 0) traj = val;
        else if (strcmp(a, "--model") == 0) model = val;
        else if (strcmp(a, "--machine-out") == 0) machine_out = val;
        else if (strcmp(a, "--cycles") == 0) bad = !((cycles = atoi(val)) >= 1 && cycles <= 1000);
        else if (strcmp(a, "--seed") == 0) {
            seed = strtoull(val, &end, 10);
            bad = (end == val || *end != '\0');
        } else if (strcmp(a, "--duration") == 0) bad = !(br_parse_numbers(val, &duration, 1) == 1 && duration > 0.0);
        else if (strcmp(a, "--force-noise") == 0) bad = !(br_parse_numbers(val, &noise, 1) == 1 && noise >= 0.0);
        else bad = 1;
        if (bad) fprintf(stderr, "br_simlog: bad option or value: %s %s\n", a, val);
    }
    if (bad || !out || (strcmp(traj, "ident") != 0 && strcmp(traj, "circle") != 0)) return usage(argv[0]);

    /* the plant: the reference machine or a saved model, then the cause flags on top */
    br_plant_cfg_t plant = br_plant_cfg_reference();
    char msg[512];
    if (model && br_plant_cfg_from_model_json(model, &plant, &plant, msg, sizeof msg) != 0) {
        fprintf(stderr, "br_simlog: %s\n", msg);
        return 1;
    }
    const br_plant_cfg_t ref = br_plant_cfg_reference();
    if (causes.offset_N != 0.0) plant.offset_N = causes.offset_N;
    if (causes.dFc_neg_N != ref.dFc_neg_N || causes.dsigma2_neg_Nspm != ref.dsigma2_neg_Nspm) {
        plant.dFc_neg_N = causes.dFc_neg_N;
        plant.dsigma2_neg_Nspm = causes.dsigma2_neg_Nspm;
    }
    if (causes.ripple_amp_N != 0.0) {
        plant.ripple_amp_N = causes.ripple_amp_N;
        plant.ripple_period_m = causes.ripple_period_m;
        plant.ripple_phase_rad = causes.ripple_phase_rad;
    }
    if (causes.grad_per_m != 0.0) plant.grad_per_m = causes.grad_per_m;
    if (causes.delay_s != 0.0) plant.delay_s = causes.delay_s;

    out_t o = {NULL, {seed * 0x2545F4914F6CDD1Dull + 1u, 0, 0.0}, noise, truth};
    o.f = fopen(out, "w");
    if (!o.f) {
        fprintf(stderr, "br_simlog: cannot write %s: %s\n", out, strerror(errno));
        return 1;
    }
    write_header(&o);
    int rc;
    if (strcmp(traj, "ident") == 0) {
        br_ident_cfg_t c = br_ident_cfg_default(&plant);
        if (cycles > 0) c.cycles = cycles;
        rc = br_ident_run(&c, &plant, ident_sink, &o);
        if (rc == 0 && machine_out) rc = write_machine(machine_out, &c);
    } else {
        br_circle_cfg_t c = br_circle_cfg_thesis(BR_CTRL_HINF_ONLY);
        c.plant = plant;
        c.duration_s = duration;
        br_circle_result_t res;
        circle_sink_t cs = {&o, plant.lead_mprad * 2.0 * BR_PI / plant.counts_per_rev,
                            plant.tau_per_duty_Nm / plant.lead_mprad};
        rc = br_circle_run(&c, circle_sink, &cs, &res);
        if (rc == 0 && machine_out) fprintf(stderr, "br_simlog: --machine-out applies to --traj ident only\n");
    }
    if (fclose(o.f) != 0) rc = -1;
    if (rc != 0) {
        fprintf(stderr, "br_simlog: failed; %s is incomplete\n", out);
        return 1;
    }
    return 0;
}
