/* X-Y circle experiment on the simulator. */
#include "br_circle.h"

#include <math.h>
#include <stdlib.h>

#include "br_circle_est.h"
#include "hal/br_hal_sim.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_app.h"

#define BR_PI 3.14159265358979323846

const char *br_circle_ctrl_name(br_circle_ctrl_t c)
{
    switch (c) {
    case BR_CTRL_HINF_ONLY: return "hinf_only";
    case BR_CTRL_HINF_UKF: return "hinf_ukf";
    case BR_CTRL_HINF_PF: return "hinf_pf";
    case BR_CTRL_HINF_TRUE: return "hinf_true";
    }
    return "unknown";
}

br_circle_cfg_t br_circle_cfg_thesis(br_circle_ctrl_t controller)
{
    br_circle_cfg_t c;
    static const float K[3] = BR_HINF_K;
    c.radius_m = 1.0e-4;
    c.period_s = 8.0;
    c.duration_s = 8.0;
    /* the machine's periods (thesis section 5: 1.5 ms for the PF, 1 ms for the others) */
    c.dt_s = (controller == BR_CTRL_HINF_PF) ? BR_EST_PF_PERIOD_S : BR_MACHINE_CTRL_PERIOD_S;
    c.controller = controller;
    c.plant = br_plant_cfg_reference();
    for (int i = 0; i < 3; i++) c.K[i] = K[i];
    c.pf = br_circle_pf_cfg_tuned((float)c.dt_s);
    c.ukf = br_circle_ukf_cfg_tuned((float)c.dt_s);
    return c;
}

/* The limit: an "estimator" that reads the plant's true friction at t_k. */
static br_status_t oracle_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    *F_hat_N = (float)((const br_plant_t *)ctx)->fnl_N;
    return BR_OK;
}

typedef struct {
    br_plant_t plant;
    br_hal_sim_t port;
    br_hal_t hal;
    br_app_t app;
    br_app_mem_t mem; /* the filter's state, owned: PF or UKF only */
    double phase;
} axis_sim_t;

/* Reference of one axis at t: position split into integer counts and a
 * fraction, plus the velocity, all on the motor side. */
static br_ref_t axis_ref(const br_circle_cfg_t *c, double phase, double t, double *x_ref)
{
    const double L = c->plant.lead_mprad, rpc = 2.0 * BR_PI / c->plant.counts_per_rev;
    const double w = 2.0 * BR_PI / c->period_s;
    *x_ref = c->radius_m * sin(w * t + phase);
    const double counts = *x_ref / L / rpc;
    const double whole = floor(counts);
    br_ref_t r;
    r.ref_counts = (int32_t)whole;
    r.ref_frac_counts = (float)(counts - whole);
    r.ref_omega_radps = (float)(c->radius_m * w * cos(w * t + phase) / L);
    return r;
}

br_ctrl_cfg_t br_circle_ctrl_cfg(const br_circle_cfg_t *c)
{
    br_ctrl_cfg_t cc;
    for (int i = 0; i < 3; i++) cc.K[i] = c->K[i];
    cc.dt_s = (float)c->dt_s;
    cc.tau_max_Nm = BR_MACHINE_TORQUE_LIMIT_NM_F;
    cc.tau_per_duty_Nm = (float)c->plant.tau_per_duty_Nm;
    cc.rad_per_count = (float)(2.0 * BR_PI / c->plant.counts_per_rev);
    cc.lead_mprad = (float)c->plant.lead_mprad;
    return cc;
}

static int axis_init(axis_sim_t *a, const br_circle_cfg_t *c, double phase)
{
    a->phase = phase;
    a->mem = (br_app_mem_t){NULL, NULL};
    br_plant_state_t x0 = {c->radius_m * sin(phase) / c->plant.lead_mprad, 0.0, 0.0};
    if (br_plant_init(&a->plant, &c->plant, &x0) != 0) return -1;
    if (br_hal_sim_init(&a->port, &a->plant, c->dt_s, &a->hal) != BR_OK) return -1;
    const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(c);
    br_est_t ext = {NULL, NULL};
    br_app_cfg_t ac = {&cc, BR_APP_EST_NONE, &c->pf, &c->ukf, &ext};
    switch (c->controller) {
    case BR_CTRL_HINF_ONLY:
        break;
    case BR_CTRL_HINF_TRUE:
        ext = (br_est_t){&a->plant, oracle_step};
        ac.est = BR_APP_EST_EXTERN;
        break;
    case BR_CTRL_HINF_UKF:
        if ((a->mem.ukf = calloc(1, sizeof *a->mem.ukf)) == NULL) return -1;
        ac.est = BR_APP_EST_UKF;
        break;
    case BR_CTRL_HINF_PF:
        if ((a->mem.pf = calloc(1, sizeof *a->mem.pf)) == NULL) return -1;
        ac.est = BR_APP_EST_PF;
        break;
    }
    br_status_t st;
    /* BR_E_PARAM also when an estimator's period is not the control period */
    st = br_app_init(&a->app, &ac, &a->hal, &a->mem);
    if (st != BR_OK) {
        fprintf(stderr, "br_circle: application init failed (status %d)\n", (int)st);
        return -1;
    }
    return 0;
}

