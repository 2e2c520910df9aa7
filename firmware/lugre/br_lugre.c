/* SPDX-License-Identifier: Apache-2.0 */
/* LuGre dynamic friction, float32. Equations in br_lugre.h and docs/modules/lugre.md. */
#include "bristle/br_lugre.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"
#include "br_lugre_kernel.h"

br_status_t br_lugre_cfg_check(const br_lugre_cfg_t *cfg)
{
    if (cfg == NULL) {
        return BR_E_NULL;
    }
    if (!br_finite_pos(cfg->sigma0_Npm) || !br_finite_pos(cfg->Fc_N) || !br_finite_pos(cfg->vs_mps)) {
        return BR_E_PARAM;
    }
    if (!br_finite_nonneg(cfg->sigma1_Nspm)) {
        return BR_E_PARAM;
    }
    if (!isfinite(cfg->Fs_N) || cfg->Fs_N < cfg->Fc_N) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

float br_lugre_g_N(const br_lugre_cfg_t *cfg, float v_mps)
{
    /* eq. 5 */
    return br_lk_g_N(cfg->Fc_N, cfg->Fs_N, cfg->vs_mps, v_mps);
}

float br_lugre_zdot_mps(const br_lugre_cfg_t *cfg, float z_m, float v_mps, float g_N)
{
    /* eq. 4 */
    return br_lk_zdot_mps(cfg->sigma0_Npm, v_mps, z_m, g_N);
}

float br_lugre_force_N(const br_lugre_cfg_t *cfg, float z_m, float zdot_mps)
{
    /* eq. 3 */
    return br_lk_force_N(cfg->sigma0_Npm, cfg->sigma1_Nspm, z_m, zdot_mps);
}

float br_lugre_z_advance_m(const br_lugre_cfg_t *cfg, float z_m, float dx_m, float g_N)
{
    if (dx_m == 0.0f) {
        return z_m;
    }
    /* eq. 4 over the displacement, exact and bounded */
    return br_lk_move(cfg->sigma0_Npm, z_m, dx_m, g_N).z1_m;
}

br_status_t br_lugre_init(br_lugre_t *s, const br_lugre_cfg_t *cfg)
{
    if (s == NULL) {
        return BR_E_NULL;
    }
    s->ready = 0;
    br_status_t st = br_lugre_cfg_check(cfg);
    if (st != BR_OK) {
        return st;
    }
    s->cfg = *cfg;
    s->z_m = 0.0f;
    s->ready = 1;
    return BR_OK;
}

br_status_t br_lugre_step(br_lugre_t *s, float v_mps, float dt_s, float *F_N)
{
    if (s == NULL || F_N == NULL) {
        return BR_E_NULL;
    }
    if (!s->ready) {
        return BR_E_STATE;
    }
    if (!isfinite(v_mps) || !br_finite_pos(dt_s)) {
        return BR_E_INPUT;
    }
    const br_lugre_cfg_t *c = &s->cfg;
    float g = br_lugre_g_N(c, v_mps);
    /* Displacement-exact bristle update (bounded at every speed). */
    float z1 = br_lugre_z_advance_m(c, s->z_m, v_mps * dt_s, g);
    if (!isfinite(z1)) {
        return BR_E_NUMERIC;
    }
    s->z_m = z1;
    *F_N = br_lugre_force_N(c, z1, br_lugre_zdot_mps(c, z1, v_mps, g));
    return BR_OK;
}
