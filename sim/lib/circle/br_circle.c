/* SPDX-License-Identifier: Apache-2.0 */
/* X-Y circle experiment on the simulator. */
#include "br_circle.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "br_circle_est.h"
#include "hal_sim/br_hal_sim.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_app.h"
#include "bristle/br_ff_pred.h"
#include "plant/br_model_params.h"
#include "tool/br_rng.h"
#include "tool/br_run_report.h"

#define BR_PI 3.14159265358979323846

const char *br_circle_ctrl_name(br_circle_ctrl_t c)
{
    switch (c) {
    case BR_CTRL_HINF_ONLY: return "hinf_only";
    case BR_CTRL_HINF_UKF: return "hinf_ukf";
    case BR_CTRL_HINF_PF: return "hinf_pf";
    case BR_CTRL_HINF_TRUE: return "hinf_true";
    case BR_CTRL_HINF_FF: return "hinf_ff";
    case BR_CTRL_HINF_QEC: return "hinf_qec";
    }
    return "unknown";
}

int br_circle_ctrl_of_est(const char *est, br_circle_ctrl_t *c)
{
    static const struct {
        const char *est;
        br_circle_ctrl_t ctrl;
    } k[] = {{"none", BR_CTRL_HINF_ONLY}, {"ukf", BR_CTRL_HINF_UKF}, {"pf", BR_CTRL_HINF_PF}};
    for (unsigned i = 0; i < sizeof k / sizeof k[0]; i++) {
        if (strcmp(est, k[i].est) == 0) {
            *c = k[i].ctrl;
            return 0;
        }
    }
    return -1;
}

br_circle_cfg_t br_circle_cfg_thesis(br_circle_ctrl_t controller)
{
    br_circle_cfg_t c;
    static const float K[3] = BR_HINF_K;
    c.radius_m = 1.0e-4;
    c.period_s = 8.0;
    c.dir = 1.0; /* clockwise */
    c.duration_s = 8.0;
    /* the machine's periods (thesis section 5: 1.5 ms for the PF, 1 ms for the others) */
    c.dt_s = (controller == BR_CTRL_HINF_PF) ? BR_EST_PF_PERIOD_S : BR_MACHINE_CTRL_PERIOD_S;
    c.controller = controller;
    c.plant = br_plant_cfg_reference();
    for (int i = 0; i < 3; i++) c.K[i] = K[i];
    c.pf = br_circle_pf_cfg_tuned((float)c.dt_s);
    c.ukf = br_circle_ukf_cfg_tuned((float)c.dt_s);
    c.ff = br_circle_ff_cfg_machine();
    c.qec = br_circle_qec_cfg_machine((float)c.dt_s);
    c.real = (br_circle_real_t){0.0, 0.0, 0.0, 0u};
    c.pred = 0;
    c.oracle_late = 0;
    return c;
}

br_circle_cfg_t br_circle_cfg_realistic(br_circle_ctrl_t controller)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(controller);
    /* the draw (docs/demo.md): factors on the reference machine, within the
     * distributions of docs/robustness.md */
    c.plant.sigma0_Npm *= 0.6;   /* bristle stiffness */
    c.plant.sigma1_Nspm *= 1.5;  /* bristle damping */
    c.plant.Fc_N *= 1.12;        /* Coulomb */
    c.plant.Fs_N *= 0.90;        /* stiction */
    c.plant.vs_mps *= 1.8;       /* Stribeck velocity */
    c.plant.sigma2_Nspm *= 1.15; /* viscous */
    c.plant.J_kgm2 *= 1.05;      /* moving mass (J and M alike) */
    c.plant.M_kg *= 1.05;
    c.real.drift_frac = 0.05;    /* friction +5 % over the 8 s */
    c.real.force_noise_N = 0.05; /* per control period */
    c.real.enc_noise_p = 1.0e-3; /* one read in a thousand one count off */
    c.real.seed = 1;
    return c;
}

