/* SPDX-License-Identifier: Apache-2.0 */
/* The drive protections of br_app_step (br_app_motion.h, docs/modules/app.md,
 * "Drive protections"). Positions in counts (an int32 and a fraction, as
 * br_ref_t), speeds in counts per period, accelerations in counts per
 * period^2. */
#include "br_app_motion.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"

/* A reference within the limits passes through when its speed and its change
 * of speed are within this fraction above them (rounding of a reference at
 * the limit itself). */
#define BR_APP_LIM_RTOL 1.0e-3f
/* The limiter has caught up when within this many counts of the reference. */
#define BR_APP_LIM_CATCH_COUNTS 0.5f

br_app_motion_cfg_t br_app_motion_cfg(const br_app_machine_t *m)
{
    br_app_motion_cfg_t c = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    if (m == NULL || !br_finite_pos(m->lead_mprad) || !br_finite_pos(m->rad_per_count) ||
        !br_finite_pos(m->mass_kg) || !br_finite_pos(m->inertia_kgm2) || !br_finite_pos(m->Fc_N) ||
        !br_finite_pos(m->Fs_N) || !br_finite_pos(m->max_speed_mps) || !br_finite_pos(m->max_accel_mps2) ||
        !br_finite_pos(m->max_following_m) || !br_finite_pos(m->travel_m) || !isfinite(m->travel_min_m) ||
        !br_finite_pos(m->period_s) || (m->coast_in_stroke != 0 && m->coast_in_stroke != 1) ||
        !(m->delay_s >= 0.0f) || !isfinite(m->delay_s)) {
        return c; /* all zero: rejected by br_app_init */
    }
    c.counts_per_m = 1.0f / (m->lead_mprad * m->rad_per_count);
    c.max_speed_mps = m->max_speed_mps;
    c.max_accel_mps2 = m->max_accel_mps2;
    c.speed_fault_mps = m->max_speed_mps * (1.0f + BR_APP_SPEED_MARGIN);
    c.max_following_m = m->max_following_m;
    /* moved mass seen at the table: M + J / L^2 */
    c.mass_kg = m->mass_kg + m->inertia_kgm2 / (m->lead_mprad * m->lead_mprad);
    /* a braking ramp from the speed fault's speed at max_accel: v^2 / (2 a),
     * the period the fault is seen in, v dt, and the following error the
     * position may be off */
    c.stop_bound_m = c.speed_fault_mps * c.speed_fault_mps / (2.0f * m->max_accel_mps2) +
                     c.speed_fault_mps * m->period_s + m->max_following_m;
    /* the open-loop brake: friction gives Fc of the deceleration mass a */
    c.brake_N = fmaxf(c.mass_kg * m->max_accel_mps2 - m->Fc_N, 0.0f);
    /* the coast envelope: with the outputs off, Coulomb friction alone
     * decelerates the moved mass, Fc / (M + J / L^2) */
    c.coast_decel_mps2 = m->coast_in_stroke ? m->Fc_N / c.mass_kg : 0.0f;
    c.soft_min_m = m->travel_min_m + c.stop_bound_m;
    c.soft_max_m = m->travel_min_m + m->travel_m - c.stop_bound_m;
    /* at standstill friction holds any force in [-Fs, Fs]: a change of 2 Fs */
    c.stuck_band_N = 2.0f * m->Fs_N;
    c.stuck_counts = BR_APP_STUCK_COUNTS;
    c.delay_s = m->delay_s;
    return c;
}

