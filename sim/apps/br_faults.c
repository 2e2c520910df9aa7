/* SPDX-License-Identifier: Apache-2.0 */
/* br_faults: the fault-injection campaign (docs/reliability.md, "Fault
 * campaign"). One axis of the reference machine on the simulator, the
 * production application (br_app_step with the machine's guards and drive
 * protections, br_app_guard_cfg / br_app_motion_cfg), each controller; a
 * move at a share of max_speed_mps, a fault or an ordinary condition
 * injected during it, the run continued after a latched fault until the
 * table stands still. Per scenario and controller: whether and what
 * latched, the detection time, the peak table speed after the injection,
 * the stopping distance from the detection to standstill, and the bounds:
 *   a fault: latched; peak speed <= the speed fault's speed plus one
 *            period of the actuator's acceleration; stopping
 *            distance <= the stop bound the soft limits keep
 *            (br_app_motion_cfg_t.stop_bound_m; the coast bound
 *            BR_MACHINE_COAST_M for the faults that switch the outputs
 *            off); standstill inside the stroke;
 *   an ordinary condition: nothing latches.
 * Exit 1 when a bound is broken that --expect does not name, or a named one
 * holds (the list is out of date). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "circle/br_circle.h"
#include "hal_sim/br_hal_sim.h"
#include "tool/br_args.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"
#include "tool/br_tool_limits.h"

#define TOOL "br_faults"
#define BR_PI 3.14159265358979323846

/* the run: a ramp to the cruise speed at half max_accel, the injection
 * INJECT_AFTER_S into the cruise, then at most RUN_AFTER_S */
#define INJECT_AFTER_S 0.2
#define RUN_AFTER_S 3.0
/* standstill: the table slower than this for STILL_S, outputs off */
#define STILL_MPS 1.0e-4
#define STILL_S 0.05

typedef enum {
    K_ENC_STUCK,   /* the counter stops at the injection */
    K_ENC_OFFSET,  /* the counter jumps by amount counts and stays off by it */
    K_ENC_SPIKE,   /* one read off by amount counts (a glitch), the next ones right */
    K_ENC_NOISE,   /* each read off by a uniform integer in [-amount, amount] */
    K_ENC_DROP,    /* amount reads in a row fail */
    K_LOAD_STEP,   /* an external force of amount x the actuator's force, from the injection on */
    K_LOAD_WAVE,   /* a cutting-force-like load: amount x the actuator's force, |sin| at 40 Hz plus 5 % at 400 Hz */
    K_REF_STEP,    /* the reference jumps by amount metres */
    K_REF_NAN,     /* the reference's speed is NaN at the injection */
    K_DEADLINE     /* the caller reports missed periods (br_app_fault) */
} kind_t;

typedef struct {
    const char *name;
    kind_t kind;
    double amount;
    double speed_share; /* cruise speed / max_speed_mps (0: the axis holds its position) */
    int ordinary;       /* 1: nothing may latch; 0: a fault that must latch within the bounds */
    const char *what;
    int to_end;         /* 1: the move as commanded is the stop bound before the high soft limit at
                           the injection and runs on beyond the stroke (the limiter's braking
                           curve and the coast envelope) */
} scenario_t;