void br_circle_csv_header(FILE *f)
{
    fprintf(f, "t,x_ref,y_ref,x,y,radial_err,duty_x,duty_y,fnl_x,fnl_y,fhat_x,fhat_y,gp_x,gp_y\n");
}

void br_circle_csv_sink(void *user, const br_circle_sample_t *s)
{
    FILE *f = user;
    fprintf(f, "%.6f,%.9e,%.9e,%.9e,%.9e,%.6e,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f", s->t_s, s->ref_m[0], s->ref_m[1],
            s->pos_m[0], s->pos_m[1], s->radial_err_m, s->duty[0], s->duty[1], s->fnl_N[0], s->fnl_N[1],
            s->F_hat_N[0], s->F_hat_N[1]);
    for (int i = 0; i < 2; i++) {
        if (s->pf[i]) fprintf(f, ",%.6f", (double)br_pf_estimate(s->pf[i])->mean[BR_X_GP]);
        else if (s->ukf[i]) fprintf(f, ",%.6f", (double)br_ukf_estimate(s->ukf[i])->mean[BR_X_GP]);
        else fprintf(f, ",");
    }
    fprintf(f, "\n");
}

int br_circle_run(const br_circle_cfg_t *c, br_circle_sink_t sink, void *user, br_circle_result_t *res)
{
    if (!(c->radius_m > 0.0 && c->period_s > 0.0 && c->duration_s > 0.0 && c->dt_s > 0.0)) {
        fprintf(stderr, "br_circle: radius, period, duration and dt must be > 0\n");
        return -1;
    }
    axis_sim_t ax[2];
    ax[0].mem = ax[1].mem = (br_app_mem_t){NULL, NULL};
    int rc = -1;
    if (axis_init(&ax[0], c, 0.0) != 0 || axis_init(&ax[1], c, 0.5 * BR_PI) != 0) goto done;
    const long n = lround(c->duration_s / c->dt_s);
    double sum2 = 0.0, emax = 0.0, fe2 = 0.0;
    int nsat = 0, nout = 0;
    long k_end = n; /* the last period run */
    res->fault_status = 0;
    res->fault_t_s = 0.0;
    for (long k = 0; k <= n && res->fault_status == 0; k++) {
        const double t = (double)k * c->dt_s;
        br_circle_sample_t s;
        s.t_s = t;
        int sat = 0;
        for (int i = 0; i < 2; i++) {
            uint32_t tick;
            ax[i].hal.tick_wait(ax[i].hal.ctx, &tick);
            s.pos_m[i] = br_plant_pos_m(&ax[i].plant);
            s.counts[i] = br_plant_encoder(&ax[i].plant);
            s.fnl_N[i] = ax[i].plant.fnl_N;
            br_ref_t r = axis_ref(c, ax[i].phase, t, &s.ref_m[i]);
            br_status_t st = br_app_step(&ax[i].app, &r);
            if (st == BR_W_OUTLIER) {
                nout++; /* the estimator skipped the update; control went on */
            } else if (st != BR_OK) {
                /* the firmware zeroed the drive: the axis stops safe; so does the run */
                res->fault_status = (int)st;
                res->fault_t_s = t;
                k_end = k;
                break;
            }
            sat |= ax[i].app.axis.last.saturated;
            s.duty[i] = (double)ax[i].app.axis.last.duty;
            s.F_hat_N[i] = (double)ax[i].app.axis.F_hat_N;
            fe2 += (s.F_hat_N[i] - s.fnl_N[i]) * (s.F_hat_N[i] - s.fnl_N[i]);
            s.pf[i] = ax[i].mem.pf;
            s.ukf[i] = ax[i].mem.ukf;
        }
        if (res->fault_status != 0) {
            break;
        }
        /* contour error of a circle: radial deviation from the radius */
        const double er = hypot(s.pos_m[0], s.pos_m[1]) - c->radius_m;
        s.radial_err_m = er;
        sum2 += er * er;
        if (fabs(er) > emax) emax = fabs(er);
        nsat += sat;
        if (sink) sink(user, &s);
    }
    /* over the periods run (all of them unless a fault stopped the axis) */
    const long ns = (res->fault_status != 0) ? k_end : n + 1;
    res->n_samples = ns;
    res->contour_rms_m = ns > 0 ? sqrt(sum2 / (double)ns) : 0.0;
    res->max_err_m = emax;
    res->saturated_steps = nsat;
    res->outlier_steps = nout;
    res->fhat_rms_err_N = ns > 0 ? sqrt(fe2 / (2.0 * (double)ns)) : 0.0;
    rc = (res->fault_status != 0) ? 1 : 0;
done:
    for (int i = 0; i < 2; i++) {
        free(ax[i].mem.pf);
        free(ax[i].mem.ukf);
    }
    return rc;
}
