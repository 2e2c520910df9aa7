/* SPDX-License-Identifier: Apache-2.0 */
/* The thesis's X-Y circle experiment (section 5) on the simulator: two
 * identical axes, each a plant, the simulator's HAL (sim/lib/hal_sim) and the
 * firmware application (br_app_step), tracking x_ref = A sin(2 pi t / T),
 * y_ref = A cos(2 pi t / T). */
#ifndef BR_CIRCLE_H
#define BR_CIRCLE_H

#include <stdio.h>

#include "bristle/br_ctrl.h"
#include "bristle/br_ff.h"
#include "bristle/br_pf.h"
#include "bristle/br_qec.h"
#include "bristle/br_ref.h"
#include "bristle/br_ukf.h"
#include "plant/br_sim_plant.h"

/* The controllers of thesis section 5, plus the limit: compensation with the
 * plant's true friction (an oracle no real machine has). */
typedef enum {
    BR_CTRL_HINF_ONLY = 0,
    BR_CTRL_HINF_UKF = 1,
    BR_CTRL_HINF_PF = 2,
    BR_CTRL_HINF_TRUE = 3,
    BR_CTRL_HINF_FF = 4, /* H-inf + static friction feedforward on the reference (firmware/ff) */
    BR_CTRL_HINF_QEC = 5 /* H-inf + the reversal (quadrant-error) pulse of the machine file (firmware/qec) */
} br_circle_ctrl_t;

/* What a real machine adds during the run (docs/robustness.md); all 0: the
 * plant as configured, bit for bit. */
typedef struct {
    double drift_frac;    /* friction level +drift_frac over the run (warm-up): the plant's friction_drift
                             cause with drift_per_s = drift_frac / duration */
    double force_noise_N; /* standard deviation of a force held over each control period (Gaussian) */
    double enc_noise_p;   /* probability per read that the encoder reads one count off (+1 or -1) */
    unsigned long long seed; /* of the noise; each axis draws its own stream */
} br_circle_real_t;

/* Name used in summary.json and file names: "hinf_only", "hinf_pf", ... */
const char *br_circle_ctrl_name(br_circle_ctrl_t c);

/* The controller of the tools' --est (none, ukf, pf: H-inf alone or with
 * that estimator) into *c; -1 for any other name (*c untouched). */
int br_circle_ctrl_of_est(const char *est, br_circle_ctrl_t *c);

typedef struct {
    double radius_m;     /* A */
    double period_s;     /* T */
    double dir;          /* +1: clockwise seen from +z (the thesis: x = A sin, y = A cos from (0, A)),
                            -1: counter-clockwise from the same start (x = -A sin, y = A cos) */
    double duration_s;
    double dt_s;         /* control period */
    br_circle_ctrl_t controller;
    br_plant_cfg_t plant; /* both axes alike */
    float K[3];          /* state-feedback gains */
    br_pf_cfg_t pf;      /* BR_CTRL_HINF_PF: the filter (its model.dt_s must equal dt_s) */
    br_ukf_cfg_t ukf;    /* BR_CTRL_HINF_UKF: likewise (an extended model: est.model.causes) */
    br_ff_cfg_t ff;      /* BR_CTRL_HINF_FF: the feedforward's identified model */
    br_qec_cfg_t qec;    /* BR_CTRL_HINF_QEC: the reversal compensation (its dt_s must equal dt_s) */
    br_circle_real_t real; /* drift and noise of the run (all 0 for the thesis experiment) */
    int pred;            /* BR_CTRL_HINF_UKF, _PF, _TRUE: 0 their compensation as it is; 1 plus the
                            feedforward's prediction (br_ff_pred.h: ff.pred_ahead_s over ff.mslip, the
                            elements driven by the reference); 2 the same anchored on the UKF's own
                            elements and g_p (a Maxwell-slip UKF only) */
    int oracle_late;     /* BR_CTRL_HINF_TRUE: 0 the plant's force at t_k, 1 that of t_k-1 (one period late) */
} br_circle_cfg_t;

