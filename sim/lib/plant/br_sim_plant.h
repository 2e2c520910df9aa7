/* SPDX-License-Identifier: Apache-2.0 */
/* Double-precision plant of one ball-screw axis (thesis eqs. 1-5): rigid
 * body + viscous + LuGre friction, encoder quantisation, amplifier.
 *
 *   (J + L^2 M) domega/dt = tau - L (sigma2 L omega + F_nl)
 *   F_nl = sigma0 z + sigma1 dz/dt,  dz/dt = L omega - sigma0 L |omega| z / g(L omega)
 *   tau = duty * tau_per_duty  (duty clamped to [-1, 1], held over the period)
 *
 * Integration (docs/modules/plant.md): substeps of h = dt / n_sub. Over each
 * substep z follows the exact solution of the bristle equation written over
 * the displacement (bounded at any speed), the friction impulse is integrated
 * in closed form (sigma0 * integral of z, sigma1 * change of z), and the rigid
 * body uses the trapezoidal rule, solved by a fixed number of fixed-point
 * iterations on the mean velocity.
 *
 * Causes (../shared/spec/measured-log.md, docs/simlog.md): fields at the end
 * of br_plant_cfg_t switch on what a measured log may show beyond the thesis
 * model. All zero is the thesis model, bit for bit. With x = L theta the load
 * position, k(x) = max(0, 1 + grad_per_m x) and s(t) = max(0, 1 + drift_per_s t),
 * t the plant time since init:
 *
 *   (J + L^2 M) domega/dt = tau(t - delay_s)
 *        - L [ k(x) s(t) (sigma2_d L omega + F_nl) + offset_N + ripple_amp_N sin(2 pi x / ripple_period_m + ripple_phase_rad) ]
 *
 * where, while the axis moves in -x, sigma2_d = sigma2_Nspm + dsigma2_neg_Nspm
 * and the Stribeck curve g is scaled by (Fc_N + dFc_neg_N) / Fc_N. */
#ifndef BR_SIM_PLANT_H
#define BR_SIM_PLANT_H

#include <stdint.h>

#include "br_gms.h"
#include "bristle_gen/model/br_causes.h"

typedef struct {
    double J_kgm2, M_kg, lead_mprad, sigma2_Nspm;
    double sigma0_Npm, sigma1_Nspm, Fc_N, Fs_N, vs_mps;
    double counts_per_rev;    /* encoder on the motor */
    double tau_per_duty_Nm;   /* amplifier gain */
    int n_sub;                /* substeps per step, >= 1 */
    /* Causes (all 0 = off; the reference machine has them off): one double per
     * parameter of a force or measurement cause, the cause registry's fields in its
     * order (bristle_gen/model/br_causes.h, BR_CAUSE_FIELDS; the equation above);
     * ripple_period_m > 0 when ripple_amp_N != 0, delay_s 0 .. BR_PLANT_DELAY_MAX_S. */
#define BR_PLANT_CAUSE_FIELD_(field, cause, hook, on) double field;
    BR_CAUSE_FIELDS(BR_PLANT_CAUSE_FIELD_)
#undef BR_PLANT_CAUSE_FIELD_
    /* The friction's presliding: gms.n == 0 (the default, all zero) is the
     * LuGre above, bit for bit; gms.n > 0 replaces it by the generalized
     * Maxwell-slip friction of br_gms.h with the same Stribeck level (Fc_N,
     * Fs_N, vs_mps, shaped by gms.delta); sigma0_Npm and sigma1_Nspm are then
     * unused. A truth of the simulator's only: the firmware never reads it. */
    br_gms_cfg_t gms;
} br_plant_cfg_t;

/* Actuator delay: the commanded torques of the last BR_PLANT_DELAY_RING
 * steps are kept; a delay longer than that history (delay_s beyond
 * (BR_PLANT_DELAY_RING - 1) steps of dt) applies the oldest kept command and
 * counts the step in br_plant_t.delay_overruns. */
#define BR_PLANT_DELAY_MAX_S 0.1
#define BR_PLANT_DELAY_RING 1024

typedef struct {
    double t_s;     /* start of the step the command was held over */
    double tau_Nm;  /* commanded torque */
} br_plant_cmd_t;

typedef struct {
    double theta_rad, omega_radps, z_m;
} br_plant_state_t;

typedef struct {
    br_plant_cfg_t cfg;
    br_plant_state_t x;
    double Jeff_kgm2;
    double tau_Nm;     /* torque applied during the last step (its mean with a delay) */
    double fnl_N;      /* friction force (LuGre, or Maxwell-slip with cfg.gms.n > 0) at the end of the
                          last step (direction level, k(x) and s(t) included); sigma2 v excluded */
    /* Causes: bookkeeping (zero and unused while the causes are off). */
    double fdist_N;    /* offset + ripple force at the end of the last step */
    double t_s;        /* plant time: the sum of the steps taken */
    br_plant_cmd_t cmd[BR_PLANT_DELAY_RING]; /* command history, a ring (delay_s > 0 only) */
    int cmd_head;      /* index of the newest command */
    int cmd_n;         /* commands kept, <= BR_PLANT_DELAY_RING */
    long cmd_pushed;   /* commands ever pushed */
    long delay_overruns; /* steps whose delayed command was older than the history */
    br_gms_state_t gms; /* the Maxwell-slip elements (cfg.gms.n > 0): from rest, undeflected, sticking */
} br_plant_t;

/* Reference machine of ../shared/spec/reference-machine.md. */
br_plant_cfg_t br_plant_cfg_reference(void);

/* 0 on success, -1 on an invalid configuration (message on stderr). */
int br_plant_init(br_plant_t *p, const br_plant_cfg_t *cfg, const br_plant_state_t *x0);

/* Advances by dt_s with the duty held (zero-order hold); with delay_s > 0
 * the torque reaching the axis is the command of delay_s earlier (zero before
 * the first command). */
void br_plant_step(br_plant_t *p, double duty, double dt_s);

/* Encoder reading: floor(theta / rad_per_count), wrapped modulo 2^32. */
int32_t br_plant_encoder(const br_plant_t *p);

/* Load-side position and velocity. */
double br_plant_pos_m(const br_plant_t *p);
/* The moving mass at the load, M + J / L^2 (L = lead_mprad), kg. */
double br_plant_meff_kg(const br_plant_cfg_t *c);
double br_plant_vel_mps(const br_plant_t *p);

/* The force an ideal estimator would hand the controller at the end of the
 * last step, N: the plant's friction and disturbance less the nominal viscous
 * term sigma2 v the controller's model holds (the estimators' compensated
 * force, br_model.h): k(x) s(t) (sigma2_d v + f_nl) + offset + ripple - sigma2 v.
 * Without causes it is fnl_N. The "true friction" oracle of the studies. */
double br_plant_comp_force_N(const br_plant_t *p);

/* 1 when any cause of the configuration is switched on. */
int br_plant_causes_on(const br_plant_cfg_t *cfg);

#endif