br_status_t br_app_motion_check(const br_app_motion_cfg_t *m)
{
    if (!br_finite_pos(m->counts_per_m) || !br_finite_pos(m->max_speed_mps) || !br_finite_pos(m->max_accel_mps2) ||
        !br_finite_pos(m->max_following_m) || !br_finite_pos(m->mass_kg) || !br_finite_pos(m->stuck_band_N) ||
        !br_finite_pos(m->stuck_counts) || !br_finite_pos(m->stop_bound_m) || !(m->brake_N >= 0.0f) ||
        !isfinite(m->brake_N) || !(m->coast_decel_mps2 >= 0.0f) || !isfinite(m->coast_decel_mps2) ||
        !(m->delay_s >= 0.0f) || !isfinite(m->delay_s)) {
        return BR_E_PARAM;
    }
    /* written so that a NaN fails: a speed fault at or above the limiter's
     * speed, soft limits that leave travel */
    if (!(m->speed_fault_mps >= m->max_speed_mps && isfinite(m->speed_fault_mps)) ||
        !(m->soft_max_m > m->soft_min_m && isfinite(m->soft_max_m) && isfinite(m->soft_min_m))) {
        return BR_E_PARAM;
    }
    /* the position the TRAVEL fault allows, a soft limit plus the following
     * limit, must fit the int32 count (2^31) */
    const float reach_m = fmaxf(fabsf(m->soft_max_m), fabsf(m->soft_min_m)) + m->max_following_m;
    if (!(reach_m * m->counts_per_m < 2147483648.0f)) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

void br_app_motion_reset(br_app_t *app)
{
    const br_app_motion_cfg_t *m = &app->motion;
    const float dt = app->ctrl.cfg.dt_s;
    app->stop = BR_APP_STOP_OFF;
    app->lim_counts = 0;
    app->lim_frac = 0.0f;
    app->lim_v = 0.0f;
    app->lim_primed = 0;
    app->lim_active = 0;
    app->ref_limited = 0;
    app->n_ref_limited = 0u;
    app->lim_vmax = m->max_speed_mps * m->counts_per_m * dt;
    app->lim_amax = m->max_accel_mps2 * m->counts_per_m * dt * dt;
    /* the model's force per count/period^2: F = mass a, a = counts / (counts_per_m dt^2) */
    app->mot_k_m = m->mass_kg / ((m->counts_per_m * dt) * dt);
    app->lim_lo = m->soft_min_m * m->counts_per_m;
    app->lim_hi = m->soft_max_m * m->counts_per_m;
    app->lim_acoast = m->coast_decel_mps2 * m->counts_per_m * dt * dt;
    /* the stroke's ends (a soft limit plus the stop bound), less the
     * following limit the position may be ahead of the reference */
    app->lim_end_lo = (m->soft_min_m - m->stop_bound_m + m->max_following_m) * m->counts_per_m;
    app->lim_end_hi = (m->soft_max_m + m->stop_bound_m - m->max_following_m) * m->counts_per_m;
    app->v_meas = 0.0f;
    app->hold_N = 0.0f;
    app->v_pred = 0.0f;
    app->d_pred = 0.0f;
    br_est_delay_reset(&app->mot_delay, m->delay_s, dt, m->delay_s > 0.0f);
    app->mot_F_N = 0.0f;
    app->brk_counts = 0;
    app->brk_frac = 0.0f;
    app->brk_v = 0.0f;
    app->brk_left = 0u;
    app->brk_duty = 0.0f;
}

/* (ac + af) - (bc + bf) in counts (wrap-safe integer part) */
static float pos_diff(int32_t ac, float af, int32_t bc, float bf)
{
    return (float)br_counts_delta(ac, bc) + (af - bf);
}

/* *c + *f moved by dv counts, the fraction kept in [0, 1) */
static void pos_add(int32_t *c, float *f, float dv)
{
    const float total = *f + dv;
    const float whole = floorf(total);
    *c = (int32_t)((uint32_t)*c + (uint32_t)(int32_t)whole);
    *f = total - whole;
    if (*f >= 1.0f) { /* rounding of total - whole */
        *f = 0.0f;
        *c = (int32_t)((uint32_t)*c + 1u);
    }
}

/* a position given in counts as a float (a soft limit) as br_ref_t parts */
static void pos_from_float(float p, int32_t *c, float *f)
{
    const float whole = floorf(p);
    *c = (int32_t)whole;
    *f = p - whole;
}

/* The speed that still stops within room counts at deceleration a in whole
 * periods: v (v + a) / (2 a) = room solved for v (the discrete braking
 * curve), v_stop = -a/2 + sqrt(a^2/4 + 2 a room); 0 at or beyond it. */
static float brake_cap(float a, float room)
{
    return (room > 0.0f) ? -0.5f * a + sqrtf(0.25f * a * a + 2.0f * a * room) : 0.0f;
}

/* The coast envelope (docs/modules/app.md, "Drive protections"): the largest
 * step v (counts per period) toward an end room counts away after which a
 * coast with the outputs off still stops before it. The table may run at
 * k v, k = 1 + BR_APP_SPEED_MARGIN, before SPEED latches; the fault is seen a
 * period late and the discrete coast adds up to a period more: k^2 v^2 /
 * (2 a) + 2 k v + v <= room, solved for v:
 *   v = a / k^2 (sqrt((2k + 1)^2 + 2 k^2 room / a) - (2k + 1))
 * FLT_MAX without an envelope (a = 0). */
static float coast_cap(const br_app_t *app, float room)
{
    const float a = app->lim_acoast, k = 1.0f + BR_APP_SPEED_MARGIN, b = 2.0f * k + 1.0f;
    if (!(a > 0.0f)) {
        return FLT_MAX;
    }
    if (!(room > 0.0f)) {
        return 0.0f;
    }
    return a / (k * k) * (sqrtf(b * b + 2.0f * k * k * room / a) - b);
}

/* The cap on a step toward the high end (hi) or the low end from position
 * lpos (counts): the braking curve that stops at the soft limit, the coast
 * envelope */
static float ref_cap(const br_app_t *app, float lpos, int hi)
{
    return hi ? fminf(brake_cap(app->lim_amax, app->lim_hi - lpos), coast_cap(app, app->lim_end_hi - lpos))
              : fminf(brake_cap(app->lim_amax, lpos - app->lim_lo), coast_cap(app, lpos - app->lim_end_lo));
}

float br_app_ref_speed_cap_mps(const br_app_t *app, float pos_m, int toward_hi)
{
    if (app == NULL || !app->ready || !isfinite(pos_m)) {
        return 0.0f;
    }
    const float cpm = app->motion.counts_per_m, dt = app->ctrl.cfg.dt_s;
    const float v = fminf(app->lim_vmax, ref_cap(app, pos_m * cpm, toward_hi != 0));
    return v / (cpm * dt);
}

br_status_t br_app_ref_limit(br_app_t *app, const br_ref_t *ref, int32_t counts, br_ref_t *out)
{
    const float dt = app->ctrl.cfg.dt_s, rpc = app->ctrl.cfg.rad_per_count;
    /* written so that a NaN fails (the controller's own range) */
    if (!(ref->ref_frac_counts >= 0.0f && ref->ref_frac_counts <= 1.0f) || !isfinite(ref->ref_omega_radps)) {
        return BR_E_INPUT;
    }
    if (!app->lim_primed) {
        /* from the axis at standstill, where it is */
        app->lim_counts = counts;
        app->lim_frac = 0.5f;
        app->lim_v = 0.0f;
        app->lim_primed = 1;
    }
    const float vmax = app->lim_vmax, amax = app->lim_amax;
    /* the target: the reference held inside the soft travel limits */
    int32_t tc = ref->ref_counts;
    float tf = ref->ref_frac_counts;
    const float tpos = (float)tc + tf;
    const int clamped = (tpos > app->lim_hi) || (tpos < app->lim_lo);
    if (tpos > app->lim_hi) {
        pos_from_float(app->lim_hi, &tc, &tf);
    } else if (tpos < app->lim_lo) {
        pos_from_float(app->lim_lo, &tc, &tf);
    }
    /* the reference's own speed, counts per period; 0 where it is clamped */
    const float vt = clamped ? 0.0f : ref->ref_omega_radps * dt / rpc;
    const float e = pos_diff(tc, tf, app->lim_counts, app->lim_frac);
    const float tol = 1.0f + BR_APP_LIM_RTOL;
    /* the caps on a step toward each end: the braking curve that stops at
     * the soft limit, the coast envelope */
    const float lpos = (float)app->lim_counts + app->lim_frac;
    const float cap_hi = ref_cap(app, lpos, 1);
    const float cap_lo = ref_cap(app, lpos, 0);
    if (!app->lim_active && !clamped && fabsf(e) <= vmax * tol && fabsf(e - app->lim_v) <= amax * tol &&
        fabsf(vt) <= vmax * tol && e <= cap_hi && -e <= cap_lo) {
        /* within every limit: the reference as it is, bit for bit */
        app->lim_counts = tc;
        app->lim_frac = tf;
        app->lim_v = e;
        app->ref_limited = 0;
        *out = *ref;
        return BR_OK;
    }
    app->lim_active = 1;
    app->ref_limited = 1;
    app->n_ref_limited++;
    /* speed that still stops at the target with deceleration amax */
    const float ae = fabsf(e);
    const float vstop = brake_cap(amax, ae);
    const float vtc = br_clampf(vt, -vmax, vmax);
    /* toward the target on the braking curve, riding on the target's speed,
     * never past it in one period */
    float vdes = vtc + copysignf(fminf(vstop, ae), e);
    vdes = br_clampf(vdes, app->lim_v - amax, app->lim_v + amax);
    vdes = br_clampf(vdes, -vmax, vmax);
    /* inside the braking curve to the soft limits and the coast envelope
     * (its deceleration, Fc / (k^2 mass), is below max_accel on a machine
     * where it binds before the braking curve, so a reference on the
     * envelope follows it) */
    vdes = br_clampf(vdes, -cap_lo, cap_hi);
    pos_add(&app->lim_counts, &app->lim_frac, vdes);
    app->lim_v = vdes;
    /* caught up: on the target at its speed; the next period passes through */
    if (fabsf(pos_diff(tc, tf, app->lim_counts, app->lim_frac)) <= BR_APP_LIM_CATCH_COUNTS &&
        fabsf(vdes - vtc) <= amax && !clamped) {
        app->lim_active = 0;
    }
    out->ref_counts = app->lim_counts;
    out->ref_frac_counts = app->lim_frac;
    out->ref_omega_radps = vdes * rpc / dt;
    return BR_OK;
}

br_app_fault_t br_app_motion_watch(br_app_t *app, int32_t d, uint32_t periods)
{
    const br_app_motion_cfg_t *m = &app->motion;
    const float dt = app->ctrl.cfg.dt_s;
    const float cpp = m->counts_per_m * dt; /* counts per period per m/s */
    const float v = (float)d / (float)periods;
    if (fabsf(v) > m->speed_fault_mps * cpp) {
        /* the braking ramp starts from the last speed below the fault's
         * (v_meas kept): a lying count must not set the ramp's speed (one
         * 2e4-count lie at 30 % of max speed made the PF's ramp run up to
         * the speed fault's speed and stop 23 mm on) */
        return BR_APP_FAULT_SPEED;
    }
    const float k_m = app->mot_k_m;
    /* the force that reached the axis over the period that ended (load side,
     * br_app_motion_push: after the actuator delay) */
    const float F = app->mot_F_N;
    if (d != 0 || periods != 1u) {
        /* the count moved (or a held read: no period-wise model): friction +
         * load now, F - mass a (eq. of motion), the speed the model starts from */
        app->hold_N = F - k_m * (v - app->v_meas);
        app->v_meas = v;
        app->v_pred = v;
        app->d_pred = 0.0f;
        return BR_APP_FAULT_NONE;
    }
    /* a still count: the speed the model predicts with the force beyond what
     * held the axis when it last moved, friction taking up to the band and
     * the count's quantization up to k_m BR_APP_STUCK_QUANT_ACCEL (F_hold's
     * uncertainty; never reversing the motion) */
    float v1 = app->v_pred + (F - app->hold_N) / k_m;
    const float brake = m->stuck_band_N / k_m + BR_APP_STUCK_QUANT_ACCEL;
    v1 = (v1 > brake) ? v1 - brake : ((v1 < -brake) ? v1 + brake : 0.0f);
    /* the motion at the period's end speed (the speed may have dropped at
     * its start: the least motion the model allows) */
    app->d_pred += v1;
    app->v_pred = v1;
    app->v_meas = 0.0f;
    if (!(fabsf(app->d_pred) <= m->stuck_counts)) {
        return BR_APP_FAULT_ENC_FROZEN; /* the model predicts motion the counter does not show */
    }
    return BR_APP_FAULT_NONE;
}

br_app_fault_t br_app_limits_check(const br_app_t *app, const br_ref_t *r, int32_t counts)
{
    const br_app_motion_cfg_t *m = &app->motion;
    const float follow = m->max_following_m * m->counts_per_m;
    const float ef = pos_diff(r->ref_counts, r->ref_frac_counts, counts, 0.5f);
    if (!(fabsf(ef) <= follow)) {
        return BR_APP_FAULT_FOLLOWING;
    }
    const float pos = (float)counts + 0.5f;
    if (!(pos <= app->lim_hi + follow && pos >= app->lim_lo - follow)) {
        return BR_APP_FAULT_TRAVEL;
    }
    return BR_APP_FAULT_NONE;
}

void br_app_outputs_off(br_app_t *app)
{
    const br_hal_t *hal = app->hal;
    (void)hal->pwm_write(hal->ctx, 0.0f);
    if (hal->pwm_disable != NULL) {
        (void)hal->pwm_disable(hal->ctx);
    }
    app->last = (br_ctrl_out_t){0};
    app->stop = BR_APP_STOP_OFF;
}

/* one period of the ramp: its speed toward 0 by amax, the controller follows
 * it without compensation; outputs off when it has stood for the settle
 * periods or anything fails */
static br_status_t brake_run(br_app_t *app, int32_t counts)
{
    const float amax = app->lim_amax;
    const float dt = app->ctrl.cfg.dt_s, rpc = app->ctrl.cfg.rad_per_count;
    app->brk_v = (app->brk_v > amax) ? app->brk_v - amax : ((app->brk_v < -amax) ? app->brk_v + amax : 0.0f);
    pos_add(&app->brk_counts, &app->brk_frac, app->brk_v);
    br_ctrl_in_t in = {counts, app->brk_counts, app->brk_frac, app->brk_v * rpc / dt, 0.0f};
    if (app->brk_left == 0u || br_ctrl_step(&app->ctrl, &in, &app->last) != BR_OK ||
        app->hal->pwm_write(app->hal->ctx, app->last.duty) != BR_OK) {
        br_app_outputs_off(app);
        return BR_E_FAULT;
    }
    app->brk_left--;
    return BR_E_FAULT;
}

br_status_t br_app_brake_start(br_app_t *app, int32_t counts)
{
    const float amax = app->lim_amax;
    const float vlim = app->motion.speed_fault_mps * app->motion.counts_per_m * app->ctrl.cfg.dt_s;
    app->stop = BR_APP_STOP_BRAKING;
    app->brk_counts = counts;
    app->brk_frac = 0.5f;
    app->brk_v = br_clampf(app->v_meas, -vlim, vlim);
    /* the periods the ramp takes from that speed, then the settle; bounded
     * by the speed fault's speed (vlim / amax <= 2^20 at init's limits) */
    app->brk_left = (uint32_t)ceilf(fabsf(app->brk_v) / amax) + BR_APP_BRAKE_SETTLE_PERIODS;
    return brake_run(app, counts);
}

br_status_t br_app_brake_period(br_app_t *app, int32_t counts, int32_t d, uint32_t periods)
{
    const br_app_motion_cfg_t *m = &app->motion;
    const float vlim = m->speed_fault_mps * m->counts_per_m * app->ctrl.cfg.dt_s;
    const float ef = pos_diff(app->brk_counts, app->brk_frac, counts, 0.5f);
    /* a ramp the axis does not follow, or a speed above the fault's: off */
    if (!(fabsf((float)d / (float)periods) <= vlim) || !(fabsf(ef) <= m->max_following_m * m->counts_per_m)) {
        br_app_outputs_off(app);
        return BR_E_FAULT;
    }
    return brake_run(app, counts);
}

br_status_t br_app_brake_open_start(br_app_t *app, float v_counts_per_period)
{
    const br_ctrl_cfg_t *k = &app->ctrl.cfg;
    const float amax = app->lim_amax;
    const float vlim = app->motion.speed_fault_mps * app->motion.counts_per_m * k->dt_s;
    const float v = br_clampf(v_counts_per_period, -vlim, vlim);
    /* the force against the motion, as a duty: F L / tau_per_duty, within
     * the controller's torque limit */
    const float duty_max = k->tau_max_Nm / k->tau_per_duty_Nm;
    const float duty = br_clampf(app->motion.brake_N * k->lead_mprad / k->tau_per_duty_Nm, 0.0f, duty_max);
    app->stop = BR_APP_STOP_OPEN;
    app->brk_duty = (v > 0.0f) ? -duty : ((v < 0.0f) ? duty : 0.0f);
    /* the periods that speed takes to stop at amax (<= 2^20 at init's limits) */
    app->brk_left = (uint32_t)ceilf(fabsf(v) / amax);
    return br_app_brake_open_period(app);
}

br_status_t br_app_brake_open_period(br_app_t *app)
{
    if (app->brk_left == 0u || app->hal->pwm_write(app->hal->ctx, app->brk_duty) != BR_OK) {
        br_app_outputs_off(app);
        return BR_E_FAULT;
    }
    app->last = (br_ctrl_out_t){app->brk_duty * app->ctrl.cfg.tau_per_duty_Nm, app->brk_duty, 0.0f, 0.0f, 0};
    app->brk_left--;
    return BR_E_FAULT;
}

void br_app_motion_push(br_app_t *app)
{
    /* the command held over the period that ended; what reached the axis over
     * it: (1 - f) u[k-1-m] + f u[k-2-m] for the delay (m + f) dt (docs/modules/est.md) */
    app->mot_F_N = br_est_delay_apply(&app->mot_delay, app->last.tau_Nm) / app->ctrl.cfg.lead_mprad;
}
