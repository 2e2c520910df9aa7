/* SPDX-License-Identifier: Apache-2.0 */
/* Actuator-delay identification while the axis runs. See br_dlyid.h and
 * docs/modules/dlyid.md (equations dly1-dly8). */
#include "bristle/br_dlyid.h"

#include <math.h>
#include <stddef.h>

#include "bristle/br_encoder.h"
#include "br_check.h"

/* Longest warm-up, in periods: far beyond any start-up, and a uint32 */
#define BR_DLYID_WARMUP_MAX_PERIODS 1.0e9f

/* (dly1) the period's transition and input, omega' = (u - L F) / J_eff held over T:
 * theta += T omega + T^2/2 (u - L F) / J_eff, omega += T (u - L F) / J_eff; the forgetting
 * e^(-T / memory_s); R + rpc^2 / 12; the friction's variance per period. Returns 1 when
 * every one is finite (a period or mass far out of range overflows them). */
static int constants(br_dlyid_t *id, const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax)
{
    const br_model_cfg_t *mc = ax->model;
    const float T = mc->dt_s;
    const float L = mc->lead_mprad;
    const float inv_J = 1.0f / (mc->J_kgm2 + L * L * mc->M_kg);
    id->b0 = 0.5f * T * T * inv_J;
    id->b1 = T * inv_J;
    id->a02 = -L * id->b0;
    id->a12 = -L * id->b1;
    id->q_force_N2 = c->q_force_N2ps * T;
    const float rpc = ax->rad_per_count;
    id->r_rad2 = ax->r_var_rad2 + rpc * rpc * (1.0f / 12.0f);
    id->forget = expf(-T / c->memory_s);
    id->forget_steady = (c->steady_after_s > 0.0f) ? expf(-T / c->steady_memory_s) : id->forget;
    /* (dly7) the travel over which LuGre's bristles carry the friction's jump at a reversal,
     * in rad at the motor */
    const float s0L = mc->lugre.sigma0_Npm * L; /* > 0 unless the product underflows: refused below */
    id->settle_rad = (s0L > 0.0f) ? BR_DLYID_SETTLE_LENGTHS * ax->gp_max_N / s0L : INFINITY;
    /* b0 and b1 are finite when L b0 and L b1 are (L > 0, br_model_init); R' is finite
     * where the estimator's check (br_est_cfg_check) accepts R and rpc */
    return isfinite(id->a02) && isfinite(id->a12) && isfinite(id->q_force_N2) && id->forget < 1.0f &&
           id->forget_steady < 1.0f && isfinite(id->settle_rad);
}

void br_dlyid_periods(float delay_s, float dt_s, uint32_t *m, float *f)
{
    const float q = delay_s / dt_s;
    *m = (uint32_t)q;
    *f = q - (float)*m;
}

int br_dlyid_cfg_ok(const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax)
{
    const float dt = ax->model->dt_s;
    if (c->n_cand == 0u) {
        return 1;
    }
    if (c->n_cand < 2u || c->n_cand > BR_DLYID_MAX_CAND || !br_finite_pos(c->step_s) ||
        !br_finite_pos(c->q_force_N2ps) || !br_finite_pos(c->memory_s) || !br_finite_nonneg(c->warmup_s) ||
        !(c->warmup_s / dt <= BR_DLYID_WARMUP_MAX_PERIODS) || !(c->switch_ratio > 0.0f && c->switch_ratio < 1.0f)) {
        return 0;
    }
    /* the steady phase: off (0), or a time within the warm-up's bound with its memory and ratio */
    if (!br_finite_nonneg(c->steady_after_s) || !(c->steady_after_s / dt <= BR_DLYID_WARMUP_MAX_PERIODS) ||
        (c->steady_after_s > 0.0f && (!br_finite_pos(c->steady_memory_s) ||
                                      !(c->steady_switch_ratio > 0.0f && c->steady_switch_ratio < 1.0f)))) {
        return 0;
    }
    br_dlyid_t scratch;
    return constants(&scratch, c, ax);
}

void br_dlyid_init(br_dlyid_t *id, const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax)
{
    const br_model_cfg_t *mc = ax->model;
    const float T = mc->dt_s;
    id->n_switch = 0u;
    id->primed = 0;
    id->k = 0u;
    id->cur = 0u;
    id->warmup = 0u;
    id->steady = UINT32_MAX;
    /* off, or unchecked: nothing below is read (br_dlyid_step returns first) */
    const uint32_t n = c->n_cand;
    if (n == 0u || n > BR_DLYID_MAX_CAND) {
        return; /* off (br_dlyid_step does nothing), or a configuration no check has seen */
    }
    (void)constants(id, c, ax); /* finite: checked by br_dlyid_cfg_ok */
    id->warmup = (uint32_t)(c->warmup_s / T + 0.5f);
    if (c->steady_after_s > 0.0f) {
        id->steady = (uint32_t)(c->steady_after_s / T + 0.5f);
    }
    for (uint32_t j = 0; j <= n; j++) {
        /* the candidates j step_s; slot n the configured delay, where the estimator starts
         * (br_est_delay_init's m and f) */
        br_dlyid_periods((j < n) ? (float)j * c->step_s : mc->causes.delay_s, T, &id->cm[j], &id->cf[j]);
    }
    id->cur = n;
}

