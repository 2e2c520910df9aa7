/* SPDX-License-Identifier: Apache-2.0 */
/* The delay identification's configuration check, for br_est_cfg_check
 * (private to firmware/est). */
#ifndef BR_DLYID_CHECK_H
#define BR_DLYID_CHECK_H

#include "bristle/br_est.h"

/* 1 when cfg->delay_id is off (n_cand = 0) or within br_dlyid_cfg_t's ranges
 * at the period cfg->model.dt_s (checked before: finite, > 0). */
int br_dlyid_cfg_ok(const br_est_cfg_t *cfg);

#endif
