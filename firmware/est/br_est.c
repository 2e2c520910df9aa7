/* SPDX-License-Identifier: Apache-2.0 */
/* Configuration and step-input checks shared by the friction estimators. See br_est.h. */
#include "bristle/br_est.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

#include "br_check.h"

/* What the delay identification reads of cfg. */
static br_dlyid_axis_t dlyid_axis(const br_est_cfg_t *cfg)
{
    const br_dlyid_axis_t ax = {&cfg->model, cfg->rad_per_count, cfg->r_var_rad2, cfg->gp_max_N};
    return ax;
}

int br_est_var_ok(float v, int zero_ok)
{
    if (v == 0.0f) {
        return zero_ok;
    }
    return isfinite(v) && v >= FLT_MIN && v <= BR_EST_VAR_MAX;
}

float br_est_gate_f2(const br_est_cfg_t *cfg, float v)
{
    const float den = cfg->outlier_sigma * sqrtf(v);
    if (!(den > 0.0f) || !isfinite(den)) {
        return 1.0f; /* no spread (v = 0) or none to scale: the thesis gate, never a 0/0 */
    }
    /* eq. G1: f = 1 + d / (g sqrt(v)) */
    const float f = 1.0f + cfg->outlier_transient_rad / den;
    return f * f;
}

