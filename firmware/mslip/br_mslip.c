/* SPDX-License-Identifier: Apache-2.0 */
/* Maxwell-slip friction, clamp form, float32. Equations in br_mslip.h and
 * docs/modules/mslip.md. */
#include "bristle/br_mslip.h"

#include <math.h>
#include <stddef.h>

#include "br_check.h"
#include "br_mslip_kernel.h"

br_status_t br_mslip_cfg_check(const br_mslip_cfg_t *cfg)
{
    if (cfg == NULL) {
        return BR_E_NULL;
    }
    if (cfg->n < 0 || cfg->n > BR_MSLIP_MAX || !br_finite_nonneg(cfg->sigma2_Nspm)) {
        return BR_E_PARAM;
    }
    float sum = 0.0f;
    int i;
    for (i = 0; i < cfg->n; i++) {
        if (!br_finite_pos(cfg->k_Npm[i]) || !br_finite_pos(cfg->share[i]) || cfg->share[i] > 1.0f) {
            return BR_E_PARAM;
        }
        sum += cfg->share[i];
    }
    /* the shares split the Stribeck level: they sum to 1 */
    if (cfg->n > 0 && !(fabsf(sum - 1.0f) <= BR_MSLIP_SHARE_TOL)) {
        return BR_E_PARAM;
    }
    return BR_OK;
}

br_status_t br_mslip_init(br_mslip_t *s, const br_mslip_cfg_t *cfg)
{
    if (s == NULL || cfg == NULL) {
        return BR_E_NULL;
    }
    s->ready = 0;
    const br_status_t st = br_mslip_cfg_check(cfg);
    if (st != BR_OK) {
        return st;
    }
    if (cfg->n < 1) {
        return BR_E_PARAM;
    }
    s->cfg = *cfg;
    int i;
    for (i = 0; i < BR_MSLIP_MAX; i++) {
        /* Delta_i = c_i g, c_i = share_i / k_i */
        s->c_mpN[i] = (i < cfg->n) ? cfg->share[i] / cfg->k_Npm[i] : 0.0f;
    }
    br_mslip_reset(s);
    s->ready = 1;
    return BR_OK;
}

void br_mslip_reset(br_mslip_t *s)
{
    int i;
    for (i = 0; i < BR_MSLIP_MAX; i++) {
        s->z_m[i] = 0.0f;
    }
}

br_status_t br_mslip_step(br_mslip_t *s, float dx_m, float v_mps, float g_N, float *F_N)
{
    if (s == NULL || F_N == NULL) {
        return BR_E_NULL;
    }
    if (!s->ready) {
        return BR_E_STATE;
    }
    if (!isfinite(dx_m) || !isfinite(v_mps) || !br_finite_pos(g_N)) {
        return BR_E_INPUT;
    }
    const br_mslip_cfg_t *c = &s->cfg;
    float z1[BR_MSLIP_MAX];
    /* z_i <- clamp(z_i + dx, -Delta_i, Delta_i); F = sum k_i z_i + sigma2 v */
    const float F = br_msk_move(c->n, c->k_Npm, s->c_mpN, s->z_m, z1, dx_m, g_N) + c->sigma2_Nspm * v_mps;
    if (!isfinite(F)) {
        return BR_E_NUMERIC; /* the state is kept */
    }
    int i;
    for (i = 0; i < c->n; i++) {
        s->z_m[i] = z1[i];
    }
    *F_N = F;
    return BR_OK;
}