/* The hardware-like plant's elements (docs/demo.md, "Hardware-like plant",
 * the choice and its sources): four equal elements breaking away at 2, 5,
 * 10, 20 um at Fs (inside presliding.md's 0.3-30 um): initial stiffness
 * sum k_i = 0.85 Fs / 1 um = 3.8e6 N/m against the machine's sigma0 4e6 N/m;
 * presliding 24 um */
static const double k_hw_d_m[BR_CIRCLE_HW_N] = {2.0e-6, 5.0e-6, 10.0e-6, 20.0e-6};
static const double k_hw_share[BR_CIRCLE_HW_N] = {0.25, 0.25, 0.25, 0.25};

void br_circle_est_mslip(br_est_cfg_t *est)
{
    br_mslip_cfg_t *ms = &est->model.mslip;
    const double Fs = (double)est->model.lugre.Fs_N;
    ms->n = BR_CIRCLE_HW_N;
    for (int i = 0; i < BR_CIRCLE_HW_N; i++) {
        /* k_i = share_i Fs / d_i (docs/modules/mslip.md) */
        ms->k_Npm[i] = (float)(k_hw_share[i] * Fs / k_hw_d_m[i]);
        ms->share[i] = (float)k_hw_share[i];
    }
    ms->sigma2_Nspm = 0.0f; /* the viscous friction stays the model's sigma2 (eq. 6) */
    est->comp_ahead_periods = 0.0f;
}

void br_circle_use_ukf_mslip(br_circle_cfg_t *c, int on)
{
    if (on) br_circle_est_mslip(&c->ukf.est);
}

void br_circle_use_pf_mslip(br_circle_cfg_t *c, int on)
{
    if (on) br_circle_est_mslip(&c->pf.est);
}

br_circle_cfg_t br_circle_cfg_hardware_like(br_circle_ctrl_t controller)
{
    br_circle_cfg_t c = br_circle_cfg_thesis(controller);
    br_gms_from_breakaway(&c.plant.gms, BR_CIRCLE_HW_N, k_hw_d_m, k_hw_share, c.plant.Fs_N, BR_CIRCLE_HW_SIGMA1_NSPM);
    c.plant.gms.clamp = 0;                  /* the finite-C slip law: not the estimators' clamp form */
    c.plant.gms.C_mps = BR_CIRCLE_HW_C_MPS;
    c.plant.gms.delta = 1.0;                /* the machine's Stribeck curve, g itself */
    return c;
}

void br_circle_use_ahead(br_circle_cfg_t *c, double lead_periods)
{
    if (lead_periods >= 0.0) {
        c->pf.est.comp_ahead_periods = (float)lead_periods;
        c->ukf.est.comp_ahead_periods = (float)lead_periods;
    }
}

void br_circle_use_ukf_load(br_circle_cfg_t *c, double q_N2ps)
{
    if (q_N2ps > 0.0) {
        const double F_act = (double)BR_MACHINE_TORQUE_LIMIT_NM_F / c->plant.lead_mprad;
        c->ukf.load.q_N2 = (float)(q_N2ps * c->dt_s);
        c->ukf.load.p0_N2 = (float)(F_act * F_act);
        c->ukf.load.max_N = (float)F_act;
    } else if (q_N2ps == 0.0) {
        /* off: br_ukf_load_t all 0 */
        c->ukf.load.q_N2 = 0.0f;
        c->ukf.load.p0_N2 = 0.0f;
        c->ukf.load.max_N = 0.0f;
    }
}

void br_circle_use_pf_load(br_circle_cfg_t *c, double q_N2ps)
{
    if (q_N2ps > 0.0) {
        c->pf.load.q_N2 = (float)(q_N2ps * (double)c->pf.est.model.dt_s);
        c->pf.load.max_N = (float)((double)BR_MACHINE_TORQUE_LIMIT_NM_F / c->plant.lead_mprad);
    } else if (q_N2ps == 0.0) {
        /* off: br_pf_load_t all 0 */
        c->pf.load.q_N2 = 0.0f;
        c->pf.load.max_N = 0.0f;
    }
}