static const scenario_t k_scen[] = {
    {"enc_stuck_30", K_ENC_STUCK, 0.0, 0.3, 0, "counter stops at 30 % of max speed", 0},
    {"enc_stuck_90", K_ENC_STUCK, 0.0, 0.9, 0, "counter stops at 90 % of max speed", 0},
    {"enc_jump_30", K_ENC_OFFSET, 2.0e5, 0.3, 0, "counter jumps 2e5 counts at 30 %", 0},
    {"enc_lie_30", K_ENC_OFFSET, 2.0e4, 0.3, 0, "counter off by 2e4 counts (below the jump limit) at 30 %", 0},
    {"enc_spike_hold", K_ENC_SPIKE, 500.0, 0.0, 1, "one read off by 500 counts, holding", 0},
    {"enc_spike_30", K_ENC_SPIKE, 500.0, 0.3, 1, "one read off by 500 counts at 30 %", 0},
    {"enc_slip_30", K_ENC_OFFSET, 1000.0, 0.3, 1, "counter slips by 1000 counts for good at 30 %", 0},
    {"enc_noise_30", K_ENC_NOISE, 3.0, 0.3, 1, "each read off by up to 3 counts at 30 %", 0},
    {"enc_drop3_90", K_ENC_DROP, 3.0, 0.9, 1, "3 failed reads in a row at 90 %", 0},
    {"enc_drop5_90", K_ENC_DROP, 5.0, 0.9, 0, "5 failed reads in a row at 90 %", 0},
    {"load_half_hold", K_LOAD_STEP, 0.5, 0.0, 1, "load step of half the actuator's force, holding", 0},
    {"load_half_30", K_LOAD_STEP, 0.5, 0.3, 1, "load step of half the actuator's force at 30 %", 0},
    {"load_small_30", K_LOAD_STEP, 0.02, 0.3, 1, "load step of 2 % of the actuator's force at 30 %", 0},
    {"cutting_30", K_LOAD_WAVE, 0.3, 0.3, 1, "cutting-force-like load, 30 % of the actuator's force, at 30 %", 0},
    {"ref_max_speed", K_REF_STEP, 0.0, 1.0, 1, "cruise at max_speed_mps", 0},
    {"ref_step_10mm", K_REF_STEP, 0.01, 0.0, 1, "reference step of 10 mm, holding", 0},
    {"ref_nan_90", K_REF_NAN, 0.0, 0.9, 0, "NaN reference speed at 90 %", 0},
    {"deadline_90", K_DEADLINE, 0.0, 0.9, 0, "missed periods reported at 90 %", 0},
    {"ref_to_end", K_REF_STEP, 0.0, 1.0, 1, "max_speed_mps toward the stroke's end, the reference beyond it", 1},
    {"deadline_end", K_DEADLINE, 0.0, 0.9, 0, "missed periods at 90 % toward the stroke's end", 1},
};
#define N_SCEN (sizeof k_scen / sizeof k_scen[0])

static const br_circle_ctrl_t k_ctrls[] = {BR_CTRL_HINF_ONLY, BR_CTRL_HINF_UKF, BR_CTRL_HINF_PF};
#define N_CTRL (sizeof k_ctrls / sizeof k_ctrls[0])

typedef struct {
    int latched;       /* a fault latched after the injection */
    int cause;         /* br_app_fault_t */
    double detect_s;   /* latch time - injection time */
    double peak_mps;   /* peak |table speed| from the injection on */
    double stop_m;     /* |position at standstill - position at the latch| */
    double end_m;      /* position at the end */
    int still;         /* reached standstill (a latched run) */
    int early_fault;   /* a fault before the injection: the run is no result */
    double early_t_s;
    int early_cause;
    char broken[96];   /* the bound broken, "" when none */
} outcome_t;

/* the encoder in front of the simulator's HAL */
typedef struct {
    br_hal_t inner;
    const scenario_t *s;
    int active;       /* the injection has happened */
    int32_t frozen;   /* K_ENC_STUCK: the count held */
    long drops_left;  /* K_ENC_DROP */
    int spiked;       /* K_ENC_SPIKE: the glitch has been read */
    uint64_t rng;
} inj_t;

static br_status_t inj_read(void *ctx, int32_t *counts)
{
    inj_t *j = ctx;
    br_status_t st = j->inner.encoder_read(j->inner.ctx, counts);
    if (st != BR_OK || !j->active) return st;
    switch (j->s->kind) {
    case K_ENC_STUCK: *counts = j->frozen; break;
    case K_ENC_OFFSET: *counts = (int32_t)((uint32_t)*counts + (uint32_t)(int32_t)j->s->amount); break;
    case K_ENC_SPIKE:
        if (!j->spiked) *counts = (int32_t)((uint32_t)*counts + (uint32_t)(int32_t)j->s->amount);
        j->spiked = 1;
        break;
    case K_ENC_NOISE: {
        /* xorshift64: a fixed stream per run */
        j->rng ^= j->rng << 13;
        j->rng ^= j->rng >> 7;
        j->rng ^= j->rng << 17;
        const long span = 2L * (long)j->s->amount + 1L;
        *counts = (int32_t)((uint32_t)*counts + (uint32_t)(int32_t)((long)(j->rng % (uint64_t)span) - (long)j->s->amount));
        break;
    }
    case K_ENC_DROP:
        if (j->drops_left > 0) {
            j->drops_left--;
            return BR_E_INPUT; /* a failed read */
        }
        break;
    default: break;
    }
    return BR_OK;
}
static br_status_t inj_pwm(void *ctx, float d) { inj_t *j = ctx; return j->inner.pwm_write(j->inner.ctx, d); }
static br_status_t inj_tick(void *ctx, uint32_t *t) { inj_t *j = ctx; return j->inner.tick_wait(j->inner.ctx, t); }