br_status_t br_est_cfg_check(const br_est_cfg_t *cfg)
{
    if (cfg == NULL) {
        return BR_E_NULL;
    }
    br_model_t model;
    const br_status_t st = br_model_init(&model, &cfg->model);
    if (st != BR_OK) {
        return st;
    }
    if (!br_finite_pos(cfg->rad_per_count) || !br_finite_pos(cfg->outlier_sigma) ||
        cfg->outlier_sigma > BR_EST_GATE_MAX_SIGMA || cfg->reanchor_after < 1u) {
        return BR_E_PARAM;
    }
    /* the gate's transient term: a displacement, 0 (off) up to BR_EST_GATE_MAX_TRANSIENT_COUNTS */
    if (!(cfg->outlier_transient_rad >= 0.0f &&
          cfg->outlier_transient_rad <= BR_EST_GATE_MAX_TRANSIENT_COUNTS * cfg->rad_per_count)) {
        return BR_E_PARAM;
    }
    if (!br_est_delay_fits(cfg->model.causes.delay_s, cfg->model.dt_s)) {
        return BR_E_PARAM;
    }
    if (!(cfg->comp_ahead_periods >= 0.0f && cfg->comp_ahead_periods <= BR_EST_AHEAD_MAX_PERIODS)) {
        return BR_E_PARAM;
    }
    for (int i = 0; i < BR_NX; i++) {
        if (!br_est_var_ok(cfg->q_var[i], 1)) {
            return BR_E_PARAM;
        }
    }
    const float rpc2 = cfg->rad_per_count * cfg->rad_per_count;
    if (!br_est_var_ok(cfg->r_var_rad2, 0) || !(cfg->r_var_rad2 >= BR_EST_R_MIN_COUNTS2 * rpc2)) {
        return BR_E_PARAM;
    }
    if (!br_finite_pos(cfg->gp_min_N) || !isfinite(cfg->gp_max_N) || !(cfg->gp_max_N > cfg->gp_min_N) ||
        !(cfg->gp0_N >= cfg->gp_min_N && cfg->gp0_N <= cfg->gp_max_N)) {
        return BR_E_PARAM;
    }
    /* last: the bank's constants use g_p's range and the model's (checked above) */
    const br_dlyid_axis_t ax = dlyid_axis(cfg);
    if (!br_dlyid_cfg_ok(&cfg->delay_id, &ax)) {
        return BR_E_PARAM;
    }
    /* the largest candidate within the command history (br_est_delay_torque's m <= HIST - 2) */
    const br_dlyid_cfg_t *id = &cfg->delay_id;
    if (id->n_cand > 0u && !br_est_delay_fits((float)(id->n_cand - 1u) * id->step_s, cfg->model.dt_s)) {
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

int br_est_delay_fits(float delay_s, float dt_s)
{
    return delay_s <= (float)(BR_EST_DELAY_HIST - 2u) * dt_s;
}

void br_est_delay_init(br_est_delay_t *d, const br_est_cfg_t *cfg)
{
    br_est_delay_reset(d, cfg->model.causes.delay_s, cfg->model.dt_s,
                       cfg->model.causes.delay_s > 0.0f || cfg->delay_id.n_cand > 0u);
}

void br_est_delay_reset(br_est_delay_t *d, float delay_s, float dt_s, int on)
{
    br_dlyid_periods(delay_s, dt_s, &d->m, &d->f);
    d->on = on;
    d->head = 0u;
    d->n = 0u;
    for (uint32_t i = 0; i < BR_EST_DELAY_HIST; i++) {
        d->u[i] = 0.0f;
    }
}

/* the command j periods before the newest (j = 0: the newest), 0 before the first */
static float cmd_ago(const br_est_delay_t *d, uint32_t j)
{
    return (j < d->n) ? d->u[(d->head + BR_EST_DELAY_HIST - j) % BR_EST_DELAY_HIST] : 0.0f;
}

float br_est_delay_apply(br_est_delay_t *d, float u_prev_Nm)
{
    if (!d->on) {
        return u_prev_Nm;
    }
    d->head = (d->head + 1u) % BR_EST_DELAY_HIST;
    d->u[d->head] = u_prev_Nm;
    if (d->n < BR_EST_DELAY_HIST) {
        d->n++;
    }
    return br_est_delay_torque(d, d->m, d->f);
}

float br_est_delay_torque(const br_est_delay_t *d, uint32_t m, float f)
{
    /* u_a = (1 - f) u[k-1-m] + f u[k-2-m] */
    return (1.0f - f) * cmd_ago(d, m) + f * cmd_ago(d, m + 1u);
}

/* u[k + i], the command of period k + i (u[k - 1] = u_prev, the newest):
 * from the history for i < -1, u_prev for the ones not yet computed (i >= -1) */
static float cmd_at(const br_est_delay_t *d, int32_t i, float u_prev_Nm)
{
    return (i >= -1) ? u_prev_Nm : cmd_ago(d, (uint32_t)(-i - 1));
}

float br_est_comp_N(const br_est_cfg_t *cfg, const br_model_t *m, const br_est_delay_t *d,
                    const float x[BR_NX], float p0_m, float u_prev_Nm, float F_ext_N, float F_hat_N)
{
    const float lambda = cfg->comp_ahead_periods;
    /* no lead; and, for a caller whose configuration br_est_cfg_check did not see,
     * no carry beyond the bounds that keep the loop below bounded */
    if (!(lambda > 0.0f && lambda <= BR_EST_AHEAD_MAX_PERIODS) || (d->on && d->m > BR_EST_DELAY_HIST - 2u)) {
        return F_hat_N;
    }
    /* the delay dm + df periods (none when off) */
    const int32_t dm = d->on ? (int32_t)d->m : 0;
    const float df = d->on ? d->f : 0.0f;
    /* (ahead 1) H = delay / dt + lambda = (dm + df) + lambda periods: n whole ones and fr of
     * the next; n <= BR_EST_DELAY_HIST - 2 + 1 + BR_EST_AHEAD_MAX_PERIODS */
    const float h = ((float)dm + df) + lambda;
    const uint32_t n = (uint32_t)h;
    const float fr = h - (float)n;
    float cur[BR_NX], nxt[BR_NX];
    for (int i = 0; i < BR_NX; i++) {
        cur[i] = x[i];
    }
    /* the external force's torque at the motor, held over the carry */
    const float u_ext = m->cfg.lead_mprad * F_ext_N;
    /* (ahead 2) the whole periods, then the part-period's end when fr > 0 (at least one
     * step: H > 0; the first checks x) */
    const uint32_t steps = n + ((fr > 0.0f) ? 1u : 0u);
    for (uint32_t j = 0; j < steps; j++) {
        /* (ahead 3) the torque reaching the axis over period k + j: (1 - f) u[k+j-m] + f u[k+j-m-1],
         * less the external force's L F_ext */
        const int32_t a = (int32_t)j - dm;
        const float u = (1.0f - df) * cmd_at(d, a, u_prev_Nm) + df * cmd_at(d, a - 1, u_prev_Nm) - u_ext;
        if (br_model_step_at(m, cur, p0_m, u, nxt) != BR_OK) {
            return F_hat_N;
        }
        if (j < n) {
            for (int i = 0; i < BR_NX; i++) {
                cur[i] = nxt[i];
            }
        }
    }
    /* (ahead 4) f_c at t + H dt, between the ends of the last period at fr of it */
    const float f0 = br_model_fcomp_N(m, x, p0_m);
    const float fc = br_model_fcomp_N(m, cur, p0_m);
    const float fh = (fr > 0.0f) ? fc + fr * (br_model_fcomp_N(m, nxt, p0_m) - fc) : fc;
    /* (ahead 5) F_comp = F_hat + f_H - f_c(x); a force beyond float range (finite states
     * at speeds far beyond any axis'): the filtered estimate */
    const float F = F_hat_N + (fh - f0);
    return isfinite(F) ? F : F_hat_N;
}

void br_est_dlyid_init(br_dlyid_t *id, const br_est_cfg_t *cfg)
{
    const br_dlyid_axis_t ax = dlyid_axis(cfg);
    br_dlyid_init(id, &cfg->delay_id, &ax);
}

void br_est_dlyid_step(br_dlyid_t *id, const br_est_cfg_t *cfg, const br_meas_t *y, br_est_delay_t *d)
{
    const uint32_t n = cfg->delay_id.n_cand;
    if (n == 0u || n > BR_DLYID_MAX_CAND) {
        return; /* off (or a configuration no check has seen): the history is not read */
    }
    /* (dly4) each slot's torque: u_j = (1 - f_j) u[k-1-m_j] + f_j u[k-2-m_j] */
    float u[BR_DLYID_MAX_SLOTS];
    for (uint32_t j = 0; j <= n; j++) {
        u[j] = br_est_delay_torque(d, id->cm[j], id->cf[j]);
    }
    const br_dlyid_axis_t ax = dlyid_axis(cfg);
    if (br_dlyid_step(id, &cfg->delay_id, &ax, y->counts, y->frac, u)) {
        d->m = id->cm[id->cur];
        d->f = id->cf[id->cur]; /* d->on: set by br_est_delay_init for the bank */
    }
}

br_status_t br_est_period(const br_est_t *e, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    if (e == NULL || e->step == NULL || F_hat_N == NULL) {
        return BR_E_NULL;
    }
    if (y != NULL) {
        return e->step(e->ctx, y, u_prev_Nm, F_hat_N);
    }
    /* no measurement: predict, or hold the estimate */
    return (e->predict != NULL) ? e->predict(e->ctx, u_prev_Nm, F_hat_N) : BR_OK;
}

br_status_t br_est_restart(const br_est_t *e)
{
    if (e == NULL) {
        return BR_E_NULL;
    }
    return (e->reset != NULL) ? e->reset(e->ctx) : BR_OK;
}