typedef struct {
    double contour_rms_m;   /* RMS of the radial (contour) error */
    double max_err_m;       /* max |radial error| */
    long n_samples;
    int saturated_steps;    /* periods where either axis saturated */
    int outlier_steps;      /* axis-periods whose measurement the estimator rejected */
    double fhat_rms_err_N;  /* RMS of (compensation - the plant's force, br_plant_comp_force_N) over both axes */
    int fault_status;       /* 0, or the negative status with which the firmware stopped an axis, or
                               BR_RUN_NOT_FOLLOWED (tool/br_run_report.h): the table was farther than the
                               radius from the reference point (it did not go round the circle) */
    double fault_t_s;       /* when it did */
    int fault_cause;        /* the latched br_app_fault_t of that axis (0 without a fault) */
    double fault_duty;      /* the duty the simulator's PWM holds after the fault (0: drive off) */
    double last_outlier_t_s; /* time of the last outlier step (-1: none) */
    double track_max_m;     /* max distance between the reference point and the table */
} br_circle_result_t;

/* The thesis experiment with the reference machine, the H-inf gains and the
 * given controller at its thesis period (1 ms; 1.5 ms and 1500 particles for
 * the PF); the feedforward from the machine's nominal model, no drift or
 * noise. */
br_circle_cfg_t br_circle_cfg_thesis(br_circle_ctrl_t controller);

/* The same on the demo's realistic plant (docs/demo.md, "Realistic plant"):
 * one documented draw of the uncertainty of docs/robustness.md (the plant's
 * parameters away from the estimators' and the feedforward's, which stay the
 * machine's nominal ones; drift, force and encoder noise). */
br_circle_cfg_t br_circle_cfg_realistic(br_circle_ctrl_t controller);

/* The thesis experiment on the hardware-like plant (docs/demo.md,
 * "Hardware-like plant"): the reference machine whose LuGre presliding is
 * replaced by a generalized Maxwell-slip friction of the same Stribeck curve
 * and a similar initial stiffness (plant.gms, the simulator's truth only; the
 * estimators and the feedforward keep the machine's LuGre model). */
br_circle_cfg_t br_circle_cfg_hardware_like(br_circle_ctrl_t controller);
/* its element damping, each element, N s/m, and its slip law's attraction
 * rate C, m/s (docs/demo.md, "Hardware-like plant", says why) */
#define BR_CIRCLE_HW_SIGMA1_NSPM 2000.0
#define BR_CIRCLE_HW_C_MPS 3.0e-3
/* its number of elements */
#define BR_CIRCLE_HW_N 4

/* The tools' --ukf-mslip: the UKF predicts with the hardware-like plant's
 * element set (breakaways and shares, k_i = share_i Fs / d_i at the model's
 * Fs) in the clamp form (docs/modules/ukf.md, "Maxwell-slip elements"), its
 * look-ahead off; on = 0 leaves the machine's model. */
void br_circle_use_ukf_mslip(br_circle_cfg_t *c, int on);
/* The same for the PF (--pf-mslip; docs/modules/pf.md, "Maxwell-slip
 * elements"): its particles carry the element set. */
void br_circle_use_pf_mslip(br_circle_cfg_t *c, int on);
/* The hardware-like plant's element set written into an estimator's model
 * (k_i = share_i Fs / d_i at the model's Fs), its look-ahead off. */
void br_circle_est_mslip(br_est_cfg_t *est);

/* The feedforward's Maxwell-slip elements (br_ff_cfg_t.mslip; docs/modules/ff-pred.md):
 * BR_CIRCLE_FF_EL_OWN the plant's own element set (the oracle case; a LuGre
 * plant has none and gets the fit), BR_CIRCLE_FF_EL_FIT four equal-share
 * elements whose breakaways span a decade (d, 2.15 d, 4.64 d, 10 d at Fs), d
 * chosen so that their initial stiffness is the plant's (sum k_i, or sigma0 on a
 * LuGre plant): what a diagnosis that measured the initial stiffness and Fs
 * gives. NONE: the static map. Call after the plant's presliding is set. */
enum { BR_CIRCLE_FF_EL_NONE = 0, BR_CIRCLE_FF_EL_OWN = 1, BR_CIRCLE_FF_EL_FIT = 2 };
void br_circle_use_ff_el(br_circle_cfg_t *c, int mode);

/* The tools' --pred: the prediction over the horizon ahead_s (> 0; <= 0 leaves
 * it off) added to the UKF's, the PF's, the oracle's and the feedforward's
 * compensation, from the feedforward's elements (anchor 1) or the UKF's own
 * (anchor 2); the feedforward needs its elements (br_circle_use_ff_el). */