/* the move: position and speed at t from p0 (ramp at acc to v, then cruise) */
static void move_at(double t, double p0, double v, double acc, double *p, double *pv)
{
    const double ta = (acc > 0.0) ? v / acc : 0.0;
    if (t < ta) {
        *p = p0 + 0.5 * acc * t * t;
        *pv = acc * t;
    } else {
        *p = p0 + 0.5 * acc * ta * ta + v * (t - ta);
        *pv = v;
    }
}

static int run_one(const scenario_t *s, br_circle_ctrl_t ctrl, const char *plant_name, double gp_tau_s,
                   double load_q_N2ps, double pf_load_q_N2ps, double pf_gate, outcome_t *o)
{
    memset(o, 0, sizeof *o);
    br_circle_cfg_t c = (strcmp(plant_name, "thesis") == 0) ? br_circle_cfg_thesis(ctrl)
                        : (strcmp(plant_name, "hardware_like") == 0) ? br_circle_cfg_hardware_like(ctrl)
                                                                      : br_circle_cfg_realistic(ctrl);
    br_circle_use_pf_gp_curve(&c, gp_tau_s); /* --pf-gp-curve */
    br_circle_use_ukf_load(&c, load_q_N2ps); /* --ukf-load */
    br_circle_use_pf_load(&c, pf_load_q_N2ps); /* --pf-load */
    br_circle_use_pf_gate(&c, pf_gate);        /* --pf-gate */
    const br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t mc = br_app_motion_cfg(&mm);
    const double L = c.plant.lead_mprad, rpc = 2.0 * BR_PI / c.plant.counts_per_rev, dt = c.dt_s;
    const double F_max = (double)BR_MACHINE_TORQUE_LIMIT_NM_F / L;
    const double v = s->speed_share * (double)mc.max_speed_mps, acc = 0.5 * (double)mc.max_accel_mps2;
    const double t_inj = ((acc > 0.0) ? v / acc : 0.0) + INJECT_AFTER_S;
    /* from 5 mm inside the low soft limit (a move), the middle of the
     * stroke (holding), or (toward the end) where the move as commanded
     * reaches the stop bound before the high soft limit at the injection */
    double p_inj, v_inj;
    move_at(t_inj, 0.0, v, acc, &p_inj, &v_inj);
    const double p0 = s->to_end ? (double)mc.soft_max_m - (double)mc.stop_bound_m - p_inj
                      : (v > 0.0) ? (double)mc.soft_min_m + 0.005
                                  : 0.5 * ((double)mc.soft_min_m + (double)mc.soft_max_m);
    br_plant_t p;
    br_hal_sim_t port;
    inj_t j = {{0}, s, 0, 0, 0, 0, 0x9E3779B97F4A7C15ull};
    const br_plant_state_t x0 = {p0 / L, 0.0, 0.0};
    if (br_plant_init(&p, &c.plant, &x0) != 0 || br_hal_sim_init(&port, &p, dt, &j.inner) != BR_OK) return -1;
    const br_hal_t hal = {&j, inj_read, inj_pwm, inj_tick, NULL, NULL};
    const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(&c);
    br_app_mem_t mem = {NULL, NULL};
    const br_est_t ext = {NULL, NULL, NULL, NULL};
    br_app_cfg_t ac = {&cc, BR_APP_EST_NONE, &c.pf, &c.ukf, &ext,
                       br_app_guard_cfg(cc.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F), mc};
    if (ctrl == BR_CTRL_HINF_PF) {
        ac.est = BR_APP_EST_PF;
        if ((mem.pf = calloc(1, sizeof *mem.pf)) == NULL) return -1;
    } else if (ctrl == BR_CTRL_HINF_UKF) {
        ac.est = BR_APP_EST_UKF;
        if ((mem.ukf = calloc(1, sizeof *mem.ukf)) == NULL) return -1;
    }
    br_app_t app;
    int rc = -1;
    if (br_app_init(&app, &ac, &hal, &mem) != BR_OK || br_app_arm(&app) != BR_OK) {
        fprintf(stderr, "%s: application init failed\n", TOOL);
        goto done;
    }
    const double base_offset = c.plant.offset_N;
    const long n = lround((t_inj + RUN_AFTER_S) / dt);
    double t_latch = -1.0, pos_latch = 0.0, still_s = 0.0;
    for (long k = 0; k <= n; k++) {
        const double t = (double)k * dt;
        uint32_t tick;
        hal.tick_wait(hal.ctx, &tick);
        const double pos = br_plant_pos_m(&p), spd = fabs(p.x.omega_radps * L);
        const int after = t >= t_inj;
        if (after && !j.active) {
            j.active = 1;
            j.frozen = br_plant_encoder(&p);
            j.drops_left = (long)s->amount;
        }
        if (after) o->peak_mps = fmax(o->peak_mps, spd);
        /* the external load (offset_N opposes +x: a load pushing toward -x) */
        if (after && s->kind == K_LOAD_STEP) p.cfg.offset_N = base_offset + s->amount * F_max;
        if (after && s->kind == K_LOAD_WAVE) {
            const double w = 2.0 * BR_PI * 40.0 * (t - t_inj);
            p.cfg.offset_N = base_offset + s->amount * F_max * (fabs(sin(w)) + 0.05 * sin(10.0 * w));
        }
        double rp, rv;
        move_at(t, p0, v, acc, &rp, &rv);
        if (after && s->kind == K_REF_STEP) rp += s->amount;
        const double cts = rp / L / rpc, whole = floor(cts);
        br_ref_t r = {(int32_t)whole, (float)(cts - whole), (float)(rv / L)};
        if (after && s->kind == K_REF_NAN && t_latch < 0.0) r.ref_omega_radps = NAN;
        br_status_t st;
        if (after && s->kind == K_DEADLINE && t_latch < 0.0) st = br_app_fault(&app, BR_APP_FAULT_DEADLINE);
        else st = br_app_step(&app, &r);
        if (st == BR_E_FAULT && t_latch < 0.0) {
            if (!after) {
                /* before the injection: the run is no result */
                o->early_fault = 1;
                o->early_t_s = t;
                o->early_cause = (int)app.fault;
                break;
            }
            t_latch = t;
            pos_latch = pos;
            o->latched = 1;
            o->cause = (int)app.fault;
            o->detect_s = t - t_inj;
        } else if (st != BR_OK && st != BR_W_OUTLIER && st != BR_E_FAULT) {
            fprintf(stderr, "%s: br_app_step returned %d\n", TOOL, (int)st);
            goto done;
        }
        if (t_latch >= 0.0) {
            /* after the latch: on until the table stands with the outputs off */
            still_s = (spd < STILL_MPS && app.stop == BR_APP_STOP_OFF) ? still_s + dt : 0.0;
            if (still_s >= STILL_S) {
                o->still = 1;
                break;
            }
        } else if (after && t - t_inj > 1.0) {
            break; /* an ordinary condition ridden through for a second */
        }
    }
    o->end_m = br_plant_pos_m(&p);
    if (o->latched) o->stop_m = fabs(o->end_m - pos_latch);
    rc = 0;
done:
    free(mem.pf);
    free(mem.ukf);
    return rc;
}

