/* SPDX-License-Identifier: Apache-2.0 */
/* Gain-matrix state feedback with integral action (thesis eq. 7), float32.
 * See br_ctrl.h and docs/modules/ctrl.md. */
#include "bristle/br_ctrl.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"

br_status_t br_ctrl_init(br_ctrl_t *c, const br_ctrl_cfg_t *cfg)
{
    if (c == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    c->ready = 0;
    if (!isfinite(cfg->K[0]) || !isfinite(cfg->K[1]) || !isfinite(cfg->K[2])) {
        return BR_E_PARAM;
    }
    if (!br_finite_pos(cfg->dt_s) || !br_finite_pos(cfg->tau_max_Nm) || !br_finite_pos(cfg->tau_per_duty_Nm) ||
        !br_finite_pos(cfg->rad_per_count) || !br_finite_pos(cfg->lead_mprad)) {
        return BR_E_PARAM;
    }
    if (cfg->tau_max_Nm > cfg->tau_per_duty_Nm) {
        return BR_E_PARAM; /* the saturation must be reachable with |duty| <= 1 */
    }
    c->cfg = *cfg;
    /* the integral is clamped both ways where its term alone saturates the
     * torque, |K2 eps| <= tau_max; without integral action (K2 = 0) eps is
     * kept at 0 */
    c->eps_max_rads = (cfg->K[2] != 0.0f) ? cfg->tau_max_Nm / fabsf(cfg->K[2]) : 0.0f;
    c->comp_max_N = cfg->tau_max_Nm / cfg->lead_mprad;
    c->eps_rads = 0.0f;
    c->prev_counts = 0;
    c->primed = 0;
    c->ready = 1;
    return BR_OK;
}

/* zero torque and duty: what every rejected step outputs */
static void zero_out(br_ctrl_out_t *out)
{
    out->tau_Nm = 0.0f;
    out->duty = 0.0f;
    out->e_theta_rad = 0.0f;
    out->omega_radps = 0.0f;
    out->saturated = 0;
}

br_status_t br_ctrl_step(br_ctrl_t *c, const br_ctrl_in_t *in, br_ctrl_out_t *out)
{
    if (c == NULL || in == NULL || out == NULL) {
        return BR_E_NULL;
    }
    if (!c->ready) {
        return BR_E_STATE;
    }
    const br_ctrl_cfg_t *k = &c->cfg;
    /* a reference fraction outside [0, 1], a non-finite reference velocity, or
     * a compensation that is not finite or beyond what the actuator can exert
     * (|L F_comp| > tau_max: no friction estimate of a working axis) */
    if (!(in->ref_frac_counts >= 0.0f && in->ref_frac_counts <= 1.0f) || !isfinite(in->ref_omega_radps) ||
        !(fabsf(in->comp_N) <= c->comp_max_N)) {
        zero_out(out);
        return BR_E_INPUT;
    }
    /* the integral state must be usable before it enters the law */
    if (!(fabsf(c->eps_rads) <= c->eps_max_rads)) {
        zero_out(out);
        return BR_E_NUMERIC;
    }
    /* omega from the wrap-safe encoder difference (backward difference) */
    int32_t d = c->primed ? br_counts_delta(in->enc_counts, c->prev_counts) : 0;
    c->prev_counts = in->enc_counts;
    c->primed = 1;
    float omega = (float)d * k->rad_per_count / k->dt_s;
    /* eq. 7 error states: e_theta from integer counts, e_omega */
    float e_counts = (float)br_counts_delta(in->enc_counts, in->ref_counts) - in->ref_frac_counts;
    float e_theta = e_counts * k->rad_per_count;
    float e_omega = omega - in->ref_omega_radps;
    /* eq. 7 control law u = K x + L F_comp */
    float u = k->K[0] * e_theta + k->K[1] * e_omega + k->K[2] * c->eps_rads + k->lead_mprad * in->comp_N;
    if (!isfinite(u)) {
        zero_out(out); /* a velocity reference or error beyond float range: the state is kept */
        return BR_E_NUMERIC;
    }
    float tau = br_clampf(u, -k->tau_max_Nm, k->tau_max_Nm);
    int sat = (tau != u);
    /* anti-windup: hold the integral when it would drive deeper into saturation */
    float du = k->K[2] * e_theta;
    if (!(sat && ((du > 0.0f && u > 0.0f) || (du < 0.0f && u < 0.0f)))) {
        c->eps_rads = br_clampf(c->eps_rads + e_theta * k->dt_s, -c->eps_max_rads, c->eps_max_rads);
    }
    out->tau_Nm = tau;
    out->duty = tau / k->tau_per_duty_Nm;
    out->e_theta_rad = e_theta;
    out->omega_radps = omega;
    out->saturated = sat;
    return BR_OK;
}