double br_circle_ukf_load_q_N2ps(const br_circle_cfg_t *c)
{
    return (c->ukf.load.max_N > 0.0f) ? (double)c->ukf.load.q_N2 / c->dt_s : 0.0;
}

double br_circle_pf_load_q_N2ps(const br_circle_cfg_t *c)
{
    return (c->pf.load.max_N > 0.0f) ? (double)c->pf.load.q_N2 / (double)c->pf.est.model.dt_s : 0.0;
}

void br_circle_use_pf_gp_curve(br_circle_cfg_t *c, double tau_s)
{
    if (tau_s > 0.0) {
        c->pf.gp_curve.on = 1u;
        c->pf.gp_curve.rho = (float)exp(-(double)c->pf.est.model.dt_s / tau_s);
    }
}

void br_circle_use_pf_gate(br_circle_cfg_t *c, double sigma)
{
    if (sigma > 0.0) c->pf.est.outlier_sigma = (float)sigma;
}

void br_circle_use_pf_adapt_max(br_circle_cfg_t *c, double s)
{
    if (s > 0.0) c->pf.adapt.max_scale = (float)s;
}

void br_circle_use_machine_causes(br_circle_cfg_t *c)
{
    c->pf.est.model.causes = br_machine_causes();
    c->ukf.est.model.causes = br_machine_causes();
}

double br_circle_feed_mps(const br_circle_cfg_t *c)
{
    return 2.0 * BR_PI * c->radius_m / c->period_s;
}

void br_circle_use_path(br_circle_cfg_t *c, double radius_m, double feed_mps, int ccw)
{
    if (radius_m > 0.0 || feed_mps > 0.0) {
        const double revs = c->duration_s / c->period_s;
        if (feed_mps > 0.0) {
            if (radius_m > 0.0) c->radius_m = radius_m;
            c->period_s = 2.0 * BR_PI * c->radius_m / feed_mps;
        } else {
            c->period_s *= radius_m / c->radius_m; /* the same feed */
            c->radius_m = radius_m;
        }
        c->duration_s = revs * c->period_s;
    }
    c->dir = ccw ? -1.0 : 1.0;
}

/* the reference's angular velocity, signed by the direction, rad/s */
static double circle_omega(const br_circle_cfg_t *c)
{
    const double w = 2.0 * BR_PI / c->period_s;
    return c->dir < 0.0 ? -w : w;
}

void br_circle_use_delay_id(br_circle_cfg_t *c, long on)
{
    if (on == 0) {
        c->pf.est.delay_id.n_cand = 0u;
        c->ukf.est.delay_id.n_cand = 0u;
    }
}

void br_circle_use_causes(br_circle_cfg_t *c, const br_causes_t *causes)
{
    c->pf.est.model.causes = *causes;
    c->ukf.est.model.causes = *causes;
    /* the PF's shared external force needs the thesis model (br_pf_init refuses it with the
     * extended one): off where the causes make the model extended, as a diagnosis writes its
     * machine.json (firmware/design/machine.py, pf_load_blockers) */
    br_model_t mm;
    if (br_model_init(&mm, &c->pf.est.model) == BR_OK && mm.extended) {
        br_circle_use_pf_load(c, 0.0);
    }
}

