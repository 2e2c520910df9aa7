/* SPDX-License-Identifier: Apache-2.0 */
/* Identification run: trajectory and EMPS-form position loop (br_ident.h). */
#include "br_ident.h"

#include <math.h>
#include <stdio.h>

#define BR_PI 3.14159265358979323846

br_ident_cfg_t br_ident_cfg_default(const br_plant_cfg_t *plant)
{
    static const br_move_t moves[4] = {
        {0.100, 0.050, 0.3},
        {0.040, 0.030, 0.3},
        {0.070, 0.015, 0.3},
        {0.000, 0.040, 0.3},
    };
    br_ident_cfg_t c;
    c.dt_s = 1e-3;
    c.acc_mps2 = 0.5;
    c.dwell0_s = 0.3;
    c.cycles = 3;
    c.n_moves = 4;
    for (int i = 0; i < 4; i++) c.moves[i] = moves[i];
    /* EMPS: kp = 160.18 1/s, kv gtau / m = 243.45 * 35.15 / 95.1 = 90 1/s.
     * Here in force units (gain 1 N per unit), kv = 90 1/s times the moving mass. */
    const double L = plant->lead_mprad;
    const double m = (plant->J_kgm2 + L * L * plant->M_kg) / (L * L);
    c.pd.kp_1ps = 160.18;
    c.pd.kv = 90.0 * m;
    c.pd.gain_N = 1.0;
    c.pd.u_max = plant->tau_per_duty_Nm / L; /* the amplifier's limit at the load */
    c.duration_s = 0.0;
    c.sweep_pp_m = c.sweep_f0_hz = c.sweep_f1_hz = 0.0;
    return c;
}

int br_ident_add_reversals(br_ident_cfg_t *c, int n_pairs)
{
    if (n_pairs < 1 || n_pairs > BR_IDENT_REV_MAX_PAIRS || c->n_moves + 2 * n_pairs > BR_IDENT_MAX_MOVES ||
        c->n_moves < 1 || c->moves[c->n_moves - 1].x_to_m != 0.0)
        return -1;
    const br_move_t out = {BR_IDENT_REV_AMP_M, BR_IDENT_REV_SPEED_MPS, 0.0};
    br_move_t back = {0.0, BR_IDENT_REV_SPEED_MPS, 0.0};
    const double rest_s = c->moves[c->n_moves - 1].dwell_s;
    for (int i = 0; i < n_pairs; i++) {
        /* the last move back rests like the cycle's last move before the next cycle */
        back.dwell_s = i == n_pairs - 1 ? rest_s : 0.0;
        c->moves[c->n_moves++] = out;
        c->moves[c->n_moves++] = back;
    }
    return 0;
}

br_ident_cfg_t br_ident_cfg_backforth(const br_plant_cfg_t *plant, double duration_s)
{
    br_ident_cfg_t c = br_ident_cfg_default(plant);
    const br_move_t there = {0.020, 0.005, 0.0}, back = {0.0, 0.005, 0.0};
    c.n_moves = 2;
    c.moves[0] = there;
    c.moves[1] = back;
    c.duration_s = duration_s;
    /* enough cycles to fill the duration (each 8.02 s) */
    c.cycles = (int)ceil(duration_s / (2.0 * (0.020 / 0.005 + 0.005 / c.acc_mps2))) + 1;
    return c;
}

br_ident_cfg_t br_ident_cfg_sweep(const br_plant_cfg_t *plant, double duration_s)
{
    br_ident_cfg_t c = br_ident_cfg_default(plant);
    c.duration_s = duration_s;
    c.sweep_pp_m = 0.004;
    c.sweep_f0_hz = 0.1;
    c.sweep_f1_hz = 4.0;
    return c;
}

/* trapezoidal (or triangular) move over distance d >= 0: duration and position */
static double move_time(double d, double v, double a)
{
    if (d <= 0.0) return 0.0;
    if (d <= v * v / a) return 2.0 * sqrt(d / a); /* triangular */
    return d / v + v / a;
}

static double move_pos(double d, double v, double a, double t)
{
    const double T = move_time(d, v, a);
    if (t <= 0.0) return 0.0;
    if (t >= T) return d;
    const double vp = fmin(v, sqrt(d * a)); /* peak speed */
    const double ta = vp / a;
    if (t < ta) return 0.5 * a * t * t;
    if (t > T - ta) {
        const double r = T - t;
        return d - 0.5 * a * r * r;
    }
    return 0.5 * a * ta * ta + vp * (t - ta);
}

