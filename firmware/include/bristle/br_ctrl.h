/* SPDX-License-Identifier: Apache-2.0 */
/* Gain-matrix state feedback with integral action (thesis eq. 7), float32.
 *
 *   e_theta = theta - theta_ref            (from integer counts, wrap-safe)
 *   e_omega = omega - omega_ref            (omega from the encoder difference)
 *   eps    <- eps + e_theta dt             (integral state, |eps| <= tau_max / |K2|)
 *   u      = K [e_theta, e_omega, eps]^T + L F_comp
 *   tau    = sat(u, tau_max)               (anti-windup: conditional integration)
 *   duty   = tau / tau_per_duty
 * K comes from firmware/design/synth_hinf.py (firmware/gen/bristle_gen/ctrl/br_hinf_gains.h).
 * See docs/modules/ctrl.md. */
#ifndef BR_CTRL_H
#define BR_CTRL_H

#include <stdint.h>
#include "bristle/br_status.h"

typedef struct {
    float K[3];             /* gains on [e_theta (rad), e_omega (rad/s), eps (rad s)]; u = K x */
    float dt_s;             /* control period, > 0 */
    float tau_max_Nm;       /* torque saturation, > 0, <= tau_per_duty_Nm */
    float tau_per_duty_Nm;  /* amplifier: torque at duty 1, > 0 */
    float rad_per_count;    /* encoder resolution on the motor, > 0 */
    float lead_mprad;       /* L, converts the compensation force to torque, > 0 */
} br_ctrl_cfg_t;

typedef struct {
    int32_t enc_counts;      /* raw encoder counts (free-running, may wrap) */
    int32_t ref_counts;      /* reference, integer part in counts */
    float ref_frac_counts;   /* reference, fractional part, in [0, 1) counts */
    float ref_omega_radps;   /* reference velocity */
    float comp_N;            /* friction compensation force (load side), from an estimator or 0 */
} br_ctrl_in_t;

typedef struct {
    float tau_Nm;          /* saturated torque command */
    float duty;            /* PWM duty in [-1, 1] */
    float e_theta_rad;     /* position error used */
    float omega_radps;     /* measured velocity used */
    int saturated;         /* 1 when the command was clipped */
} br_ctrl_out_t;

typedef struct {
    br_ctrl_cfg_t cfg;
    float eps_rads;        /* integral of the position error, |eps| <= eps_max_rads */
    float eps_max_rads;    /* tau_max / |K2|: the integral term alone saturates the torque */
    float comp_max_N;      /* tau_max / L: the largest compensation the actuator can exert */
    int32_t prev_counts;
    int primed;            /* prev_counts valid */
    int ready;
} br_ctrl_t;

br_status_t br_ctrl_init(br_ctrl_t *c, const br_ctrl_cfg_t *cfg);

/* One control period. Zero torque and duty, the integral state unchanged, and
 *   BR_E_INPUT   for a reference fraction outside [0, 1] or non-finite, a
 *                non-finite reference velocity, or a compensation that is
 *                non-finite or larger than tau_max / L;
 *   BR_E_NUMERIC for an integral state that is non-finite or beyond its clamp,
 *                or a control law that is not finite (an error or reference
 *                velocity beyond float range).
 * The caller (the axis loop) latches these as faults. */
br_status_t br_ctrl_step(br_ctrl_t *c, const br_ctrl_in_t *in, br_ctrl_out_t *out);

#endif