/* the stopping distance bound of a latched cause: the faults that cannot
 * brake (HAL, DEADLINE: outputs off) coast, BR_MACHINE_COAST_M from the
 * speed fault's speed; every other one brakes within the soft limits'
 * stop bound */
static double stop_bound(int cause, const br_app_motion_cfg_t *mc)
{
    if (cause == BR_APP_FAULT_HAL || cause == BR_APP_FAULT_DEADLINE) return (double)BR_MACHINE_COAST_M_F;
    return (double)mc->stop_bound_m;
}

/* the bounds of the campaign (above); "" when they hold */
static void judge(const scenario_t *s, const br_app_motion_cfg_t *mc, double dt_s, outcome_t *o)
{
    /* the speed fault's speed plus what the actuator adds in the period
     * before the measurement shows it: F_max / mass dt */
    const double L = (double)BR_MACHINE_LEAD_MPRAD_F;
    const double v_lim = (double)mc->speed_fault_mps + (double)BR_MACHINE_TORQUE_LIMIT_NM_F / L / (double)mc->mass_kg * dt_s;
    const double lo = (double)BR_MACHINE_TRAVEL_MIN_M, hi = lo + (double)BR_MACHINE_TRAVEL_M;
    if (o->early_fault) snprintf(o->broken, sizeof o->broken, "fault before the injection");
    else if (s->ordinary && o->latched) snprintf(o->broken, sizeof o->broken, "tripped");
    else if (!s->ordinary && !o->latched) snprintf(o->broken, sizeof o->broken, "not detected");
    else if (o->latched && !o->still) snprintf(o->broken, sizeof o->broken, "no standstill");
    else if (!s->ordinary && o->peak_mps > v_lim) snprintf(o->broken, sizeof o->broken, "peak speed");
    else if (o->latched && o->stop_m > stop_bound(o->cause, mc)) snprintf(o->broken, sizeof o->broken, "stopping distance");
    else if (!(o->end_m >= lo && o->end_m <= hi)) snprintf(o->broken, sizeof o->broken, "beyond the stroke");
    else o->broken[0] = '\0';
}

