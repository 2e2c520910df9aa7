/* X-Y circle experiment on the simulator. */
#include "br_circle.h"

#include <math.h>

#include "br_hal_sim.h"
#include "br_hinf_gains.h"
#include "br_reference_machine.h"
#include "bristle/br_axis.h"

#define BR_PI 3.14159265358979323846

br_circle_cfg_t br_circle_cfg_thesis(void)
{
    br_circle_cfg_t c;
    static const float K[3] = BR_HINF_K;
    c.radius_m = 1.0e-4;
    c.period_s = 8.0;
    c.duration_s = 8.0;
    c.dt_s = 1.0e-3;
    c.controller = BR_CTRL_HINF_ONLY;
    c.plant = br_plant_cfg_reference();
    for (int i = 0; i < 3; i++) c.K[i] = K[i];
    return c;
}

typedef struct {
    br_plant_t plant;
    br_hal_sim_t port;
    br_hal_t hal;
    br_axis_t axis;
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

static int axis_init(axis_sim_t *a, const br_circle_cfg_t *c, double phase)
{
    a->phase = phase;
    br_plant_state_t x0 = {c->radius_m * sin(phase) / c->plant.lead_mprad, 0.0, 0.0};
    if (br_plant_init(&a->plant, &c->plant, &x0) != 0) return -1;
    if (br_hal_sim_init(&a->port, &a->plant, c->dt_s, &a->hal) != BR_OK) return -1;
    br_ctrl_cfg_t cc;
    for (int i = 0; i < 3; i++) cc.K[i] = c->K[i];
    cc.dt_s = (float)c->dt_s;
    cc.tau_max_Nm = (float)c->plant.tau_per_duty_Nm;
    cc.tau_per_duty_Nm = (float)c->plant.tau_per_duty_Nm;
    cc.rad_per_count = (float)(2.0 * BR_PI / c->plant.counts_per_rev);
    cc.lead_mprad = (float)c->plant.lead_mprad;
    br_status_t st = br_axis_init(&a->axis, &a->hal, &cc, NULL);
    if (st != BR_OK) {
        fprintf(stderr, "br_circle: controller init failed (status %d)\n", (int)st);
        return -1;
    }
    return 0;
}

void br_circle_csv_header(FILE *f) { fprintf(f, "t,x_ref,y_ref,x,y,radial_err,duty_x,duty_y,fnl_x,fnl_y\n"); }

void br_circle_csv_sink(void *user, const br_circle_sample_t *s)
{
    fprintf((FILE *)user, "%.6f,%.9e,%.9e,%.9e,%.9e,%.6e,%.6f,%.6f,%.6f,%.6f\n", s->t_s, s->ref_m[0], s->ref_m[1],
            s->pos_m[0], s->pos_m[1], s->radial_err_m, s->duty[0], s->duty[1], s->fnl_N[0], s->fnl_N[1]);
}

int br_circle_run(const br_circle_cfg_t *c, br_circle_sink_t sink, void *user, br_circle_result_t *res)
{
    if (!(c->radius_m > 0.0 && c->period_s > 0.0 && c->duration_s > 0.0 && c->dt_s > 0.0)) {
        fprintf(stderr, "br_circle: radius, period, duration and dt must be > 0\n");
        return -1;
    }
    axis_sim_t ax[2];
    if (axis_init(&ax[0], c, 0.0) != 0 || axis_init(&ax[1], c, 0.5 * BR_PI) != 0) return -1;
    const long n = lround(c->duration_s / c->dt_s);
    double sum2 = 0.0, emax = 0.0;
    int nsat = 0;
    for (long k = 0; k <= n; k++) {
        const double t = (double)k * c->dt_s;
        br_circle_sample_t s;
        s.t_s = t;
        int sat = 0;
        for (int i = 0; i < 2; i++) {
            uint32_t tick;
            ax[i].hal.tick_wait(ax[i].hal.ctx, &tick);
            s.pos_m[i] = br_plant_pos_m(&ax[i].plant);
            s.fnl_N[i] = ax[i].plant.fnl_N;
            br_ref_t r = axis_ref(c, ax[i].phase, t, &s.ref_m[i]);
            br_status_t st = br_axis_step(&ax[i].axis, &r);
            if (st != BR_OK) {
                fprintf(stderr, "br_circle: axis %d step failed at t=%.4f s (status %d)\n", i, t, (int)st);
                return -1;
            }
            sat |= ax[i].axis.last.saturated;
            s.duty[i] = (double)ax[i].axis.last.duty;
        }
        /* contour error of a circle: radial deviation from the radius */
        const double er = hypot(s.pos_m[0], s.pos_m[1]) - c->radius_m;
        s.radial_err_m = er;
        sum2 += er * er;
        if (fabs(er) > emax) emax = fabs(er);
        nsat += sat;
        if (sink) sink(user, &s);
    }
    res->n_samples = n + 1;
    res->contour_rms_m = sqrt(sum2 / (double)(n + 1));
    res->max_err_m = emax;
    res->saturated_steps = nsat;
    return 0;
}
