/* SPDX-License-Identifier: Apache-2.0 */
/* The application: configuration -> estimator -> one control period (br_app.h). */
#include "bristle/br_app.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_app_motion.h"
#include "br_check.h"

/* The estimator runs at the controller's period: the same float, up to a few
 * ulp of rounding in however each was formed. */
#define BR_APP_PERIOD_RTOL 1.0e-6f

static br_status_t check_period(const br_ctrl_cfg_t *ctrl, float est_dt_s)
{
    /* written so that a NaN fails */
    return (fabsf(est_dt_s - ctrl->dt_s) <= BR_APP_PERIOD_RTOL * ctrl->dt_s) ? BR_OK : BR_E_PARAM;
}

br_status_t br_app_est_init(const br_app_cfg_t *cfg, const br_app_mem_t *mem, br_est_t *est)
{
    if (cfg == NULL || cfg->ctrl == NULL || est == NULL) {
        return BR_E_NULL;
    }
    *est = (br_est_t){NULL, NULL, NULL, NULL};
    br_status_t st;
    switch (cfg->est) {
    case BR_APP_EST_NONE:
        return BR_OK;
    case BR_APP_EST_PF:
        if (cfg->pf == NULL || mem == NULL || mem->pf == NULL) {
            return BR_E_NULL;
        }
        st = check_period(cfg->ctrl, cfg->pf->est.model.dt_s);
        if (st == BR_OK) {
            st = br_pf_init(mem->pf, cfg->pf);
        }
        if (st == BR_OK) {
            *est = br_pf_est(mem->pf);
        }
        return st;
    case BR_APP_EST_UKF:
        if (cfg->ukf == NULL || mem == NULL || mem->ukf == NULL) {
            return BR_E_NULL;
        }
        st = check_period(cfg->ctrl, cfg->ukf->est.model.dt_s);
        if (st == BR_OK) {
            st = br_ukf_init(mem->ukf, cfg->ukf);
        }
        if (st == BR_OK) {
            *est = br_ukf_est(mem->ukf);
        }
        return st;
    case BR_APP_EST_EXTERN:
        if (cfg->ext == NULL || cfg->ext->step == NULL) {
            return BR_E_NULL;
        }
        *est = *cfg->ext;
        return BR_OK;
    }
    return BR_E_PARAM;
}

/* Largest values the guards accept (bounded counters, a delta that an int32
 * difference can hold with room, a stale hold of at most a second at 1 kHz). */
#define BR_APP_MAX_DELTA_LIMIT (1u << 30)
#define BR_APP_STALE_LIMIT 1000u
/* Longest braking ramp, periods (from the speed fault's speed at max_accel). */
#define BR_APP_BRAKE_LIMIT (1u << 20)

br_app_guard_cfg_t br_app_guard_cfg(float dt_s, float max_speed_counts_per_s)
{
    br_app_guard_cfg_t g = {0u, BR_APP_GUARD_STALE_PERIODS, 0u, 0u};
    if (!br_finite_pos(dt_s) || !br_finite_pos(max_speed_counts_per_s)) {
        return g; /* zero delta and lock window: rejected by br_app_init */
    }
    const float d = ceilf(BR_APP_JUMP_SPEEDS * max_speed_counts_per_s * dt_s);
    const float w = ceilf(BR_APP_GUARD_LOCK_S / dt_s);
    g.enc_max_delta_counts = (d <= (float)BR_APP_MAX_DELTA_LIMIT) ? (uint32_t)d : BR_APP_MAX_DELTA_LIMIT + 1u;
    g.lock_window_periods = (w <= (float)BR_APP_LOCK_WINDOW_MAX) ? (uint32_t)w : BR_APP_LOCK_WINDOW_MAX + 1u;
    if (g.lock_window_periods <= BR_APP_LOCK_WINDOW_MAX) {
        g.lock_max_outliers = (uint32_t)ceilf(BR_APP_GUARD_LOCK_FRACTION * (float)g.lock_window_periods);
    }
    return g;
}

