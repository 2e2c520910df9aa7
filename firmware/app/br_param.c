/* SPDX-License-Identifier: Apache-2.0 */
/* The run-time parameters (bristle/br_param.h, docs/link.md, "Parameters"). */
#include "bristle/br_param.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

/* a float field as the wire value and back; a uint32_t field likewise */
#define BR_PARAM_GET_F(lv) (lv)
#define BR_PARAM_GET_U(lv) ((float)(lv))
#define BR_PARAM_SET_F(lv, v) ((lv) = (v))
#define BR_PARAM_SET_U(lv, v) ((lv) = (uint32_t)(v))
#define BR_PARAM_INT_F 0
#define BR_PARAM_INT_U 1

/* v within a row's range (the machine file's rules, generated) */
static int in_range(float v, float lo, float hi, int lo_open, int hi_open, int zero_ok, int normal, int is_int)
{
    if (!isfinite(v)) {
        return 0;
    }
    if (v == 0.0f && !zero_ok) {
        return 0;
    }
    if (normal && v != 0.0f && !(fabsf(v) >= FLT_MIN)) {
        return 0;
    }
    if (is_int && v != floorf(v)) {
        return 0;
    }
    const int above_lo = lo_open ? v > lo : v >= lo;
    const int below_hi = hi_open ? v < hi : v <= hi;
    return above_lo && below_hi;
}

br_status_t br_param_check(uint16_t id, unsigned est_mask, float v)
{
#define BR_PARAM_ROW(name, pid, mask, lo, hi, lo_open, hi_open, zero_ok, normal, type, live, field, rpc_pow) \
    if (id == (pid) && ((mask) & est_mask) != 0u) { \
        return in_range(v, lo, hi, lo_open, hi_open, zero_ok, normal, BR_PARAM_INT_##type) ? BR_OK : BR_E_PARAM; \
    }
    BR_LINK_PARAM_TABLE(BR_PARAM_ROW)
#undef BR_PARAM_ROW
    return BR_E_INPUT;
}

br_status_t br_param_get(const br_est_cfg_t *c, uint16_t id, unsigned est_mask, float *v)
{
    if (c == NULL || v == NULL) {
        return BR_E_NULL;
    }
    const float rpc = c->rad_per_count;
    const float rpc2 = rpc * rpc;
#define BR_PARAM_ROW(name, pid, mask, lo, hi, lo_open, hi_open, zero_ok, normal, type, live, field, rpc_pow) \
    if (id == (pid) && ((mask) & est_mask) != 0u) { \
        *v = ((rpc_pow) == 2) ? BR_PARAM_GET_##type(c->field) / rpc2 \
           : ((rpc_pow) == 1) ? BR_PARAM_GET_##type(c->field) / rpc : BR_PARAM_GET_##type(c->field); \
        return BR_OK; \
    }
    BR_LINK_PARAM_TABLE(BR_PARAM_ROW)
#undef BR_PARAM_ROW
    return BR_E_INPUT;
}

br_status_t br_param_set(br_est_cfg_t *c, uint16_t id, unsigned est_mask, float v)
{
    if (c == NULL) {
        return BR_E_NULL;
    }
    br_status_t st = br_param_check(id, est_mask, v);
    if (st != BR_OK) {
        return st;
    }
    br_est_cfg_t cand = *c;
    const float rpc = c->rad_per_count;
    const float rpc2 = rpc * rpc;
#define BR_PARAM_ROW(name, pid, mask, lo, hi, lo_open, hi_open, zero_ok, normal, type, live, field, rpc_pow) \
    if (id == (pid)) { \
        BR_PARAM_SET_##type(cand.field, ((rpc_pow) == 2) ? v * rpc2 : ((rpc_pow) == 1) ? v * rpc : v); \
    }
    BR_LINK_PARAM_TABLE(BR_PARAM_ROW)
#undef BR_PARAM_ROW
    /* the estimators' own rules on the whole configuration (init's) */
    st = br_est_cfg_check(&cand);
    if (st != BR_OK) {
        return st;
    }
    *c = cand;
    return BR_OK;
}

int br_param_live(uint16_t id)
{
#define BR_PARAM_ROW(name, pid, mask, lo, hi, lo_open, hi_open, zero_ok, normal, type, live, field, rpc_pow) \
    if (id == (pid)) { \
        return (live); \
    }
    BR_LINK_PARAM_TABLE(BR_PARAM_ROW)
#undef BR_PARAM_ROW
    return 0;
}