/* (dly2) the first measurement: every filter at theta = frac rpc, at rest, F = 0, P0 */
static void prime(br_dlyid_t *id, const br_dlyid_axis_t *ax, int32_t counts, float frac, uint32_t n)
{
    const float rpc = ax->rad_per_count;
    const float T = ax->model->dt_s;
    for (uint32_t j = 0; j <= n; j++) {
        id->x[j][0] = frac * rpc;
        id->x[j][1] = 0.0f;
        id->x[j][2] = 0.0f;
        id->J[j] = 0.0f;
    }
    for (int i = 0; i < BR_DLYID_NX; i++) {
        for (int j = 0; j < BR_DLYID_NX; j++) {
            id->P[i][j] = 0.0f;
        }
    }
    /* theta within the measurement noise, omega within a count per period, F within g_p's range */
    id->P[0][0] = id->r_rad2;
    id->P[1][1] = (rpc / T) * (rpc / T);
    id->P[2][2] = ax->gp_max_N * ax->gp_max_N;
    id->origin_counts = counts;
    id->k = 0u;
    id->dir = 0;
    id->settle_left_rad = 0.0f;
    id->run_rad = 0.0f;
    id->primed = 1;
}

/* (dly3) P- = A P A^T + diag(0, 0, q_F), A = [1 T a02; 0 1 a12; 0 0 1]; then the gain
 * K = P-[:,0] / S, S = P-_00 + R, and P+ = P- - K P-[0,:]. P does not depend on the
 * data: with the finite constants br_dlyid_cfg_ok requires it is the Riccati recursion
 * of an observable system (theta measured), bounded. */
static void covariance(br_dlyid_t *id, float T, float K[BR_DLYID_NX])
{
    const float A[BR_DLYID_NX][BR_DLYID_NX] = {{1.0f, T, id->a02}, {0.0f, 1.0f, id->a12}, {0.0f, 0.0f, 1.0f}};
    float AP[BR_DLYID_NX][BR_DLYID_NX], Pm[BR_DLYID_NX][BR_DLYID_NX];
    for (int i = 0; i < BR_DLYID_NX; i++) {
        for (int j = 0; j < BR_DLYID_NX; j++) {
            float s = 0.0f;
            for (int l = 0; l < BR_DLYID_NX; l++) {
                s += A[i][l] * id->P[l][j];
            }
            AP[i][j] = s;
        }
    }
    for (int i = 0; i < BR_DLYID_NX; i++) {
        for (int j = 0; j < BR_DLYID_NX; j++) {
            float s = 0.0f;
            for (int l = 0; l < BR_DLYID_NX; l++) {
                s += AP[i][l] * A[j][l];
            }
            Pm[i][j] = s;
        }
    }
    Pm[2][2] += id->q_force_N2;
    const float S = Pm[0][0] + id->r_rad2;
    for (int i = 0; i < BR_DLYID_NX; i++) {
        K[i] = Pm[i][0] / S;
    }
    for (int i = 0; i < BR_DLYID_NX; i++) {
        for (int j = 0; j < BR_DLYID_NX; j++) {
            id->P[i][j] = Pm[i][j] - K[i] * Pm[0][j];
        }
    }
    /* P+ <- (P+ + P+^T) / 2 */
    for (int i = 0; i < BR_DLYID_NX; i++) {
        for (int j = i + 1; j < BR_DLYID_NX; j++) {
            const float m = 0.5f * (id->P[i][j] + id->P[j][i]);
            id->P[i][j] = m;
            id->P[j][i] = m;
        }
    }
}

/* (dly7) a velocity reversal after a run of at least settle_rad: the friction jumps
 * by up to 2 g_p,max over a few presliding lengths, which no candidate's random walk
 * follows, and the innovations then favour whichever delay happens to match the
 * controller's reaction to the jump. From such a change of the sign of the filter in
 * use's velocity (beyond one count per period, w_min, so that rest does not count)
 * the innovations are not scored until the axis has travelled settle_rad. A reversal
 * after a shorter run (an oscillation, a dither) is not one: the bristles never left
 * presliding, where the friction is a spring and does not jump. */
static void reversal(br_dlyid_t *id, float w_min, float T)
{
    const float w = id->x[id->cur][1];
    const int32_t s = (w > w_min) ? 1 : ((w < -w_min) ? -1 : 0);
    const float step = fabsf(w) * T;
    if (s != 0 && id->dir != 0 && s != id->dir) {
        if (id->run_rad >= id->settle_rad) {
            id->settle_left_rad = id->settle_rad;
        }
        id->run_rad = 0.0f;
    } else {
        id->settle_left_rad -= step;
        id->run_rad += step;
    }
    if (s != 0) {
        id->dir = s;
    }
}

