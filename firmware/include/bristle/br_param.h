/* SPDX-License-Identifier: Apache-2.0 */
/* The run-time parameters: an estimator's settings read and written by id
 * (docs/link.md, "Parameters"). The catalogue is generated
 * (bristle_gen/link/br_link_params.h, from python/bristle/link/params.py with
 * the machine file's ranges, firmware/design/gen_link.py). A write is
 * accepted when the value is in the machine file's range for it and the
 * configuration it makes passes the estimators' own check (br_est_cfg_check).
 * These functions change a br_est_cfg_t the caller owns (a RAM copy); when it
 * reaches the filter is the caller's (br_svc: at the arm, or at once for a
 * live parameter). */
#ifndef BR_PARAM_H
#define BR_PARAM_H

#include <stdint.h>

#include "bristle/br_est.h"
#include "bristle/br_status.h"
#include "bristle_gen/link/br_link_params.h"

/* BR_OK when id is a parameter of the estimators in est_mask
 * (BR_LINK_PARAM_EST_PF / _UKF) and v is within its range (the machine
 * file's rules: the generated table); BR_E_INPUT: no such parameter here;
 * BR_E_PARAM: v non-finite, out of range, 0 where 0 is not allowed, subnormal
 * where a normal float is required, or not whole for an integer. */
br_status_t br_param_check(uint16_t id, unsigned est_mask, float v);

/* The value of parameter id in c, in the parameter's unit (a variance in
 * counts^2: the configuration's rad^2 divided by rad_per_count^2).
 * BR_E_NULL, BR_E_INPUT (no such parameter here). */
br_status_t br_param_get(const br_est_cfg_t *c, uint16_t id, unsigned est_mask, float *v);

/* br_param_check, then the value into a copy of c, br_est_cfg_check on the
 * copy, and only then into c. BR_E_NULL, br_param_check's statuses, or
 * br_est_cfg_check's (c unchanged on any error). */
br_status_t br_param_set(br_est_cfg_t *c, uint16_t id, unsigned est_mask, float v);

/* 1 when parameter id may change while the axis runs (it is read every
 * period), 0 when it waits for the next arm (or is unknown). */
int br_param_live(uint16_t id);

#endif