static br_status_t guard_check(const br_app_guard_cfg_t *g)
{
    if (g->enc_max_delta_counts < 1u || g->enc_max_delta_counts > BR_APP_MAX_DELTA_LIMIT ||
        g->enc_stale_periods > BR_APP_STALE_LIMIT || g->lock_window_periods < 1u ||
        g->lock_window_periods > BR_APP_LOCK_WINDOW_MAX || g->lock_max_outliers >= g->lock_window_periods) {
        return BR_E_PARAM; /* a lock limit of the whole window or more could never trip */
    }
    return BR_OK;
}

/* A fault where the position is not trusted (or the loop cannot run): duty
 * 0, outputs off at once. */
static br_status_t latch(br_app_t *app, br_app_fault_t cause)
{
    app->fault = cause;
    br_app_outputs_off(app);
    return BR_E_FAULT;
}

/* A fault where the position is not trusted but the last speed is: the
 * open-loop brake against speed v (counts per period), then outputs off. */
static br_status_t latch_open(br_app_t *app, br_app_fault_t cause, float v)
{
    app->fault = cause;
    return br_app_brake_open_start(app, v);
}

/* A fault where the position is trusted: the braking ramp from the count of
 * this period, then outputs off. */
static br_status_t latch_brake(br_app_t *app, br_app_fault_t cause, int32_t counts)
{
    app->fault = cause;
    return br_app_brake_start(app, counts);
}

/* The lock monitor's window emptied (at init and at every arm). */
static void lock_reset(br_app_t *app)
{
    for (uint32_t i = 0u; i < BR_APP_LOCK_WORDS; i++) {
        app->lock_bits[i] = 0u;
    }
    app->lock_pos = 0u;
    app->n_lock = 0u;
}

/* One period into the lock monitor's sliding window: the oldest period leaves
 * it, this one enters. 1 when the window then holds more outlier periods than
 * lock_max_outliers. */
static int lock_lost(br_app_t *app, int outlier)
{
    const uint32_t word = app->lock_pos / 32u, bit = 1u << (app->lock_pos % 32u);
    if ((app->lock_bits[word] & bit) != 0u) {
        app->n_lock--;
    }
    if (outlier) {
        app->lock_bits[word] |= bit;
        app->n_lock++;
    } else {
        app->lock_bits[word] &= ~bit;
    }
    app->lock_pos = (app->lock_pos + 1u < app->guard.lock_window_periods) ? app->lock_pos + 1u : 0u;
    return app->n_lock > app->guard.lock_max_outliers;
}

br_status_t br_app_init(br_app_t *app, const br_app_cfg_t *cfg, const br_hal_t *hal, const br_app_mem_t *mem)
{
    if (app == NULL) {
        return BR_E_NULL;
    }
    app->ready = 0;
    if (cfg == NULL) {
        return BR_E_NULL;
    }
    br_est_t est;
    br_status_t st = br_app_est_init(cfg, mem, &est);
    if (st != BR_OK) {
        return st;
    }
    st = guard_check(&cfg->guard);
    if (st == BR_OK) {
        st = br_app_motion_check(&cfg->motion);
    }
    if (st != BR_OK) {
        return st;
    }
    if (hal == NULL || hal->encoder_read == NULL || hal->pwm_write == NULL || hal->tick_wait == NULL) {
        return BR_E_NULL;
    }
    st = br_ctrl_init(&app->ctrl, cfg->ctrl);
    if (st != BR_OK) {
        return st;
    }
    /* the stuck-encoder model's command history holds the actuator delay */
    if (!br_est_delay_fits(cfg->motion.delay_s, cfg->ctrl->dt_s)) {
        return BR_E_PARAM;
    }
    app->motion = cfg->motion;
    br_app_motion_reset(app); /* the limits in counts at the controller's period */
    /* a braking ramp of bounded length, a limiter that moves in a period */
    if (!(app->lim_vmax * (1.0f + BR_APP_SPEED_MARGIN) <= (float)BR_APP_BRAKE_LIMIT * app->lim_amax) ||
        !(app->lim_vmax > 0.0f && app->lim_amax > 0.0f)) {
        return BR_E_PARAM;
    }
    app->hal = hal;
    app->est = est;
    app->F_hat_N = 0.0f;
    app->last = (br_ctrl_out_t){0};
    app->ready = 1;
    app->guard = cfg->guard;
    app->last_counts = 0;
    app->have_counts = 0;
    app->n_stale = 0u;
    lock_reset(app);
    (void)latch(app, BR_APP_FAULT_DISARMED);
    return BR_OK;
}