void br_circle_use_model(br_circle_cfg_t *c, const br_plant_cfg_t *m)
{
    br_model_cfg_t *ms[2] = {&c->pf.est.model, &c->ukf.est.model};
    for (int i = 0; i < 2; i++) {
        ms[i]->J_kgm2 = (float)m->J_kgm2;
        ms[i]->M_kg = (float)m->M_kg;
        ms[i]->sigma2_Nspm = (float)m->sigma2_Nspm;
        ms[i]->lugre.sigma0_Npm = (float)m->sigma0_Npm;
        ms[i]->lugre.sigma1_Nspm = (float)m->sigma1_Nspm;
        ms[i]->lugre.Fc_N = (float)m->Fc_N;
        ms[i]->lugre.Fs_N = (float)m->Fs_N;
        ms[i]->lugre.vs_mps = (float)m->vs_mps;
    }
    const br_causes_t causes = br_causes_from_model(m);
    br_circle_use_causes(c, &causes);
    c->ff.Fc_N = (float)m->Fc_N;
    c->ff.Fs_N = (float)m->Fs_N;
    c->ff.vs_mps = (float)m->vs_mps;
    c->ff.sigma2_Nspm = (float)m->sigma2_Nspm;
    c->ff.causes = br_causes_from_model(m);
}

typedef struct {
    br_plant_t plant;
    br_hal_sim_t port;
    br_hal_t hal;
    br_app_t app;
    br_app_mem_t mem; /* the filter's state, owned: PF or UKF only */
    br_ff_t ff;       /* the feedforward (BR_CTRL_HINF_FF) */
    br_qec_t qec;     /* the reversal compensation (BR_CTRL_HINF_QEC) */
    int ff_on;        /* ff initialised: set to the reference each period */
    br_ff_pred_t pred; /* the estimate plus the feedforward's prediction (cfg.pred) */
    int oracle_late;  /* the oracle: one period late */
    int oracle_primed; /* oracle_prev_N holds a period's force */
    double oracle_prev_N;
    double phase;
    /* the run's drift and noise (br_circle_real_t) */
    br_circle_real_t real;
    br_rng_t rng;
    br_plant_cfg_t base;  /* the plant's configuration before drift and noise */
    br_hal_t inner;       /* the simulator's HAL behind the noisy encoder */
} axis_sim_t;

/* The limit: an "estimator" that reads the plant's true friction at t_k (or,
 * oracle_late, the one it read a period before). */
static br_status_t oracle_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    axis_sim_t *a = ctx;
    const double f = br_plant_comp_force_N(&a->plant);
    *F_hat_N = (float)((a->oracle_late && a->oracle_primed) ? a->oracle_prev_N : f);
    a->oracle_prev_N = f;
    a->oracle_primed = 1;
    return BR_OK;
}

/* encoder noise: the simulator's reading, one count off with probability p */
static br_status_t noisy_encoder_read(void *ctx, int32_t *counts)
{
    axis_sim_t *a = ctx;
    const br_status_t st = a->inner.encoder_read(a->inner.ctx, counts);
    if (st == BR_OK && br_rng_uniform(&a->rng) < a->real.enc_noise_p) {
        const uint32_t u = (uint32_t)*counts + (br_rng_uniform(&a->rng) < 0.5 ? 1u : UINT32_MAX); /* wraps */
        *counts = u <= (uint32_t)INT32_MAX ? (int32_t)u : -(int32_t)(~u) - 1;
    }
    return st;
}
static br_status_t inner_pwm_write(void *ctx, float duty)
{
    axis_sim_t *a = ctx;
    return a->inner.pwm_write(a->inner.ctx, duty);
}
static br_status_t inner_tick_wait(void *ctx, uint32_t *tick)
{
    axis_sim_t *a = ctx;
    return a->inner.tick_wait(a->inner.ctx, tick);
}
static br_status_t inner_pwm_disable(void *ctx)
{
    axis_sim_t *a = ctx;
    return a->inner.pwm_disable ? a->inner.pwm_disable(a->inner.ctx) : BR_OK;
}
static br_status_t inner_pwm_enable(void *ctx)
{
    axis_sim_t *a = ctx;
    return a->inner.pwm_enable ? a->inner.pwm_enable(a->inner.ctx) : BR_OK;
}

