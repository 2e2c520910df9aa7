/* A friction estimator on an extended model (the causes of a diagnosis'
 * model.json), built around the firmware's estimator on the nominal model
 * (UKF or PF, unchanged): docs/diagnose.md, "Control terms".
 *
 * The extended model adds to the nominal friction a force that is a known
 * function of the estimated state, and delays the torque:
 *
 *   F_cause(x, v, f) = offset + A sin(2 pi x / P + phase)
 *                      + k(x) (sigma2_d v + c_d f) - (sigma2 v + f)
 *   k(x) = max(0, 1 + s x);  sigma2_d = sigma2 + dsigma2 when v < 0, else sigma2;
 *   c_d = (Fc + dFc) / Fc when f < 0 (bristles deflected towards -x), else 1
 *
 * with f the inner estimator's LuGre friction. Each step the inner estimator
 * is given the torque that reached the axis over the last period (the
 * command of delay_s earlier, zero-order hold) minus L F_cause at the last
 * estimate, so it sees the nominal model's dynamics; the compensation is
 * f + F_cause at the new estimate. The asymmetry scales the friction rather
 * than the bristle dynamics inside the estimator: exact while sliding, an
 * approximation within a reversal's presliding (scaling by the sign of f
 * keeps it continuous there).
 *
 * This is the simulator side of the firmware change proposed in
 * docs/diagnose.md: there the same terms would sit in br_model_deriv. */
#ifndef BR_EST_EXT_H
#define BR_EST_EXT_H

#include "bristle/br_est.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"
#include "plant/br_sim_plant.h"

#define BR_EST_EXT_HIST 64 /* torque history: delays up to 62 periods */

typedef struct {
    br_est_t inner;
    const br_ukf_t *ukf;        /* exactly one of ukf / pf: the inner estimator, */
    const br_pf_t *pf;          /* read for its mean state */
    br_plant_cfg_t m;           /* the extended model (plant-configuration form: the fields model.json's
                                 * names set, sim/plant/br_model_params.h) */
    double dt_s, rad_per_count;
    double u_hist[BR_EST_EXT_HIST]; /* commanded torques, newest at u_head */
    int u_head;
    long u_n;
    double F_cause_N;           /* cause force at the last estimate */
} br_est_ext_t;

/* 0, or -1 (message on stderr) when the model's delay exceeds the history,
 * the period is not positive, or not exactly one inner estimator is given. */
int br_est_ext_init(br_est_ext_t *e, br_est_t inner, const br_ukf_t *ukf, const br_pf_t *pf,
                    const br_plant_cfg_t *model, double dt_s);

/* br_est_t step (ctx is a br_est_ext_t *): the inner step's status. */
br_status_t br_est_ext_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N);

/* F_cause above, load side (N), for a friction f at (x, v). */
double br_est_ext_cause_force(const br_plant_cfg_t *m, double x_m, double v_mps, double f_N);

#endif