br_status_t br_app_arm(br_app_t *app)
{
    if (app == NULL) {
        return BR_E_NULL;
    }
    if (!app->ready) {
        return BR_E_STATE;
    }
    /* the controller restarts: integral and previous count cleared */
    const br_ctrl_cfg_t kc = app->ctrl.cfg;
    br_status_t st = br_ctrl_init(&app->ctrl, &kc);
    if (st == BR_OK && app->est.step != NULL) {
        st = br_est_restart(&app->est); /* primed again at the next measurement */
    }
    if (st != BR_OK) {
        return st; /* stays latched */
    }
    app->F_hat_N = 0.0f;
    app->last = (br_ctrl_out_t){0};
    app->have_counts = 0;
    app->n_stale = 0u;
    lock_reset(app);
    br_app_motion_reset(app);
    const br_hal_t *hal = app->hal;
    st = hal->pwm_write(hal->ctx, 0.0f);
    if (st == BR_OK && hal->pwm_enable != NULL) {
        st = hal->pwm_enable(hal->ctx);
    }
    if (st != BR_OK) {
        (void)latch(app, BR_APP_FAULT_HAL);
        return st;
    }
    app->fault = BR_APP_FAULT_NONE;
    return BR_OK;
}

br_status_t br_app_fault(br_app_t *app, br_app_fault_t cause)
{
    if (app == NULL) {
        return BR_E_NULL;
    }
    if (!app->ready) {
        return BR_E_STATE;
    }
    if (cause <= BR_APP_FAULT_NONE || cause > BR_APP_FAULT_REF_UNDERRUN) {
        return BR_E_PARAM;
    }
    return latch(app, cause);
}