void br_circle_use_pred(br_circle_cfg_t *c, double ahead_s, int anchor);

/* The estimators' and the feedforward's model from an identified one (a
 * diagnosis's model.json loaded as a plant configuration): its mass, LuGre
 * and viscous parameters and its causes (br_causes_from_model, through
 * br_circle_use_causes). */
void br_circle_use_model(br_circle_cfg_t *c, const br_plant_cfg_t *model);

/* Both estimators' causes; where they make the model the extended one the PF's
 * shared external force is switched off, as a diagnosis's machine.json has it
 * (br_pf_init refuses the force with the extended model). */
void br_circle_use_causes(br_circle_cfg_t *c, const br_causes_t *causes);

/* The tools' --ahead: both estimators' compensation lead
 * (est.comp_ahead_periods, docs/modules/est.md); lead < 0 leaves the
 * machine file's. */
void br_circle_use_ahead(br_circle_cfg_t *c, double lead_periods);

/* The tools' --ukf-load: the UKF's external-force state (docs/modules/ukf.md,
 * "External force") with the random walk q_N2ps (N^2/s) at the run's period,
 * P0 = the actuator's force squared and |F_d| <= the actuator's force, as
 * machine.py derives them from estimator.ukf.load; q_N2ps = 0 turns it off,
 * q_N2ps < 0 leaves the machine file's. */
void br_circle_use_ukf_load(br_circle_cfg_t *c, double q_N2ps);

/* The tools' --pf-load: the PF's shared external force (docs/modules/pf.md,
 * "External force") with the random walk q_N2ps (N^2/s) at the PF's period
 * and |F_d| <= the actuator's force, as machine.py derives them from
 * estimator.pf.load; q_N2ps = 0 turns it off, q_N2ps < 0 leaves the machine
 * file's. */
void br_circle_use_pf_load(br_circle_cfg_t *c, double q_N2ps);

/* The external-force states' random walks as c runs them, N^2/s (0: off):
 * for the tools' reports */
double br_circle_ukf_load_q_N2ps(const br_circle_cfg_t *c);
double br_circle_pf_load_q_N2ps(const br_circle_cfg_t *c);

/* The tools' --pf-gp-curve: the PF's g_p along the Stribeck curve
 * (docs/modules/pf.md, "Fast moves") with the time constant tau_s at the PF's
 * period; tau_s <= 0 leaves the machine file's. */
void br_circle_use_pf_gp_curve(br_circle_cfg_t *c, double tau_s);

/* The tools' --pf-gate: the PF's outlier gate (est.outlier_sigma, docs/modules/pf.md,
 * "The gate"), sigma standard deviations; sigma <= 0 leaves the machine file's. A study
 * setting (docs/presliding-plants.md, "The PF's gate"). */
void br_circle_use_pf_gate(br_circle_cfg_t *c, double sigma);

/* The tools' --pf-adapt-max: cfg.adapt's largest variance factor (docs/modules/pf.md,
 * "Keeping lock"); 1 keeps the factor at 1, the thesis filter; s <= 0 leaves the
 * machine file's; no effect where cfg.adapt is off (nis_ref 0). A study setting
 * (docs/fleet.md, "The PF's start on the fleet's axes"). */
void br_circle_use_pf_adapt_max(br_circle_cfg_t *c, double s);

/* The tools' --machine-causes: the PF's and the UKF's estimation model with the
 * machine file's causes (br_machine_causes), the estimator the image built for
 * the machine runs, instead of the thesis model (docs/fleet.md, "The estimators
 * as the image has them"). */
void br_circle_use_machine_causes(br_circle_cfg_t *c);

/* The tools' --delay-id: 0 turns both estimators' delay identification off
 * (est.delay_id, docs/modules/dlyid.md); any other value leaves the machine's. */
void br_circle_use_delay_id(br_circle_cfg_t *c, long on);

/* The tools' circle (--radius-m, --feed-mm-min, --dir; docs/circle-test.md):
 * radius_m > 0 sets the radius A, feed_mps > 0 the tangential feed v = 2 pi A / T;
 * either one sets the period T = 2 pi A / v (a radius alone keeps c's feed,
 * T scaled by the radius's ratio) and as many revolutions as c had (the
 * thesis: one, duration = T). Neither (both <= 0): c's circle bit for bit.
 * ccw != 0 runs it counter-clockwise (c->dir = -1), else clockwise. */