int br_dlyid_step(br_dlyid_t *id, const br_dlyid_cfg_t *c, const br_dlyid_axis_t *ax, int32_t counts, float frac,
                  const float u_Nm[BR_DLYID_MAX_SLOTS])
{
    const uint32_t n = c->n_cand;
    if (n == 0u || n > BR_DLYID_MAX_CAND) {
        return 0;
    }
    if (!id->primed) {
        prime(id, ax, counts, frac, n);
        return 0;
    }
    const float rpc = ax->rad_per_count;
    float K[BR_DLYID_NX];
    const float T = ax->model->dt_s;
    reversal(id, rpc / T, T);
    const int scored = !(id->settle_left_rad > 0.0f);
    /* the phase: the steady one's forgetting and ratio from id->steady periods on */
    const int steady = c->steady_after_s > 0.0f && id->k >= id->steady;
    const float forget = steady ? id->forget_steady : id->forget;
    const float ratio = steady ? c->steady_switch_ratio : c->switch_ratio;
    covariance(id, T, K);
    /* theta re-expressed relative to the new count (wrap-safe), the measurement frac rpc */
    const float shift = (float)br_counts_delta(counts, id->origin_counts) * rpc;
    const float y_rel = frac * rpc;
    int finite = 1;
    /* the candidates and the configured delay's slot n */
    for (uint32_t j = 0; j <= n; j++) {
        float *x = id->x[j];
        /* (dly4) candidate j's prediction with the torque its delay brings: u_j = (1 - f_j)
         * u[k-1-m_j] + f_j u[k-2-m_j] (the caller's, from its command history) */
        const float u = u_Nm[j];
        const float th = x[0] + T * x[1] + id->a02 * x[2] + id->b0 * u - shift;
        const float om = x[1] + id->a12 * x[2] + id->b1 * u;
        /* (dly5) innovation nu_j = y - theta-_j, update x+ = x- + K nu_j, J_j <- forget J_j + nu_j^2 */
        const float nu = y_rel - th;
        x[0] = th + K[0] * nu;
        x[1] = om + K[1] * nu;
        x[2] = x[2] + K[2] * nu;
        if (scored) {
            id->J[j] = forget * id->J[j] + nu * nu;
        }
        finite = finite && isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(id->J[j]);
    }
    id->origin_counts = counts;
    if (!finite) {
        id->primed = 0; /* the bank restarts at the next measurement */
        return 0;
    }
    if (id->k < UINT32_MAX) {
        id->k++;
    }
    if (id->k < id->warmup) {
        return 0;
    }
    /* (dly6) the best candidate takes over when its sum is below switch_ratio times the
     * sum of the one in use ... */
    uint32_t best = id->cur;
    if (!steady) {
        for (uint32_t j = 0; j <= n; j++) {
            if (id->J[j] < id->J[best]) {
                best = j;
            }
        }
        if (!(id->J[best] < ratio * id->J[id->cur])) {
            return 0;
        }
    } else {
        /* (dly8) ... in the steady phase below rho^d_j times it for a candidate d_j steps along
         * the grid from the delay in use (the configured delay: from the candidate nearest it,
         * the last one for a delay beyond the grid, which it may refine to: d_j = 0), the best
         * the one of the smallest J_j / rho^d_j: a far jump needs a far better sum. A delay
         * does not jump, and in a closed loop whose command follows the innovations, or at a
         * load's onset, a far candidate wins a sum by chance (docs/modules/dlyid.md, "One step
         * at a time"). The configured delay's slot is where the bank starts, not a step. */
        uint32_t at = id->cur;
        if (at == n) {
            const float g = ((float)id->cm[n] + id->cf[n]) * T / c->step_s + 0.5f;
            at = (g < (float)(n - 1u)) ? (uint32_t)g : n - 1u;
        }
        float w_best = 1.0f;
        for (uint32_t j = 0; j < n; j++) {
            const uint32_t d = (j > at) ? j - at : at - j;
            float w = 1.0f;
            for (uint32_t i = 0; i < d; i++) {
                w *= ratio;
            }
            /* J_j / w < J_best / w_best, without the division */
            if (j != id->cur && id->J[j] * w_best < id->J[best] * w) {
                best = j;
                w_best = w;
            }
        }
        if (best == id->cur) {
            return 0;
        }
    }
    /* ... and the one in use explains the motion worse than the noise allows */
    const float J_noise = BR_DLYID_NOISE_FACTOR * (id->r_rad2 + id->P[0][0]) / (1.0f - forget);
    if (!(id->J[id->cur] > J_noise)) {
        return 0;
    }
    id->cur = best;
    if (id->n_switch < UINT32_MAX) {
        id->n_switch++;
    }
    return 1;
}