/* An external-force state for the report's first line: "on (Q N^2/s)" or "off",
 * ", the machine's" when no option set it */
static void load_text(char *buf, size_t n, double q_N2ps, int machines)
{
    const char *whose = machines ? ", the machine's" : "";
    if (q_N2ps > 0.0) {
        snprintf(buf, n, "on (%.4g N^2/s%s)", q_N2ps, whose);
    } else {
        snprintf(buf, n, "off%s", machines ? " (the machine's)" : "");
    }
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s [--plant thesis|realistic|hardware_like] [--only LIST] [--ctrl LIST]\n"
            "          [--pf-gp-curve TAU_S] [--pf-load Q_N2_PER_S] [--ukf-load Q_N2_PER_S] [--pf-gate SIGMA]\n"
            "          [--md OUT.md] [--expect LIST]\n" BR_ARGS_COMMON_USAGE
            "  --plant P     the reference machine's plant (default realistic)\n"
            "  --only LIST   the scenarios to run, comma-separated (default all)\n"
            "  --ctrl LIST   hinf_only,hinf_ukf,hinf_pf (default all)\n"
            "  --pf-gp-curve TAU_S  the PF's g_p along the Stribeck curve, time constant (0: off, the machine's)\n"
            "  --pf-load Q_N2_PER_S  the PF's shared external force with this random walk, N^2/s (0: off; default the machine's)\n"
            "  --ukf-load Q_N2_PER_S  the UKF's external-force state with this random walk, N^2/s (0: off; default the machine's)\n"
            "  --pf-gate SIGMA  the PF's outlier gate, sigmas (%g .. %g; a study, docs/presliding-plants.md)\n"
            "  --md OUT.md   the table as markdown\n"
            "  --expect LIST scenario/controller pairs (enc_stuck_90/hinf_pf) whose bound is known broken\n",
            argv0, argv0, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA);
    return 2;
}