void br_circle_use_path(br_circle_cfg_t *c, double radius_m, double feed_mps, int ccw);

/* The tangential feed of c's circle, 2 pi A / T, m/s. */
double br_circle_feed_mps(const br_circle_cfg_t *c);

/* The firmware's controller configuration of one axis of cfg: its gains and
 * period, the machine's torque limit, the plant's amplifier, encoder and lead
 * (also what sim/apps/br_track.c runs). */
br_ctrl_cfg_t br_circle_ctrl_cfg(const br_circle_cfg_t *cfg);

/* One control period of both axes (load side, true plant positions). */
typedef struct {
    double t_s;
    double ref_m[2];     /* x, y reference */
    double pos_m[2];     /* x, y plant position */
    double vel_mps[2];   /* x, y plant velocity */
    int32_t counts[2];   /* x, y encoder readings */
    double radial_err_m; /* hypot(x, y) - A: + is outward */
    double duty[2];
    double fnl_N[2];     /* true LuGre force of each axis */
    double F_hat_N[2];   /* the compensation used (0 for H-inf only) */
    const br_pf_t *pf[2]; /* the filters after this period's step (PF only, else NULL) */
    const br_ukf_t *ukf[2]; /* likewise for the UKF */
} br_circle_sample_t;

typedef void (*br_circle_sink_t)(void *user, const br_circle_sample_t *s);

/* Runs the experiment, calling sink (if not NULL) once per period. Returns 0;
 * 1 when the firmware stopped an axis (a fault: zero duty, the status and time
 * in res->fault_status, fault_t_s; the results cover the periods before it);
 * -1 with a message on stderr on an invalid configuration, res->fault_cause
 * BR_RUN_CAUSE_REFUSED_AT_INIT (and res->fault_status the BR_E_*) when it was
 * the firmware that refused the application at init (br_run_report.h). */
int br_circle_run(const br_circle_cfg_t *cfg, br_circle_sink_t sink, void *user, br_circle_result_t *res);

/* The application elsewhere: the image in the loop (sim/apps/br_pil.c, docs/link.md,
 * "The image in the loop"). br_circle_run_remote calls step once per axis and
 * period in place of br_app_step, with the encoder count the application would
 * read; step answers with what the remote application did, and the run applies
 * port_duty to the plant through the simulator's PWM port. step returns 0, or
 * -1 (with a message on stderr) when the remote cannot answer, which ends the
 * run with -1. */
typedef struct {
    float port_duty;  /* what the remote's PWM port holds: the amplifier's input */
    int status;       /* the period's status (br_app_step's) */
    int fault;        /* br_app_fault_t after the period */
    float duty;       /* the controller's duty (br_app_t.last.duty) */
    float F_hat_N;    /* the compensation used */
    int saturated;    /* the torque saturated */
} br_circle_remote_out_t;

typedef struct {
    int (*step)(void *user, int axis, long k, int32_t counts, br_circle_remote_out_t *out);
    void *user;
} br_circle_remote_t;

/* br_circle_run with each axis's application remote (NULL: br_circle_run). The
 * configuration must be one the remote runs (the caller's to check). */
int br_circle_run_remote(const br_circle_cfg_t *cfg, const br_circle_remote_t *remote, br_circle_sink_t sink,
                         void *user, br_circle_result_t *res);

/* The circle's reference of axis (0 x, 1 y) at t: what br_circle_run hands
 * br_app_step, and the position in metres in *x_ref. */
br_ref_t br_circle_axis_ref(const br_circle_cfg_t *c, int axis, double t, double *x_ref);

/* A sink writing CSV rows t,x_ref,y_ref,x,y,radial_err,duty_x,duty_y,fnl_x,fnl_y,
 * fhat_x,fhat_y,gp_x,gp_y (gp: the PF's mean g_p, else empty) to the FILE *
 * given as user; br_circle_csv_header writes the header line. */
void br_circle_csv_header(FILE *f);
void br_circle_csv_sink(void *user, const br_circle_sample_t *s);

#endif