/* force noise for the next period: a Gaussian force held over the
 * period (added to the plant's offset). The run's drift is the plant's own
 * friction_drift cause (axis_init), not a second model of it. */
static void axis_perturb(axis_sim_t *a)
{
    const br_circle_real_t *r = &a->real;
    if (r->force_noise_N > 0.0) a->plant.cfg.offset_N = a->base.offset_N + r->force_noise_N * br_rng_gauss(&a->rng);
}

/* Reference of one axis at t: position split into integer counts and a
 * fraction, plus the velocity, all on the motor side. */
static br_ref_t axis_ref(const br_circle_cfg_t *c, double phase, double t, double *x_ref)
{
    const double L = c->plant.lead_mprad, rpc = 2.0 * BR_PI / c->plant.counts_per_rev;
    const double w = circle_omega(c);
    *x_ref = c->radius_m * sin(w * t + phase);
    const double counts = *x_ref / L / rpc;
    const double whole = floor(counts);
    br_ref_t r;
    r.ref_counts = (int32_t)whole;
    r.ref_frac_counts = (float)(counts - whole);
    r.ref_omega_radps = (float)(c->radius_m * w * cos(w * t + phase) / L);
    return r;
}

/* the axes' phases: x = A sin(w t), y = A sin(w t + pi/2) */
static double axis_phase(int axis)
{
    return axis == 0 ? 0.0 : 0.5 * BR_PI;
}

