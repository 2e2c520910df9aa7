/* Estimator on an extended model around a nominal one (br_est_ext.h). */
#include "br_est_ext.h"

#include <math.h>
#include <stdio.h>

#define BR_PI 3.14159265358979323846

int br_est_ext_init(br_est_ext_t *e, br_est_t inner, const br_ukf_t *ukf, const br_pf_t *pf,
                    const br_plant_cfg_t *model, double dt_s)
{
    if (!(dt_s > 0.0) || inner.step == NULL || (ukf == NULL) == (pf == NULL)) {
        fprintf(stderr, "br_est_ext: needs a period > 0 and exactly one inner UKF or PF\n");
        return -1;
    }
    if (!(model->delay_s >= 0.0) || model->delay_s / dt_s > (double)(BR_EST_EXT_HIST - 2)) {
        fprintf(stderr, "br_est_ext: delay %g s exceeds the %d-period history\n", model->delay_s,
                BR_EST_EXT_HIST - 2);
        return -1;
    }
    e->inner = inner;
    e->ukf = ukf;
    e->pf = pf;
    e->m = *model;
    e->dt_s = dt_s;
    e->rad_per_count = 2.0 * BR_PI / model->counts_per_rev;
    for (int i = 0; i < BR_EST_EXT_HIST; i++) e->u_hist[i] = 0.0;
    e->u_head = 0;
    e->u_n = 0;
    e->F_cause_N = 0.0;
    return 0;
}

double br_est_ext_cause_force(const br_plant_cfg_t *m, double x, double v, double f)
{
    double F = m->offset_N;
    if (m->ripple_amp_N != 0.0) F += m->ripple_amp_N * sin(2.0 * BR_PI * x / m->ripple_period_m + m->ripple_phase_rad);
    const double k = fmax(0.0, 1.0 + m->grad_per_m * x);
    /* viscous by the direction of motion; the LuGre level by the direction of
     * the bristle deflection (the sign of f), so that the scaled force c f
     * stays continuous through a reversal */
    const double s2 = m->sigma2_Nspm + (v < 0.0 ? m->dsigma2_neg_Nspm : 0.0);
    const double c = f < 0.0 ? (m->Fc_N + m->dFc_neg_N) / m->Fc_N : 1.0;
    return F + k * (s2 * v + c * f) - (m->sigma2_Nspm * v + f);
}

/* the command u[k - j] (j = 0: the newest), 0 before the first */
static double u_ago(const br_est_ext_t *e, int j)
{
    if ((long)j >= e->u_n) return 0.0;
    return e->u_hist[(e->u_head - j + BR_EST_EXT_HIST) % BR_EST_EXT_HIST];
}

br_status_t br_est_ext_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    br_est_ext_t *e = ctx;
    /* the command held over the last period, then the torque that reached the
     * axis over it: delay d = (m + f) dt gives (1 - f) u[k-1-m] + f u[k-2-m] */
    e->u_head = (e->u_head + 1) % BR_EST_EXT_HIST;
    e->u_hist[e->u_head] = (double)u_prev_Nm;
    e->u_n++;
    const double q = e->m.delay_s / e->dt_s;
    const int md = (int)floor(q);
    const double fr = q - md;
    const double u_applied = (1.0 - fr) * u_ago(e, md) + fr * u_ago(e, md + 1);
    const double L = e->m.lead_mprad;
    float f_in = 0.0f;
    const br_status_t st = e->inner.step(e->inner.ctx, y, (float)(u_applied - L * e->F_cause_N), &f_in);
    if (BR_FAILED(st)) return st;
    const float *x;
    int32_t origin;
    if (e->ukf) {
        x = br_ukf_estimate(e->ukf)->mean;
        origin = br_ukf_estimate(e->ukf)->origin_counts;
    } else {
        x = br_pf_estimate(e->pf)->mean;
        origin = br_pf_estimate(e->pf)->origin_counts;
    }
    const double pos = L * ((double)origin * e->rad_per_count + (double)x[BR_X_THETA]);
    const double vel = L * (double)x[BR_X_OMEGA];
    e->F_cause_N = br_est_ext_cause_force(&e->m, pos, vel, (double)f_in);
    *F_hat_N = (float)((double)f_in + e->F_cause_N);
    return st;
}
