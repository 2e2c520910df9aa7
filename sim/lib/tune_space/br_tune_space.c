/* SPDX-License-Identifier: Apache-2.0 */
/* The noise tuning's search space (br_tune_space.h, docs/tuning.md). */
#include "tune_space/br_tune_space.h"

#include <math.h>
#include <string.h>

int br_tune_n_params(int pf) { return pf ? 4 : 5; }

float *br_tune_param_ptr(br_circle_cfg_t *c, int pf, int i)
{
    if (pf) {
        return i < 3 ? &c->pf.est.q_var[i + 1] : &c->pf.est.r_var_rad2;
    }
    return i < 4 ? &c->ukf.est.q_var[i] : &c->ukf.est.r_var_rad2;
}

const char *br_tune_param_name(int pf, int i)
{
    static const char *const pfn[] = {"q_omega", "q_z", "q_gp", "r"};
    static const char *const ukn[] = {"q_theta", "q_omega", "q_z", "q_gp", "r"};
    if (i < 0 || i >= br_tune_n_params(pf)) return "?";
    return pf ? pfn[i] : ukn[i];
}

void br_tune_space(const br_circle_cfg_t *base, int pf, int r_floor, double *x0, double *lo, double *hi)
{
    br_circle_cfg_t c = *base;
    const int n = br_tune_n_params(pf);
    for (int i = 0; i < n; i++) {
        x0[i] = log((double)*br_tune_param_ptr(&c, pf, i));
        lo[i] = x0[i] - 3.0 * log(10.0);
        hi[i] = x0[i] + 3.0 * log(10.0);
    }
    const double rpc = (double)(pf ? c.pf.est.rad_per_count : c.ukf.est.rad_per_count);
    const double floor_r = log(BR_TUNE_QUANT_COUNTS2 * BR_TUNE_R_FLOOR_MARGIN * rpc * rpc);
    if (r_floor) lo[n - 1] = fmax(lo[n - 1], fmin(floor_r, x0[n - 1]));
}

br_nm_cfg_t br_tune_nm_cfg(int n, const double *lo, const double *hi, int max_fev)
{
    br_nm_cfg_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.n = n;
    cfg.init_step = 0.25;
    cfg.xatol = 0.01;
    cfg.fatol = 1e-12;
    cfg.max_fev = max_fev;
    cfg.lo = lo;
    cfg.hi = hi;
    return cfg;
}
