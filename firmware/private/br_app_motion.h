/* SPDX-License-Identifier: Apache-2.0 */
/* The drive protections of br_app_step (private to the application):
 * reference limiter, speed, following and travel limits, the stuck-encoder
 * model and the braking ramp (docs/modules/app.md, "Drive protections"). */
#ifndef BR_APP_MOTION_H
#define BR_APP_MOTION_H

#include "bristle/br_app.h"

/* BR_OK or BR_E_PARAM (a limit non-finite, non-positive, or soft limits
 * that leave no travel). */
br_status_t br_app_motion_check(const br_app_motion_cfg_t *m);

/* Clears the limiter, the model and the ramp; the limits in counts at the
 * controller's period (at init and at every arm). */
void br_app_motion_reset(br_app_t *app);

/* The reference handed to the controller: ref as it is while within the
 * speed, acceleration and soft travel limits, else the limiter's (flagged
 * in app->ref_limited). BR_E_INPUT for a non-finite or out-of-range ref. */
br_status_t br_app_ref_limit(br_app_t *app, const br_ref_t *ref, int32_t counts, br_ref_t *out);

/* One good read spanning `periods` periods with delta d: the speed fault and
 * the stuck-encoder model (ENC_FROZEN), BR_APP_FAULT_NONE when neither. */
br_app_fault_t br_app_motion_watch(br_app_t *app, int32_t d, uint32_t periods);
/* Every period the loop runs (before the read): the last command into the
 * actuator-delay history, the force that reached the axis over the period
 * that ended into app->mot_F_N (the stuck-encoder model's force). */
void br_app_motion_push(br_app_t *app);

/* FOLLOWING or TRAVEL for the reference r handed to the controller and the
 * count, else BR_APP_FAULT_NONE. */
br_app_fault_t br_app_limits_check(const br_app_t *app, const br_ref_t *r, int32_t counts);

/* The braking ramp from the last measured speed at count `counts`; runs its
 * first period. Always BR_E_FAULT. */
br_status_t br_app_brake_start(br_app_t *app, int32_t counts);

/* One braking period on a good read (delta d over `periods`). BR_E_FAULT. */
br_status_t br_app_brake_period(br_app_t *app, int32_t counts, int32_t d, uint32_t periods);

/* The open-loop brake from v (counts per period, the last trusted speed):
 * stop OPEN, its first period. Always BR_E_FAULT. */
br_status_t br_app_brake_open_start(br_app_t *app, float v_counts_per_period);

/* One open-loop braking period (no encoder read): the braking duty, outputs
 * off when the periods are done or the write fails. BR_E_FAULT. */
br_status_t br_app_brake_open_period(br_app_t *app);

/* Duty 0 and the outputs off (stop OFF). */
void br_app_outputs_off(br_app_t *app);

#endif
