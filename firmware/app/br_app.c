/* The application: configuration -> estimator -> axis loop (br_app.h). */
#include "bristle/br_app.h"

#include <math.h>
#include <stddef.h>

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
    *est = (br_est_t){NULL, NULL};
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
            *est = (br_est_t){mem->pf, br_pf_est_step};
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
            *est = (br_est_t){mem->ukf, br_ukf_est_step};
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

br_status_t br_app_init(br_app_t *app, const br_app_cfg_t *cfg, const br_hal_t *hal, const br_app_mem_t *mem)
{
    if (app == NULL) {
        return BR_E_NULL;
    }
    app->axis.ready = 0;
    br_est_t est;
    const br_status_t st = br_app_est_init(cfg, mem, &est);
    if (st != BR_OK) {
        return st;
    }
    return br_axis_init(&app->axis, hal, cfg->ctrl, (est.step != NULL) ? &est : NULL);
}

br_status_t br_app_step(br_app_t *app, const br_ref_t *ref)
{
    if (app == NULL) {
        return BR_E_NULL;
    }
    return br_axis_step(&app->axis, ref);
}