br_ref_t br_circle_axis_ref(const br_circle_cfg_t *c, int axis, double t, double *x_ref)
{
    return axis_ref(c, axis_phase(axis), t, x_ref);
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

/* cfg.pred: the compensation ac names (the UKF, the PF or the oracle) made
 * first, then handed to the application through br_ff_pred's interface: its
 * estimate plus the feedforward's prediction (a->ff, set to the reference each
 * period) */
static int pred_wrap(axis_sim_t *a, const br_circle_cfg_t *c, br_app_cfg_t *ac, br_est_t *ext)
{
    if (ac->est == BR_APP_EST_NONE || c->controller == BR_CTRL_HINF_FF || c->controller == BR_CTRL_HINF_QEC)
        return 0; /* H-inf alone has nothing to add to; the feedforward adds its own (pred_ahead_s) */
    br_est_t inner;
    const float *z = NULL, *g = NULL;
    if (br_ff_init(&a->ff, &c->ff) != BR_OK || br_app_est_init(ac, &a->mem, &inner) != BR_OK) {
        fprintf(stderr, "br_circle: invalid feedforward or estimator configuration for the prediction\n");
        return -1;
    }
    a->ff_on = 1;
    if (c->pred == 2) {
        /* anchored on the UKF's own elements and level */
        if (a->mem.ukf == NULL || c->ukf.est.model.mslip.n != c->ff.mslip.n) {
            fprintf(stderr, "br_circle: the prediction's UKF anchor needs a Maxwell-slip UKF with the "
                            "feedforward's element set\n");
            return -1;
        }
        z = a->mem.ukf->est.elem_m;
        g = &a->mem.ukf->est.mean[BR_X_GP];
    }
    if (br_ff_pred_init(&a->pred, inner, &a->ff, z, g) != BR_OK) {
        fprintf(stderr, "br_circle: the prediction needs the feedforward's elements and a horizon\n");
        return -1;
    }
    *ext = br_ff_pred_est(&a->pred);
    ac->est = BR_APP_EST_EXTERN;
    return 0;
}

/* 0, or -1 with a message; *refused the firmware's BR_E_* when it refused the
 * application (an estimator, the feedforward) at init, else left as it is */
static int axis_init(axis_sim_t *a, const br_circle_cfg_t *c, double phase, int index, br_status_t *refused)
{
    a->phase = phase;
    a->ff_on = 0;
    a->mem = (br_app_mem_t){NULL, NULL};
    a->real = c->real;
    a->base = c->plant;
    a->rng = (br_rng_t){c->real.seed * 2654435761ull + (uint64_t)index * 0x632BE59BD9B4E019ull, 0, 0.0};
    br_plant_state_t x0 = {c->radius_m * sin(phase) / c->plant.lead_mprad, 0.0, 0.0};
    /* the run's warm-up: the plant's friction_drift, drift_frac over the run's duration */
    br_plant_cfg_t pc = c->plant;
    pc.drift_per_s += c->real.drift_frac / c->duration_s;
    if (br_plant_init(&a->plant, &pc, &x0) != 0) return -1;
    if (br_hal_sim_init(&a->port, &a->plant, c->dt_s, &a->hal) != BR_OK) return -1;
    if (c->real.enc_noise_p > 0.0) {
        /* the noisy encoder in front of the simulator's HAL */
        a->inner = a->hal;
        a->hal = (br_hal_t){a, noisy_encoder_read, inner_pwm_write, inner_tick_wait, inner_pwm_disable,
                            inner_pwm_enable};
    }
    const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(c);
    br_est_t ext = {NULL, NULL, NULL, NULL};
    br_app_cfg_t ac = {&cc, BR_APP_EST_NONE, &c->pf, &c->ukf, &ext,
                       br_app_guard_cfg(cc.dt_s, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F), br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE)};
    switch (c->controller) {
    case BR_CTRL_HINF_ONLY:
        break;
    case BR_CTRL_HINF_TRUE:
        a->oracle_late = c->oracle_late;
        a->oracle_primed = 0;
        a->oracle_prev_N = 0.0;
        ext = (br_est_t){a, oracle_step, NULL, NULL};
        ac.est = BR_APP_EST_EXTERN;
        break;
    case BR_CTRL_HINF_FF:
        if ((*refused = br_ff_init(&a->ff, &c->ff)) != BR_OK) {
            fprintf(stderr, "br_circle: invalid feedforward configuration\n");
            return -1;
        }
        a->ff_on = 1;
        ext = (br_est_t){&a->ff, br_ff_est_step, NULL, NULL};
        ac.est = BR_APP_EST_EXTERN;
        break;
    case BR_CTRL_HINF_QEC:
        if ((float)c->dt_s != c->qec.dt_s || (*refused = br_qec_init(&a->qec, &c->qec)) != BR_OK) {
            fprintf(stderr, "br_circle: invalid reversal compensation configuration\n");
            return -1;
        }
        ext = (br_est_t){&a->qec, br_qec_est_step, NULL, NULL};
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
    if (c->pred != 0 && pred_wrap(a, c, &ac, &ext) != 0) return -1;
    br_status_t st;
    /* BR_E_PARAM also when an estimator's period is not the control period */
    st = br_app_init(&a->app, &ac, &a->hal, &a->mem);
    if (st == BR_OK) {
        st = br_app_arm(&a->app); /* the simulator arms right after init */
    }
    if (st != BR_OK) {
        fprintf(stderr, "br_circle: application init failed (status %d)\n", (int)st);
        *refused = st;
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
        br_pf_stats_t ps;
        if (s->pf[i]) {
            /* g_p's particle mean (gp0 before the first measurement) */
            const float gp = (br_pf_stats(s->pf[i], &ps) == BR_OK) ? ps.mean[BR_X_GP] : s->pf[i]->cfg.est.gp0_N;
            fprintf(f, ",%.6f", (double)gp);
        }
        else if (s->ukf[i]) fprintf(f, ",%.6f", (double)br_ukf_estimate(s->ukf[i])->mean[BR_X_GP]);
        else fprintf(f, ",");
    }
    fprintf(f, "\n");
}

int br_circle_run(const br_circle_cfg_t *c, br_circle_sink_t sink, void *user, br_circle_result_t *res)
{
    return br_circle_run_remote(c, NULL, sink, user, res);
}

/* one period of axis a's application, here (br_app_step) or remote */
static int axis_step(axis_sim_t *a, const br_circle_remote_t *remote, int i, long k, const br_ref_t *r,
                     br_circle_remote_out_t *o)
{
    if (remote == NULL) {
        o->status = (int)br_app_step(&a->app, r);
        o->fault = (int)a->app.fault;
        o->duty = a->app.last.duty;
        o->F_hat_N = a->app.F_hat_N;
        o->saturated = a->app.last.saturated;
        return 0;
    }
    int32_t counts = 0;
    (void)a->hal.encoder_read(a->hal.ctx, &counts); /* what the application would read */
    if (remote->step(remote->user, i, k, counts, o) != 0) return -1;
    (void)a->hal.pwm_write(a->hal.ctx, o->port_duty); /* a non-finite one holds 0 */
    return 0;
}

/* the firmware refused the application at init: the run never started (br_run_report.h);
 * -1 as for any configuration the run cannot take, res saying why */
static int refused_at_init(br_circle_result_t *res, br_status_t st)
{
    memset(res, 0, sizeof *res);
    res->fault_status = (int)st;
    res->fault_cause = BR_RUN_CAUSE_REFUSED_AT_INIT;
    res->last_outlier_t_s = -1.0;
    return -1;
}

int br_circle_run_remote(const br_circle_cfg_t *c, const br_circle_remote_t *remote, br_circle_sink_t sink,
                         void *user, br_circle_result_t *res)
{
    res->fault_cause = 0; /* BR_RUN_CAUSE_REFUSED_AT_INIT only when the firmware refused */
    if (!(c->radius_m > 0.0 && c->period_s > 0.0 && c->duration_s > 0.0 && c->dt_s > 0.0)) {
        fprintf(stderr, "br_circle: radius, period, duration and dt must be > 0\n");
        return -1;
    }
    if (!(c->dir == 1.0 || c->dir == -1.0)) {
        fprintf(stderr, "br_circle: dir must be +1 (clockwise) or -1 (counter-clockwise)\n");
        return -1;
    }
    const br_circle_real_t *rl = &c->real;
    if (!(isfinite(rl->drift_frac) && rl->drift_frac > -0.9 && rl->drift_frac < 10.0 && isfinite(rl->force_noise_N) &&
          rl->force_noise_N >= 0.0 && isfinite(rl->enc_noise_p) && rl->enc_noise_p >= 0.0 && rl->enc_noise_p <= 1.0)) {
        fprintf(stderr, "br_circle: drift in (-0.9, 10), force noise >= 0, encoder noise in [0, 1]\n");
        return -1;
    }
    axis_sim_t ax[2];
    ax[0].mem = ax[1].mem = (br_app_mem_t){NULL, NULL};
    int rc = -1;
    br_status_t refused = BR_OK;
    if (axis_init(&ax[0], c, axis_phase(0), 0, &refused) != 0 || axis_init(&ax[1], c, axis_phase(1), 1, &refused) != 0) {
        if (refused != BR_OK) rc = refused_at_init(res, refused);
        goto done;
    }
    const long n = lround(c->duration_s / c->dt_s);
    double sum2 = 0.0, emax = 0.0, fe2 = 0.0, track_max = 0.0, lost_t = 0.0;
    int nsat = 0, nout = 0;
    long k_end = n; /* the last period run */
    res->fault_status = 0;
    res->fault_t_s = 0.0;
    res->fault_cause = 0;
    res->fault_duty = 0.0;
    res->last_outlier_t_s = -1.0;
    for (long k = 0; k <= n && res->fault_status == 0; k++) {
        const double t = (double)k * c->dt_s;
        br_circle_sample_t s;
        s.t_s = t;
        int sat = 0;
        for (int i = 0; i < 2; i++) {
            uint32_t tick;
            /* force noise over the period the tick ends (k > 0) */
            if (k > 0) axis_perturb(&ax[i]);
            ax[i].hal.tick_wait(ax[i].hal.ctx, &tick);
            s.pos_m[i] = br_plant_pos_m(&ax[i].plant);
            s.vel_mps[i] = br_plant_vel_mps(&ax[i].plant);
            s.counts[i] = br_plant_encoder(&ax[i].plant);
            s.fnl_N[i] = ax[i].plant.fnl_N;
            br_ref_t r = axis_ref(c, ax[i].phase, t, &s.ref_m[i]);
            if (ax[i].ff_on || c->controller == BR_CTRL_HINF_QEC) {
                /* the feedforward's (the reversal compensation's) reference at t_k, load side */
                const double w = circle_omega(c), ph = w * t + ax[i].phase;
                const br_ff_in_t in = {(float)(c->radius_m * w * cos(ph)), (float)(-c->radius_m * w * w * sin(ph)),
                                       (float)s.ref_m[i]};
                if (ax[i].ff_on) br_ff_set_ref(&ax[i].ff, &in);
                else br_qec_set_ref(&ax[i].qec, &in);
            }
            br_circle_remote_out_t o;
            if (axis_step(&ax[i], remote, i, k, &r, &o) != 0) goto done;
            const int st = o.status;
            if (st == BR_W_OUTLIER) {
                nout++; /* the estimator skipped the update; control went on */
                res->last_outlier_t_s = t;
            } else if (st != BR_OK) {
                /* the firmware zeroed the drive: the axis stops safe; so does the run */
                res->fault_status = st;
                res->fault_t_s = t;
                res->fault_cause = o.fault;
                res->fault_duty = ax[i].port.duty;
                k_end = k;
                break;
            }
            sat |= o.saturated;
            s.duty[i] = (double)o.duty;
            s.F_hat_N[i] = (double)o.F_hat_N;
            /* against the force a perfect estimator hands over (the oracle's) */
            const double f_true = br_plant_comp_force_N(&ax[i].plant);
            fe2 += (s.F_hat_N[i] - f_true) * (s.F_hat_N[i] - f_true);
            s.pf[i] = remote == NULL ? ax[i].mem.pf : NULL; /* a remote's filter is not here */
            s.ukf[i] = remote == NULL ? ax[i].mem.ukf : NULL;
        }
        if (res->fault_status != 0) {
            break;
        }
        /* contour error of a circle: radial deviation from the radius */
        const double er = hypot(s.pos_m[0], s.pos_m[1]) - c->radius_m;
        /* and how far the table is from where the reference is: a table that stays
         * put on the circle has no radial error at all */
        const double te = hypot(s.ref_m[0] - s.pos_m[0], s.ref_m[1] - s.pos_m[1]);
        if (!(te <= c->radius_m) && !(track_max > c->radius_m)) lost_t = t;
        track_max = fmax(track_max, te);
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
    res->track_max_m = track_max;
    /* a table farther from the reference point than the circle's radius did not go
     * round the circle (a motionless axis sits on the circle with no radial
     * error): a fault of the harness's, never a perfect result (docs/circle-test.md) */
    if (res->fault_status == 0 && !(track_max <= c->radius_m)) {
        fprintf(stderr, "br_circle: the table did not follow the circle: it was %.3e m from the reference point, more "
                        "than the radius %.3e m (first at %.4f s); no result\n", track_max, c->radius_m, lost_t);
        res->fault_status = BR_RUN_NOT_FOLLOWED;
        res->fault_cause = BR_RUN_CAUSE_NOT_FOLLOWED;
        res->fault_t_s = lost_t;
    }
    rc = (res->fault_status != 0) ? 1 : 0;
done:
    for (int i = 0; i < 2; i++) {
        free(ax[i].mem.pf);
        free(ax[i].mem.ukf);
    }
    return rc;
}