double br_ident_duration_s(const br_ident_cfg_t *c)
{
    if (c->duration_s > 0.0) return c->duration_s;
    double T = c->dwell0_s, x = 0.0;
    for (int k = 0; k < c->cycles; k++) {
        for (int i = 0; i < c->n_moves; i++) {
            T += move_time(fabs(c->moves[i].x_to_m - x), c->moves[i].v_max_mps, c->acc_mps2) + c->moves[i].dwell_s;
            x = c->moves[i].x_to_m;
        }
    }
    return T;
}

/* the sweep's reference: phi(tau) = 2 pi (f0 tau + (f1 - f0) tau^2 / (2 T)),
 * tau the time since the first dwell, T the sweep's length */
static double sweep_ref_m(const br_ident_cfg_t *c, double t)
{
    const double tau = t - c->dwell0_s, T = c->duration_s - c->dwell0_s;
    if (tau <= 0.0 || T <= 0.0) return 0.0;
    const double phi = 2.0 * BR_PI * (c->sweep_f0_hz * tau + (c->sweep_f1_hz - c->sweep_f0_hz) * tau * tau / (2.0 * T));
    return 0.5 * c->sweep_pp_m * (1.0 - cos(phi));
}

double br_ident_ref_m(const br_ident_cfg_t *c, double t)
{
    if (c->sweep_pp_m > 0.0) return sweep_ref_m(c, t);
    double t0 = c->dwell0_s, x = 0.0;
    if (t <= t0) return 0.0;
    for (int k = 0; k < c->cycles; k++) {
        for (int i = 0; i < c->n_moves; i++) {
            const br_move_t *m = &c->moves[i];
            const double d = fabs(m->x_to_m - x);
            const double T = move_time(d, m->v_max_mps, c->acc_mps2);
            if (t < t0 + T) return x + copysign(move_pos(d, m->v_max_mps, c->acc_mps2, t - t0), m->x_to_m - x);
            t0 += T + m->dwell_s;
            x = m->x_to_m;
            if (t < t0) return x;
        }
    }
    return x;
}

int br_ident_run(const br_ident_cfg_t *c, const br_plant_cfg_t *plant_cfg, br_log_sink_t sink, void *user)
{
    if (!(c->dt_s > 0.0 && c->acc_mps2 > 0.0 && c->cycles >= 1 && c->n_moves >= 1 &&
          c->n_moves <= BR_IDENT_MAX_MOVES && c->pd.u_max > 0.0 && c->duration_s >= 0.0 &&
          !(c->sweep_pp_m > 0.0 && !(c->duration_s > c->dwell0_s && c->sweep_f0_hz > 0.0 &&
                                     c->sweep_f1_hz >= c->sweep_f0_hz)))) {
        fprintf(stderr, "br_ident: invalid run configuration\n");
        return -1;
    }
    for (int i = 0; i < c->n_moves; i++) {
        if (!(c->moves[i].v_max_mps > 0.0 && c->moves[i].dwell_s >= 0.0 && isfinite(c->moves[i].x_to_m))) {
            fprintf(stderr, "br_ident: invalid move %d\n", i);
            return -1;
        }
    }
    br_plant_t p;
    const br_plant_state_t x0 = {0.0, 0.0, 0.0};
    if (br_plant_init(&p, plant_cfg, &x0) != 0) return -1;
    const double L = plant_cfg->lead_mprad;
    const double m_per_count = L * 2.0 * BR_PI / plant_cfg->counts_per_rev;
    const long n = lround(br_ident_duration_s(c) / c->dt_s);
    double q_prev = 0.0, qf_prev = 0.0;
    for (long k = 0; k <= n; k++) {
        br_log_row_t r;
        r.t_s = (double)k * c->dt_s;
        r.ref_m = br_ident_ref_m(c, r.t_s);
        r.pos_m = (double)br_plant_encoder(&p) * m_per_count;
        r.pos_true_m = br_plant_pos_m(&p);
        r.vel_true_mps = br_plant_vel_mps(&p);
        r.fnl_N = p.fnl_N;
        if (k == 0) q_prev = qf_prev = r.pos_m;
        const double qf = 0.5 * (r.pos_m + q_prev);
        const double qdot = (qf - qf_prev) / c->dt_s;
        q_prev = r.pos_m;
        qf_prev = qf;
        double u = c->pd.kp_1ps * c->pd.kv * (r.ref_m - r.pos_m) - c->pd.kv * qdot;
        u = fmin(fmax(u, -c->pd.u_max), c->pd.u_max);
        r.force_N = c->pd.gain_N * u;
        if (sink) sink(user, &r);
        br_plant_step(&p, r.force_N * L / plant_cfg->tau_per_duty_Nm, c->dt_s);
        if (!isfinite(p.x.omega_radps)) {
            fprintf(stderr, "br_ident: the plant state is not finite at t = %.3f s\n", r.t_s);
            return -1;
        }
    }
    return 0;
}