static void print_row(FILE *f, const scenario_t *s, br_circle_ctrl_t ctrl, const outcome_t *o, int expected)
{
    fprintf(f, "| %s | %s | %s | ", s->name, s->what, br_circle_ctrl_name(ctrl));
    if (o->early_fault) {
        fprintf(f, "FAULT before the injection at %.4f s (%s) | | | |", o->early_t_s, br_run_fault_name(o->early_cause));
    } else if (o->latched) {
        fprintf(f, "%s | %.1f ms | %.4f m/s | %.2f mm |", br_run_fault_name(o->cause), 1e3 * o->detect_s, o->peak_mps,
                1e3 * o->stop_m);
    } else {
        fprintf(f, "none | | %.4f m/s | |", o->peak_mps);
    }
    fprintf(f, " %s |\n", o->broken[0] ? (expected ? "broken (known)" : "**BROKEN**") : "holds");
    if (o->broken[0]) fprintf(f, "|  | bound: %s | | | | | | |\n", o->broken);
}

int main(int argc, char **argv)
{
    const char *plant = "realistic", *only = NULL, *ctrls = NULL, *md = NULL, *expect = NULL;
    double gp_tau_s = 0.0, load_q = -1.0, pf_load_q = -1.0, pf_gate = 0.0; /* -1: the machine's */
    static const struct option opts[] = {{"plant", required_argument, NULL, 'p'}, {"only", required_argument, NULL, 'o'},
                                         {"ctrl", required_argument, NULL, 'c'},  {"md", required_argument, NULL, 'm'},
                                         {"expect", required_argument, NULL, 'e'},
                                         {"pf-gp-curve", required_argument, NULL, 'g'},
                                         {"ukf-load", required_argument, NULL, 'l'},
                                         {"pf-load", required_argument, NULL, 'L'},
                                         {"pf-gate", required_argument, NULL, 'G'}, {NULL, 0, NULL, 0}};
    br_args_t ap;
    if (br_args_start(&ap, TOOL, argc, argv, usage)) return 0;
    const char *val;
    for (int o; (o = br_args_next(&ap, opts, &val)) != BR_ARGS_END;) {
        switch (o) {
        case 'p': plant = val; break;
        case 'o': only = val; break;
        case 'c': ctrls = val; break;
        case 'm': md = val; break;
        case 'e': expect = val; break;
        case 'g':
            if (br_arg_double(TOOL, ap.opt, val, 0.0, 100.0, &gp_tau_s)) return usage(argv[0], stderr);
            break;
        case 'l':
            if (br_arg_double(TOOL, ap.opt, val, 0.0, 1.0e9, &load_q)) return usage(argv[0], stderr);
            break;
        case 'L':
            if (br_arg_double(TOOL, ap.opt, val, 0.0, 1.0e9, &pf_load_q)) return usage(argv[0], stderr);
            break;
        case 'G':
            if (br_arg_double(TOOL, ap.opt, val, BR_TOOL_GATE_MIN_SIGMA, BR_TOOL_GATE_MAX_SIGMA, &pf_gate))
                return usage(argv[0], stderr);
            break;
        default: return usage(argv[0], stderr);
        }
    }
    if (strcmp(plant, "thesis") != 0 && strcmp(plant, "realistic") != 0 && strcmp(plant, "hardware_like") != 0) {
        fprintf(stderr, "%s: --plant: %s is not thesis, realistic or hardware_like\n", TOOL, plant);
        return usage(argv[0], stderr);
    }
    /* every listed name must exist */
    const char *lists[2] = {only, ctrls};
    for (int l = 0; l < 2; l++) {
        for (const char *p = lists[l]; p && *p;) {
            const char *e = strchr(p, ',');
            const int len = (int)(e ? (size_t)(e - p) : strlen(p));
            int found = 0;
            for (size_t i = 0; l == 0 && i < N_SCEN; i++) found |= (int)strlen(k_scen[i].name) == len && !strncmp(p, k_scen[i].name, (size_t)len);
            for (size_t i = 0; l == 1 && i < N_CTRL; i++) {
                const char *nm = br_circle_ctrl_name(k_ctrls[i]);
                found |= (int)strlen(nm) == len && !strncmp(p, nm, (size_t)len);
            }
            if (!found) {
                fprintf(stderr, "%s: %s: no %s named %.*s\n", TOOL, l ? "--ctrl" : "--only", l ? "controller" : "scenario", len, p);
                return usage(argv[0], stderr);
            }
            p = e ? e + 1 : NULL;
        }
    }
    br_outfile_t out = {0};
    if (md && br_outfile_open(&out, TOOL, md) != 0) return 1;
    const br_app_machine_t mm = BR_MACHINE_APP_MACHINE;
    const br_app_motion_cfg_t mc = br_app_motion_cfg(&mm);
    FILE *f = md ? out.f : stdout;
    /* the external forces as the runs have them: the option's, or the machine file's */
    br_circle_cfg_t lc = br_circle_cfg_thesis(BR_CTRL_HINF_UKF);
    br_circle_use_ukf_load(&lc, load_q);
    const double uq = br_circle_ukf_load_q_N2ps(&lc);
    lc = br_circle_cfg_thesis(BR_CTRL_HINF_PF);
    br_circle_use_pf_load(&lc, pf_load_q);
    const double pq = br_circle_pf_load_q_N2ps(&lc);
    char ld[64], pld[64];
    load_text(ld, sizeof ld, uq, load_q < 0.0);
    load_text(pld, sizeof pld, pq, pf_load_q < 0.0);
    char gt[64] = "";
    if (pf_gate > 0.0) snprintf(gt, sizeof gt, "; PF gate %g sigma (a study)", pf_gate);
    fprintf(f, "Plant: %s; PF g_p curve %s; PF external force %s; UKF external force %s%s. Stop bound %.1f mm (coast %.1f mm), speed fault %.4f m/s, stroke [%.4f, %.4f] m, soft limits [%.4f, %.4f] m.\n\n",
            plant, gp_tau_s > 0.0 ? "on" : "off (the machine's)", pld, ld, gt, 1e3 * (double)mc.stop_bound_m, 1e3 * (double)BR_MACHINE_COAST_M_F, (double)mc.speed_fault_mps, (double)BR_MACHINE_TRAVEL_MIN_M,
            (double)BR_MACHINE_TRAVEL_MIN_M + (double)BR_MACHINE_TRAVEL_M, (double)mc.soft_min_m, (double)mc.soft_max_m);
    fprintf(f, "| scenario | what | controller | latched | detection | peak speed | stopping distance | bounds |\n");
    fprintf(f, "|---|---|---|---|---|---|---|---|\n");
    int n_broken = 0, n_stale = 0, n_run = 0;
    for (size_t i = 0; i < N_SCEN; i++) {
        if (only && !br_arg_list_has(only, k_scen[i].name)) continue;
        for (size_t k = 0; k < N_CTRL; k++) {
            if (ctrls && !br_arg_list_has(ctrls, br_circle_ctrl_name(k_ctrls[k]))) continue;
            outcome_t o;
            if (run_one(&k_scen[i], k_ctrls[k], plant, gp_tau_s, load_q, pf_load_q, pf_gate, &o) != 0) {
                br_outfile_discard(&out);
                return 1;
            }
            judge(&k_scen[i], &mc, br_circle_cfg_thesis(k_ctrls[k]).dt_s, &o);
            char key[96];
            snprintf(key, sizeof key, "%s/%s", k_scen[i].name, br_circle_ctrl_name(k_ctrls[k]));
            const int expected = br_arg_list_has(expect, key);
            print_row(f, &k_scen[i], k_ctrls[k], &o, expected);
            if (md) print_row(stdout, &k_scen[i], k_ctrls[k], &o, expected);
            n_run++;
            if (o.broken[0] && !expected) n_broken++;
            if (!o.broken[0] && expected) {
                fprintf(stderr, "%s: %s holds its bound but --expect names it: update the list\n", TOOL, key);
                n_stale++;
            }
        }
    }
    fprintf(f, "\n%d runs, %d bounds broken beyond the expected.\n", n_run, n_broken);
    if (md && br_outfile_commit(&out, TOOL) != 0) return 1;
    if (n_broken) fprintf(stderr, "%s: %d bounds broken\n", TOOL, n_broken);
    return (n_broken || n_stale) ? 1 : 0;
}
