/* SPDX-License-Identifier: Apache-2.0 */
/* Identification run on the simulator (docs/simlog.md): a repeated cycle of
 * bang-bang-acceleration moves (trapezoidal velocity) over about 0.1 m at up
 * to 0.05 m/s with dwells, like the EMPS benchmark's excitation, tracked by an
 * EMPS-form position loop at the control period:
 *
 *   qf(k) = (q(k) + q(k-1)) / 2,  qdot(k) = (qf(k) - qf(k-1)) / dt
 *   u = kp kv (ref - q) - kv qdot,  |u| <= u_max,  F = gain u   (force at the load)
 *
 * q is the encoder position at the load (quantised), F the commanded force,
 * applied as duty F L / tau_per_duty over the next period. */
#ifndef BR_IDENT_H
#define BR_IDENT_H

#include "plant/br_sim_plant.h"

typedef struct {
    double kp_1ps;   /* position gain, 1/s */
    double kv;       /* velocity gain (controller units per m/s) */
    double gain_N;   /* force per controller unit */
    double u_max;    /* controller output limit (controller units) */
} br_pd_cfg_t;

typedef struct {
    double x_to_m;    /* target of the move */
    double v_max_mps; /* cruise speed */
    double dwell_s;   /* rest after the move */
} br_move_t;

#define BR_IDENT_MAX_MOVES 16

typedef struct {
    double dt_s;       /* control period */
    double acc_mps2;   /* acceleration of every move */
    double dwell0_s;   /* rest before the first move */
    int cycles;        /* repetitions of the move list */
    int n_moves;
    br_move_t moves[BR_IDENT_MAX_MOVES]; /* from x = 0 */
    br_pd_cfg_t pd;
    double duration_s;  /* > 0: the run's length (the moves cut or repeated); 0: the moves' */
    /* a sweep instead of the moves when sweep_pp_m > 0: after dwell0_s,
     * ref = sweep_pp_m (1 - cos phi(t)) / 2 with phi' = 2 pi f(t), f rising
     * linearly from sweep_f0_hz to sweep_f1_hz at duration_s */
    double sweep_pp_m, sweep_f0_hz, sweep_f1_hz;
} br_ident_cfg_t;

/* One logged period: what a measured log holds, plus the plant's truth. */
typedef struct {
    double t_s, ref_m;
    double pos_m;      /* encoder position at the load */
    double force_N;    /* commanded force at the load (after the limit) */
    double pos_true_m, vel_true_mps;
    double fnl_N;      /* the plant's LuGre force */
} br_log_row_t;

typedef void (*br_log_sink_t)(void *user, const br_log_row_t *row);

/* The default run for a plant: 1 ms, 0.5 m/s^2, 3 cycles of four moves
 * (0 -> 0.1 m at 0.05 m/s, -> 0.04 at 0.03, -> 0.07 at 0.015, -> 0 at 0.04,
 * 0.3 s dwells), and the EMPS loop scaled to the plant's moving mass (same
 * kp and velocity-loop rate kv gain / m as EMPS: 160.18 1/s, 90 1/s). */
br_ident_cfg_t br_ident_cfg_default(const br_plant_cfg_t *plant);

/* The reversal segment (docs/simlog.md, "The reversal segment"): n_pairs
 * back-and-forth moves 0 -> BR_IDENT_REV_AMP_M -> 0 at BR_IDENT_REV_SPEED_MPS,
 * no dwell at the turn, appended to each cycle of c's moves (which must end at
 * x = 0, as the default run's do): slow reversals whose presliding an element
 * set and a bristle tell apart (docs/diagnose.md, presliding_hysteresis).
 * 0, or -1 when n_pairs is outside 1 .. BR_IDENT_REV_MAX_PAIRS or the moves
 * would not fit. */
#define BR_IDENT_REV_AMP_M 1e-4
#define BR_IDENT_REV_SPEED_MPS 1e-4
#define BR_IDENT_REV_MAX_PAIRS 4
int br_ident_add_reversals(br_ident_cfg_t *c, int n_pairs);

/* The slow back-and-forth (docs/simlog.md): 0 -> 0.02 m -> 0 at 5 mm/s,
 * 0.5 m/s^2, no dwell at the reversals, repeated over duration_s. */
br_ident_cfg_t br_ident_cfg_backforth(const br_plant_cfg_t *plant, double duration_s);

/* The sweep (docs/simlog.md): 4 mm peak to peak, 0.1 -> 4 Hz over duration_s
 * (peak speed 0.05 m/s at the end). */
br_ident_cfg_t br_ident_cfg_sweep(const br_plant_cfg_t *plant, double duration_s);

/* Duration of the run, s: duration_s when > 0, else the moves' (all cycles). */
double br_ident_duration_s(const br_ident_cfg_t *c);

/* Reference position at t (before 0: 0; after the end: the last target). */
double br_ident_ref_m(const br_ident_cfg_t *c, double t_s);

/* Runs the loop on a plant starting at rest at x = 0; calls sink once per
 * period (samples 0 .. duration/dt). 0, or -1 with a message on stderr. */
int br_ident_run(const br_ident_cfg_t *c, const br_plant_cfg_t *plant, br_log_sink_t sink, void *user);

#endif
