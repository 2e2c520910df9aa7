/* Configuration and step-input checks shared by the friction estimators. See br_est.h. */
#include "bristle/br_est.h"

#include <math.h>

static int finite_pos(float v) { return isfinite(v) && v > 0.0f; }

br_status_t br_est_check_common(const float q_var[4], float r_var_rad2, float gp0_N, float gp_min_N, float gp_max_N,
                                float outlier_sigma, uint32_t reanchor_after, float rad_per_count)
{
    for (int i = 0; i < 4; i++) {
        if (!isfinite(q_var[i]) || q_var[i] < 0.0f) {
            return BR_E_PARAM;
        }
    }
    if (!finite_pos(r_var_rad2) || !finite_pos(outlier_sigma) || !finite_pos(rad_per_count) || reanchor_after < 1u) {
        return BR_E_PARAM;
    }
    if (!finite_pos(gp_min_N) || !isfinite(gp_max_N) || !(gp_max_N > gp_min_N) ||
        !(gp0_N >= gp_min_N && gp0_N <= gp_max_N)) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

br_status_t br_est_check_step(const br_meas_t *y, float u_prev_Nm)
{
    if (!isfinite(u_prev_Nm) || !isfinite(y->frac) || y->frac < 0.0f || y->frac > 1.0f) {
        return BR_E_INPUT;
    }
    return BR_OK;
}