br_status_t br_app_step(br_app_t *app, const br_ref_t *ref)
{
    if (app == NULL || ref == NULL) {
        return BR_E_NULL;
    }
    if (!app->ready) {
        return BR_E_STATE;
    }
    const br_hal_t *hal = app->hal;
    const int braking = (app->fault != BR_APP_FAULT_NONE && app->stop == BR_APP_STOP_BRAKING);
    if (app->fault != BR_APP_FAULT_NONE && app->stop == BR_APP_STOP_OPEN) {
        return br_app_brake_open_period(app); /* no encoder read: it is not trusted */
    }
    if (app->fault != BR_APP_FAULT_NONE && !braking) {
        br_app_outputs_off(app);
        return BR_E_FAULT;
    }
    br_app_motion_push(app);
    int32_t counts = 0;
    br_status_t st = hal->encoder_read(hal->ctx, &counts);
    br_status_t est_st = BR_OK;
    if (st != BR_OK) {
        if (braking) {
            /* the ramp needs the position: on open loop from the ramp's speed */
            return br_app_brake_open_start(app, app->brk_v);
        }
        /* no position this period: hold the last one for enc_stale_periods */
        if (++app->n_stale > app->guard.enc_stale_periods) {
            return latch_open(app, BR_APP_FAULT_ENC_STALE, app->v_meas);
        }
        if (!app->have_counts) {
            /* nothing to hold yet: duty 0 this period, outputs stay enabled
             * (not latched: a good read next period runs the loop) */
            (void)hal->pwm_write(hal->ctx, 0.0f);
            app->last = (br_ctrl_out_t){0};
            return BR_OK;
        }
        /* the position the controller sees: the last good read moved on at
         * the speed measured then over the periods held (held at the count
         * itself the controller would see the axis stop and push it off) */
        const float ahead = br_clampf(app->v_meas * (float)app->n_stale, -1.0e9f, 1.0e9f);
        counts = (int32_t)((uint32_t)app->last_counts + (uint32_t)(int32_t)lrintf(ahead));
        if (app->est.step != NULL) {
            /* the estimator predicts over the period (or holds its estimate) */
            est_st = br_est_period(&app->est, NULL, app->last.tau_Nm, &app->F_hat_N);
        }
    } else {
        /* the periods since the last good read: this one and the held ones */
        const uint32_t periods = app->n_stale + 1u;
        app->n_stale = 0u;
        if (app->have_counts) {
            const int32_t d = br_counts_delta(counts, app->last_counts);
            /* |d| as unsigned: INT32_MIN included */
            const uint32_t mag = (d < 0) ? (uint32_t)0u - (uint32_t)d : (uint32_t)d;
            /* the largest delta of one period, times the periods the delta spans (after
             * held reads the axis moved for all of them; <= 2^30 (1000 + 1), no overflow) */
            if ((uint64_t)mag > (uint64_t)app->guard.enc_max_delta_counts * periods) {
                if (braking) {
                    return br_app_brake_open_start(app, app->brk_v);
                }
                return latch_open(app, BR_APP_FAULT_ENC_JUMP, app->v_meas);
            }
            app->last_counts = counts;
            if (braking) {
                return br_app_brake_period(app, counts, d, periods);
            }
            /* the speed fault and the stuck-encoder model */
            const br_app_fault_t f = br_app_motion_watch(app, d, periods);
            if (f == BR_APP_FAULT_SPEED) {
                return latch_brake(app, f, counts);
            }
            if (f != BR_APP_FAULT_NONE) {
                return latch_open(app, f, app->v_pred); /* ENC_FROZEN: the model's speed */
            }
        }
        app->last_counts = counts;
        app->have_counts = 1;
        if (app->est.step != NULL) {
            /* the estimator sees the count's centre and the torque of the last period */
            const br_meas_t y = {counts, 0.5f};
            est_st = br_est_period(&app->est, &y, app->last.tau_Nm, &app->F_hat_N);
        }
    }
    /* a warning (an outlier measurement skipped, whose prediction stays
     * usable): control goes on and the status is passed up */
    if (BR_FAILED(est_st)) {
        return latch_brake(app, BR_APP_FAULT_ESTIMATOR, counts);
    }
    /* an estimator that keeps rejecting the measurement (and re-anchoring on
     * it) has lost the axis: stop rather than compensate with its estimate */
    if (app->est.step != NULL && lock_lost(app, est_st == BR_W_OUTLIER)) {
        return latch_brake(app, BR_APP_FAULT_LOST_LOCK, counts);
    }
    /* the reference within the machine's speed, acceleration and soft travel */
    br_ref_t r;
    if (br_app_ref_limit(app, ref, counts, &r) != BR_OK) {
        return latch_brake(app, BR_APP_FAULT_CTRL_INPUT, counts); /* the position is trusted */
    }
    const br_app_fault_t lf = br_app_limits_check(app, &r, counts);
    if (lf != BR_APP_FAULT_NONE) {
        return latch_brake(app, lf, counts);
    }
    br_ctrl_in_t in = {counts, r.ref_counts, r.ref_frac_counts, r.ref_omega_radps, app->F_hat_N};
    st = br_ctrl_step(&app->ctrl, &in, &app->last);
    if (st != BR_OK) {
        /* the controller's input or state: braking without it, on open loop */
        return latch_open(app, (st == BR_E_INPUT) ? BR_APP_FAULT_CTRL_INPUT : BR_APP_FAULT_CTRL_STATE,
                          app->v_meas);
    }
    st = hal->pwm_write(hal->ctx, app->last.duty);
    if (st != BR_OK) {
        return latch(app, BR_APP_FAULT_HAL);
    }
    return est_st;
}
