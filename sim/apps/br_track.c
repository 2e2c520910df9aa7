/* SPDX-License-Identifier: Apache-2.0 */
/* br_track: a measured log's own reference trajectory (its t,ref columns) on
 * the plant of the machine this build is for (BR_MACHINE), or of a model.json
 * (--model: the identified plant with its causes), with each controller:
 *
 *   pd           the log's position loop (the EMPS form of sim/lib/ident/br_ident.h:
 *                u = kp kv (ref - q) - kv qdot, |u| <= u_max, F = gain u), --pd
 *   hinf_only    the firmware (br_app_step), H-infinity only, control period
 *   hinf_pf      the firmware with the PF on the nominal model, the PF's period
 *   hinf_ukf     the firmware with the UKF on the nominal model, the control period
 *   hinf_pf_ext  the same PF on the extended model: est.model.causes set from
 *                the plant's causes (--model), the firmware's extended model
 *   hinf_true    the limit: H-infinity compensating the plant's true friction
 *                (an oracle no real machine has)
 *   hinf_ff      H-infinity + the static feedforward (firmware/ff) of the plant's
 *                model (--model): friction on the reference velocity, its
 *                causes, and the moving mass times the reference acceleration
 *   hinf_pf_ff   H-infinity + the PF (nominal model) + the feedforward's inertia
 *                term alone (moving mass times the reference acceleration)
 *   hinf_pf_ext_ff  the same with the PF on the extended model
 *   hinf_true_ff the oracle + the inertia term: the limit of an estimator
 *                beside an acceleration feedforward
 *   hinf_inertia, hinf_pf_inertia, hinf_ukf_inertia
 *                H-infinity alone, + the PF, + the UKF, each with the inertia
 *                feedforward of the build's machine file (its moving mass, not
 *                the plant's, times the reference acceleration): what the
 *                firmware knows, no oracle (docs/fleet.md, "The tracks")
 *
 * The firmware's configuration (gains, periods, estimator settings) is the
 * build's machine's (br_circle_cfg_thesis). The tracking error is the
 * reference minus the plant's true load position at each control period.
 * docs/configure.md, docs/machines/emps.md.
 *
 * Usage: br_track --ref LOG.csv [--model MODEL.json] [--pd KP,KV,GAIN,UMAX]
 *                 [--ctrl pd,hinf_only,hinf_pf,hinf_pf_ext,hinf_true,hinf_ff,hinf_pf_ff,
 *                        hinf_pf_ext_ff,hinf_true_ff,hinf_ukf,hinf_inertia,hinf_pf_inertia,
 *                        hinf_ukf_inertia] [--json OUT] [--trace DIR] [--machine-causes]
 * --machine-causes: the UKF and the PF of the runs not on the extended model (the
 * _ext ones keep the plant's) carry the build's machine file's causes, as the image does (br_machine_causes;
 * docs/fleet.md, "The estimators as the image has them"), not the thesis model.
 * Prints one line per controller: tracking RMS and maximum error. --trace
 * writes each run's trace, and for hinf_pf and hinf_pf_ext one row per PF
 * step (pf_trace_row). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "circle/br_circle.h"
#include "circle/br_circle_pftrace.h"
#include "hal_sim/br_hal_sim.h"
#include "plant/br_model_params.h"
#include "gms_args/br_gms_args.h"
#include "plant/br_plant_json.h"
#include "cause_args/br_cause_args.h"
#include "tool/br_args.h"
#include "tool/br_logcsv.h"
#include "tool/br_outfile.h"
#include "tool/br_run_report.h"

#define BR_PI 3.14159265358979323846

typedef struct {
    double t0, dt;
    double *ref;
    long n;
} traj_t;

/* the t and ref columns of a measured log, by the diagnosis's rules (tool/br_logcsv.h) */
static int read_traj(const char *path, traj_t *tr)
{
    static const char *const names[] = {"t", "ref"};
    br_logcsv_t lg;
    if (br_logcsv_read("br_track", path, names, 2, 2, &lg) != 0) return -1;
    tr->t0 = lg.t0;
    tr->dt = lg.col[0][1] - lg.col[0][0];
    tr->n = lg.n;
    tr->ref = lg.col[1];
    free(lg.col[0]);
    return 0;
}

/* the reference at t (from the log's start), linear between samples, held
 * outside; its velocity by a central difference over one log sample */
static double traj_ref(const traj_t *tr, double t)
{
    const double u = t / tr->dt;
    if (u <= 0.0) return tr->ref[0];
    const long i = (long)floor(u);
    if (i >= tr->n - 1) return tr->ref[tr->n - 1];
    return tr->ref[i] + (u - (double)i) * (tr->ref[i + 1] - tr->ref[i]);
}

static double traj_vel(const traj_t *tr, double t)
{
    return (traj_ref(tr, t + tr->dt) - traj_ref(tr, t - tr->dt)) / (2.0 * tr->dt);
}

/* its acceleration by a central second difference over one log sample */
static double traj_acc(const traj_t *tr, double t)
{
    return (traj_ref(tr, t + tr->dt) - 2.0 * traj_ref(tr, t) + traj_ref(tr, t - tr->dt)) / (tr->dt * tr->dt);
}

/* the run-in of a log that starts at speed v0 (run_fw): from rest at
 * constant acceleration v0 / t_s over the t_s before the log, ending at the
 * log's first sample x0 with its speed */
typedef struct {
    double x0, v0, t_s;
} run_in_t;

/* the run-in's position at t in [-t_s, 0): x0 - v0 t_s / 2 + v0 tau^2 / (2 t_s), tau = t + t_s */
static double run_in_ref(const run_in_t *ri, double t)
{
    const double tau = t + ri->t_s;
    return (ri->t_s > 0.0) ? ri->x0 - 0.5 * ri->v0 * ri->t_s + 0.5 * ri->v0 * tau * tau / ri->t_s : ri->x0;
}

/* its speed: v0 tau / t_s */
static double run_in_vel(const run_in_t *ri, double t)
{
    return (ri->t_s > 0.0) ? ri->v0 * (t + ri->t_s) / ri->t_s : 0.0;
}

/* the PF's estimate plus the feedforward, clamped to what the controller accepts */
typedef struct {
    br_est_t inner;
    br_ff_t ff;
} pf_ff_t;

static br_status_t pf_ff_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    pf_ff_t *w = ctx;
    float f_ff = 0.0f;
    const br_status_t st = w->inner.step(w->inner.ctx, y, u_prev_Nm, F_hat_N);
    if (BR_FAILED(st)) return st;
    const br_status_t s2 = br_ff_est_step(&w->ff, y, u_prev_Nm, &f_ff);
    if (BR_FAILED(s2)) return s2;
    *F_hat_N = fminf(fmaxf(*F_hat_N + f_ff, -w->ff.cfg.comp_max_N), w->ff.cfg.comp_max_N);
    return st;
}

typedef struct {
    double sum2, emax;
    long n;
    FILE *trace;
    FILE *pf_trace; /* --pf-trace: the PF's steps (hinf_pf only) */
} err_t;

static void err_add(err_t *e, double t, double ref, double pos, double force_N)
{
    const double er = ref - pos;
    e->sum2 += er * er;
    if (fabs(er) > e->emax) e->emax = fabs(er);
    e->n++;
    if (e->trace) fprintf(e->trace, "%.6f,%.10e,%.10e,%.6e,%.6e\n", t, ref, pos, er, force_N);
}

/* the log's position loop on the plant, at the log's period */
static int run_pd(const traj_t *tr, const br_plant_cfg_t *pc, const double pd[4], err_t *e)
{
    br_plant_t p;
    const br_plant_state_t x0 = {tr->ref[0] / pc->lead_mprad, 0.0, 0.0};
    if (br_plant_init(&p, pc, &x0) != 0) return -1;
    const double m_per_count = pc->lead_mprad * 2.0 * BR_PI / pc->counts_per_rev;
    double q_prev = 0.0, qf_prev = 0.0;
    for (long k = 0; k < tr->n; k++) {
        const double t = (double)k * tr->dt, r = tr->ref[k];
        const double q = (double)br_plant_encoder(&p) * m_per_count;
        if (k == 0) q_prev = qf_prev = q;
        const double qf = 0.5 * (q + q_prev), qdot = (qf - qf_prev) / tr->dt;
        q_prev = q;
        qf_prev = qf;
        const double u = fmin(fmax(pd[0] * pd[1] * (r - q) - pd[1] * qdot, -pd[3]), pd[3]);
        err_add(e, t, r, br_plant_pos_m(&p), pd[2] * u);
        br_plant_step(&p, pd[2] * u * pc->lead_mprad / pc->tau_per_duty_Nm, tr->dt);
    }
    return 0;
}

/* the limit's "estimator": the plant's true friction at t_k */
static br_status_t oracle_step(void *ctx, const br_meas_t *y, float u_prev_Nm, float *F_hat_N)
{
    (void)y;
    (void)u_prev_Nm;
    *F_hat_N = (float)br_plant_comp_force_N((const br_plant_t *)ctx);
    return BR_OK;
}

/* --pf-trace: one row per PF step of the hinf_pf runs (docs/modules/pf.md,
 * "Fast moves"): the plant's truth beside the filter's cloud after the step,
 * the best particle's miss and the gate. Positions in counts relative to the
 * filter's origin, speeds in m/s, forces in N. */
static void pf_trace_row(FILE *f, double t, const br_plant_t *p, const br_pf_t *pf)
{
    const double rpc = (double)pf->cfg.est.rad_per_count, L = (double)pf->cfg.est.model.lead_mprad;
    double mean[BR_NX], sd[BR_NX], miss;
    br_pftrace_cloud(pf, mean, sd, &miss);
    const double inv2r = (double)pf->inv_2r;
    const double th_true = p->x.theta_rad - (double)pf->origin_counts * rpc;
    /* the plant's Stribeck level g(v) (eq. 5) */
    const double g_true = p->cfg.Fc_N + (p->cfg.Fs_N - p->cfg.Fc_N) * exp(-fabs(br_plant_vel_mps(p)) / p->cfg.vs_mps);
    fprintf(f, "%.6f,%.6e,%.6e,%.6e,%.6e,%.4f,%.4f,%.4f,%.6e,%.6e,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u\n", t,
            br_plant_vel_mps(p), p->fnl_N, (double)pf->est.F_hat_N, L * mean[BR_X_OMEGA], (th_true - mean[0]) / rpc,
            sd[0] / rpc, miss, L * sd[BR_X_OMEGA], mean[BR_X_Z], mean[BR_X_GP], sd[BR_X_GP],
            sqrt(-(double)pf->lmax / inv2r) / rpc, sqrt(-(double)pf->outlier_l / inv2r) / rpc, (double)pf->nis_avg,
            (double)pf->q_scale_std, g_true, (unsigned)pf->n_outliers);
}

/* the firmware (br_app_step) with the build's machine configuration */
/* ff: 0 none, 1 the feedforward of the plant's model (friction, causes, inertia; ctrl
 * BR_CTRL_HINF_FF), 2 the estimator (ctrl BR_CTRL_HINF_PF: the PF; BR_CTRL_HINF_TRUE:
 * the oracle) plus the feedforward's inertia term (the plant's mass), 3 the inertia term of
 * the build's machine file (its mass) alone (ctrl BR_CTRL_HINF_ONLY) or beside the estimator
 * (BR_CTRL_HINF_PF, BR_CTRL_HINF_UKF) */
/* *n_limited: the periods whose reference the drive's limiter changed (br_app_ref_limit; the run-in
 * included), 0 when the application never ran */
/* causes: 0 the thesis model, 1 the plant's causes (the _ext runs), 2 the machine file's (--machine-causes) */
static int run_fw(const traj_t *tr, const br_plant_cfg_t *pc, br_circle_ctrl_t ctrl, int causes, int ff, err_t *e,
                  br_run_report_t *rep, uint32_t *n_limited)
{
    *n_limited = 0u;
    br_circle_cfg_t c = br_circle_cfg_thesis(ctrl);
    const br_plant_cfg_t mach = c.plant; /* the build's machine file's plant */
    c.plant = *pc;
    if (causes == 1) c.pf.est.model.causes = br_causes_from_model(pc);
    if (causes == 2) br_circle_use_machine_causes(&c);
    static pf_ff_t w; /* the feedforward (and the PF's br_est_t for ff 2) */
    if (ff) {
        /* the feedforward from the plant's model (ff 3: the machine file's) */
        const br_plant_cfg_t *fp = (ff == 3) ? &mach : pc;
        br_circle_cfg_t m = c;
        br_circle_use_model(&m, fp);
        c.ff = m.ff;
        c.ff.mass_kg = (float)(fp->J_kgm2 / (fp->lead_mprad * fp->lead_mprad) + fp->M_kg);
        if (ff >= 2) {
            /* the inertia term alone: the PF estimates the friction */
            c.ff.Fs_N = c.ff.Fc_N = 1e-20f;
            c.ff.sigma2_Nspm = 0.0f;
            memset(&c.ff.causes, 0, sizeof c.ff.causes);
        }
        if (br_ff_init(&w.ff, &c.ff) != BR_OK) {
            fprintf(stderr, "br_track: invalid feedforward configuration\n");
            return -1;
        }
    }
    const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(&c);
    br_plant_t p;
    br_hal_sim_t port;
    br_hal_t hal;
    br_app_t app;
    br_app_mem_t mem = {NULL, NULL};
    const br_est_t ext = {&p, oracle_step, NULL, NULL};
    /* the encoder's plausibility guard from the trajectory's own top speed
     * (twice it: the axis lags and overshoots), in counts/s of this plant */
    double vmax = 0.0;
    for (long i = 0; i < tr->n; i++) vmax = fmax(vmax, fabs(traj_vel(tr, (double)i * tr->dt)));
    const double counts_per_m = pc->counts_per_rev / (2.0 * BR_PI * pc->lead_mprad);
    const br_app_est_kind_t kind = ctrl == BR_CTRL_HINF_PF    ? BR_APP_EST_PF
                                   : ctrl == BR_CTRL_HINF_UKF ? BR_APP_EST_UKF
                                                              : BR_APP_EST_NONE;
    br_app_cfg_t ac = {&cc, kind, &c.pf, &c.ukf, &ext,
                       br_app_guard_cfg(cc.dt_s, (float)(2.0 * vmax * counts_per_m + 1.0 / c.dt_s)),
                       br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE)};
    if (ctrl == BR_CTRL_HINF_TRUE) ac.est = BR_APP_EST_EXTERN;
    /* a log that starts in motion (EMPS: 0.015 m/s at its first sample): a
     * run-in from rest before it at half the limiter's acceleration, n_run
     * periods, not counted in the figures; the drive's reference limiter
     * would otherwise limit the speed step at the arm and the run would
     * track another trajectory than the log's */
    const double v0 = (tr->ref[1] - tr->ref[0]) / tr->dt;
    const double a_run = 0.5 * (double)ac.motion.max_accel_mps2;
    const long n_run = (a_run > 0.0) ? (long)ceil(fabs(v0) / a_run / c.dt_s) : 0;
    const run_in_t ri = {tr->ref[0], v0, (double)n_run * c.dt_s};
    const br_plant_state_t x0 = {run_in_ref(&ri, -ri.t_s) / pc->lead_mprad, 0.0, 0.0};
    int rc = -1;
    br_status_t refused = BR_OK; /* the firmware refused the application at init (br_run_report.h) */
    if (ctrl == BR_CTRL_HINF_PF && (mem.pf = calloc(1, sizeof *mem.pf)) == NULL) return -1;
    if (ctrl == BR_CTRL_HINF_UKF && (mem.ukf = calloc(1, sizeof *mem.ukf)) == NULL) return -1;
    br_est_t ffe = {&w.ff, br_ff_est_step, NULL, NULL};
    if (ff == 1 || (ff == 3 && kind == BR_APP_EST_NONE)) {
        ac.est = BR_APP_EST_EXTERN;
        ac.ext = &ffe;
    } else if (ff >= 2) {
        /* the PF as configured (or the oracle), behind the wrapper that adds the inertia term */
        if (ctrl == BR_CTRL_HINF_TRUE) w.inner = ext;
        else if ((refused = br_app_est_init(&ac, &mem, &w.inner)) != BR_OK) {
            fprintf(stderr, "br_track: PF init failed\n");
            goto done;
        }
        ffe = (br_est_t){&w, pf_ff_step, NULL, NULL};
        ac.est = BR_APP_EST_EXTERN;
        ac.ext = &ffe;
    }
    if (br_plant_init(&p, pc, &x0) != 0 || br_hal_sim_init(&port, &p, c.dt_s, &hal) != BR_OK) goto done;
    br_status_t st = br_app_init(&app, &ac, &hal, &mem);
    if (st == BR_OK) st = br_app_arm(&app); /* the simulator arms right after init */
    if (st != BR_OK) {
        fprintf(stderr, "br_track: application init failed (status %d)\n", (int)st);
        refused = st;
        goto done;
    }
    const double L = pc->lead_mprad, rpc = 2.0 * BR_PI / pc->counts_per_rev;
    const long n = lround((double)(tr->n - 1) * tr->dt / c.dt_s);
    rep->fault_status = 0;
    for (long k = -n_run; k <= n; k++) {
        const double t = (double)k * c.dt_s;
        uint32_t tick;
        hal.tick_wait(hal.ctx, &tick);
        const double x_ref = (k < 0) ? run_in_ref(&ri, t) : traj_ref(tr, t);
        const double v_ref = (k < 0) ? run_in_vel(&ri, t) : traj_vel(tr, t);
        const double counts = x_ref / L / rpc, whole = floor(counts);
        const br_ref_t r = {(int32_t)whole, (float)(counts - whole), (float)(v_ref / L)};
        if (ff) {
            const double a_ref = (k < 0) ? ri.v0 / ri.t_s : traj_acc(tr, t);
            const br_ff_in_t in = {(float)v_ref, (float)a_ref, (float)x_ref};
            br_ff_set_ref(&w.ff, &in);
        }
        const double pos = br_plant_pos_m(&p);
        const uint32_t pos0 = mem.pf ? mem.pf->noise_pos : 0u;
        st = br_app_step(&app, &r);
        /* a PF step moved the noise table on */
        if (e->pf_trace && mem.pf && mem.pf->noise_pos != pos0 && mem.pf->primed) pf_trace_row(e->pf_trace, t, &p, mem.pf);
        if (st != BR_OK && st != BR_W_OUTLIER) {
            rep->fault_status = (int)st;
            rep->fault_cause = (int)app.fault;
            rep->fault_t_s = t;
            break;
        }
        if (k >= 0) err_add(e, t, x_ref, pos, (double)app.last.duty * pc->tau_per_duty_Nm / L);
    }
    *n_limited = app.n_ref_limited;
    rc = 0;
done:
    if (refused != BR_OK) {
        /* the run never started: a fault at 0 s, counted, never a figure */
        rep->fault_status = (int)refused;
        rep->fault_cause = BR_RUN_CAUSE_REFUSED_AT_INIT;
        rep->fault_t_s = 0.0;
        rc = 0;
    }
    free(mem.pf);
    free(mem.ukf);
    return rc;
}

#define TOOL "br_track"

/* --speed-cap LO,HI: the largest reference speed (m/s) the drive's limiter passes untouched
 * anywhere in [LO, HI] toward either end (br_app_ref_speed_cap_mps at HI toward the high end
 * and at LO toward the low one: its caps shrink toward each end), for the application of
 * every controller this tool runs (their periods differ): the smallest, printed alone on
 * stdout. The question a trajectory built for this drive asks (sim/studies/fleet_axis.py). */
static int speed_cap(const br_plant_cfg_t *pc, double lo, double hi)
{
    static const br_circle_ctrl_t ctrls[] = {BR_CTRL_HINF_ONLY, BR_CTRL_HINF_PF, BR_CTRL_HINF_UKF};
    double v = INFINITY;
    for (size_t i = 0; i < sizeof ctrls / sizeof ctrls[0]; i++) {
        br_circle_cfg_t c = br_circle_cfg_thesis(ctrls[i]);
        c.plant = *pc;
        const br_ctrl_cfg_t cc = br_circle_ctrl_cfg(&c);
        const br_app_motion_cfg_t mc = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE);
        const br_app_cfg_t ac = {&cc, BR_APP_EST_NONE, NULL, NULL, NULL,
                                 br_app_guard_cfg(cc.dt_s, mc.max_speed_mps * mc.counts_per_m), mc};
        const br_plant_state_t x0 = {0.0, 0.0, 0.0};
        br_plant_t p;
        br_hal_sim_t port;
        br_hal_t hal;
        br_app_t app;
        br_app_mem_t mem = {NULL, NULL};
        if (br_plant_init(&p, pc, &x0) != 0 || br_hal_sim_init(&port, &p, c.dt_s, &hal) != BR_OK ||
            br_app_init(&app, &ac, &hal, &mem) != BR_OK) {
            fprintf(stderr, "%s: --speed-cap: the application for this machine did not initialise\n", TOOL);
            return 1;
        }
        v = fmin(v, fmin((double)br_app_ref_speed_cap_mps(&app, (float)hi, 1),
                         (double)br_app_ref_speed_cap_mps(&app, (float)lo, 0)));
    }
    printf("%.9g\n", v);
    return 0;
}

/* DIR/KIND_NAME.csv through br_outfile (docs/tools.md, rule 2) */
static int open_trace(br_outfile_t *o, const char *dir, const char *kind, const char *name)
{
    char path[BR_OUTFILE_PATH_MAX];
    const int n = snprintf(path, sizeof path, "%s/%s_%s.csv", dir, kind, name);
    if (n < 0 || (size_t)n >= sizeof path) {
        fprintf(stderr, "%s: cannot write %s/%s_%s.csv: path too long\n", TOOL, dir, kind, name);
        return -1;
    }
    return br_outfile_open(o, TOOL, path);
}

static int usage(const char *argv0, FILE *to)
{
    fprintf(to,
            "usage: %s --ref LOG.csv [--model MODEL.json] [--pd KP,KV,GAIN,UMAX]\n"
            "          [--ctrl pd,hinf_only,hinf_pf,hinf_pf_ext,hinf_true,hinf_ff,hinf_pf_ff,\n"
            "                  hinf_pf_ext_ff,hinf_true_ff,hinf_ukf,hinf_inertia,hinf_pf_inertia,\n"
            "                  hinf_ukf_inertia] [--json OUT] [--trace DIR] [--machine-causes]\n"
            "          [--gms D1,..,DN] [--gms-zeta Z]\n"
            "       %s --speed-cap LO,HI [--model MODEL.json]\n"
            BR_ARGS_COMMON_USAGE
            "  --ref LOG.csv       the measured log whose reference trajectory is tracked\n"
            "  --model MODEL.json  the plant from a diagnosis's saved model\n"
            "  --pd KP,KV,GAIN,UMAX the log's position loop (all > 0): adds the pd run\n"
            "  --ctrl LIST         the controllers to run, comma-separated\n"
            "  --json OUT          the runs' figures as JSON\n"
            "  --trace DIR         each run's trace as CSV into DIR (track_NAME.csv), and for\n"
            "                      the PF runs its steps (pf_NAME.csv: truth, cloud, miss, gate)\n"
            "  --machine-causes    the UKF and the PF with the machine file's causes, as the image has them\n"
            "                      (not the _ext runs: the plant's)\n"
            "  --speed-cap LO,HI   print the largest reference speed (m/s) this build's drive passes\n"
            "                      untouched in [LO, HI] m toward either end (max speed, the braking\n"
            "                      curve to the soft limits, the coast envelope), and run nothing\n",
            argv0, argv0, argv0);
    br_gms_usage(to);
    return 2;
}

int main(int argc, char **argv)
{
    const char *ref = NULL, *model = NULL, *json = NULL, *trace = NULL, *ctrls = NULL;
    double pd[4], cap[2];
    int have_pd = 0, have_cap = 0, machine_causes = 0;
    br_gms_args_t gms = BR_GMS_ARGS_DEFAULT;
    static const struct option opts[] = {{"ref", required_argument, NULL, 'r'},
                                         {"model", required_argument, NULL, 'm'},
                                         {"json", required_argument, NULL, 'j'},
                                         {"trace", required_argument, NULL, 't'},
                                         {"ctrl", required_argument, NULL, 'c'},
                                         {"pd", required_argument, NULL, 'p'},
                                         {"speed-cap", required_argument, NULL, 's'},
                                         {"machine-causes", no_argument, NULL, 'M'},
                                         BR_GMS_LONGOPTS{NULL, 0, NULL, 0}};
    br_args_t p;
    if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;
    const char *val;
    for (int o; (o = br_args_next(&p, opts, &val)) != BR_ARGS_END;) {
        switch (o) {
        case 'r': ref = val; break;
        case 'm': model = val; break;
        case 'j': json = val; break;
        case 't': trace = val; break;
        case 'c': ctrls = val; break;
        case 'M': machine_causes = 1; break;
        case 'p':
            have_pd = br_parse_numbers(val, pd, 4) == 4 && pd[0] > 0.0 && pd[1] > 0.0 && pd[2] > 0.0 && pd[3] > 0.0;
            if (!have_pd) {
                fprintf(stderr, "%s: --pd needs KP,KV,GAIN,UMAX, all > 0: %s\n", TOOL, val);
                return 2;
            }
            break;
        case 's':
            have_cap = br_parse_numbers(val, cap, 2) == 2 && isfinite(cap[0]) && isfinite(cap[1]) && cap[0] <= cap[1] &&
                       fabs(cap[0]) <= 1e3 && fabs(cap[1]) <= 1e3;
            if (!have_cap) {
                fprintf(stderr, "%s: --speed-cap needs LO,HI in m, LO <= HI, both within +-1e3: %s\n", TOOL, val);
                return 2;
            }
            break;
        case BR_GMS_OPT:
            if (br_gms_arg(TOOL, p.opt, val, &gms) != 0) return usage(argv[0], stderr);
            break;
        default: return usage(argv[0], stderr); /* BR_ARGS_BAD: reported */
        }
    }
    if (br_gms_args_check(TOOL, &gms) != 0) return usage(argv[0], stderr);
    if (have_cap) {
        br_plant_cfg_t pc = br_plant_cfg_reference();
        char m[512];
        if (model && br_plant_cfg_from_model_json(model, &pc, &pc, m, sizeof m) != 0) {
            fprintf(stderr, "br_track: %s\n", m);
            return 1;
        }
        return speed_cap(&pc, cap[0], cap[1]);
    }
    if (!ref) {
        fprintf(stderr, "%s: --ref is required\n", TOOL);
        return usage(argv[0], stderr);
    }
    if (!ctrls) ctrls = have_pd ? "pd,hinf_only,hinf_pf,hinf_pf_ext,hinf_true" : "hinf_only,hinf_pf,hinf_pf_ext,hinf_true";
    br_plant_cfg_t plant = br_plant_cfg_reference();
    char msg[512];
    if (model && br_plant_cfg_from_model_json(model, &plant, &plant, msg, sizeof msg) != 0) {
        fprintf(stderr, "br_track: %s\n", msg);
        return 1;
    }
    /* --gms: the plant's friction Maxwell-slip (after the model: its Fs and moving mass) */
    br_gms_args_apply(&gms, &plant);
    traj_t tr;
    if (read_traj(ref, &tr) != 0) return 1;
    /* written to a temporary file, renamed onto --json only when every run succeeded */
    br_outfile_t out = {0};
    if (json && br_outfile_open(&out, TOOL, json) != 0) {
        free(tr.ref);
        return 1;
    }
    FILE *js = out.f;
    if (js)
        fprintf(js, "{\n  \"generator\": \"br_track (sim/apps/br_track.c); generated, do not edit\",\n"
                    "  \"duration_s\": %.6g,\n  \"estimator_causes\": \"%s\"", (double)(tr.n - 1) * tr.dt,
                machine_causes ? "machine" : "thesis");
    static const char *const names[] = {"pd",           "hinf_only",       "hinf_pf",        "hinf_pf_ext",
                                        "hinf_true",    "hinf_ff",         "hinf_pf_ff",     "hinf_pf_ext_ff",
                                        "hinf_true_ff", "hinf_ukf",        "hinf_inertia",   "hinf_pf_inertia",
                                        "hinf_ukf_inertia"};
    const int n_names = (int)(sizeof names / sizeof names[0]);
    int rc = 0;
    static br_outfile_t traces[20];
    int ntraces = 0;
    for (int w = 0; w < n_names && rc == 0; w++) {
        const size_t len = strlen(names[w]);
        const char *hit = strstr(ctrls, names[w]);
        while (hit && ((hit != ctrls && hit[-1] != ',') || (hit[len] != ',' && hit[len] != '\0')))
            hit = strstr(hit + 1, names[w]);
        if (!hit) continue;
        err_t e = {0.0, 0.0, 0, NULL, NULL};
        if (trace) {
            /* each trace to a temporary file, renamed with the others when every run succeeded */
            if (open_trace(&traces[ntraces], trace, "track", names[w]) != 0) {
                rc = 1;
                break;
            }
            e.trace = traces[ntraces++].f;
            fprintf(e.trace, "t,ref,pos,err,force\n");
            if (w == 2 || w == 3) {
                if (open_trace(&traces[ntraces], trace, "pf", names[w]) != 0) {
                    rc = 1;
                    break;
                }
                e.pf_trace = traces[ntraces++].f;
                fprintf(e.pf_trace, "t,v_mps,fnl_true_N,F_hat_N,v_mean_mps,th_err_counts,th_sd_counts,best_miss_counts,"
                                    "v_sd_mps,z_mean_m,gp_mean_N,gp_sd_N,miss_min_counts,gate_counts,nis_avg,"
                                    "q_scale_std,g_true_N,n_outliers\n");
            }
        }
        br_run_report_t rep = {0.0, 0.0, 0, 0, 0.0};
        uint32_t n_limited = 0u;
        if (w == 0) {
            if (!have_pd) {
                fprintf(stderr, "br_track: the pd controller needs --pd KP,KV,GAIN,UMAX\n");
                rc = 2;
            } else if (run_pd(&tr, &plant, pd, &e) != 0) rc = 1;
        } else {
            const br_circle_ctrl_t ctrl = (w == 1 || w == 10) ? BR_CTRL_HINF_ONLY
                                          : (w == 4 || w == 8) ? BR_CTRL_HINF_TRUE
                                          : w == 5 ? BR_CTRL_HINF_FF
                                          : (w == 9 || w == 12) ? BR_CTRL_HINF_UKF : BR_CTRL_HINF_PF;
            const int ff = w == 5 ? 1 : (w >= 6 && w <= 8) ? 2 : (w >= 10) ? 3 : 0;
            const int causes = (w == 3 || w == 7) ? 1 : machine_causes ? 2 : 0;
            if (run_fw(&tr, &plant, ctrl, causes, ff, &e, &rep, &n_limited) != 0) rc = 1;
        }
        if (rc != 0) break;
        rep.rms_m = e.n > 0 ? sqrt(e.sum2 / (double)e.n) : NAN;
        rep.max_m = e.emax;
        /* a run of no period, or a non-finite figure, is no result (docs/tools.md, rule 3) */
        if (rep.fault_status == 0 && !(isfinite(rep.rms_m) && isfinite(rep.max_m))) {
            fprintf(stderr, "%s: %s: the tracking error is not finite (or no period ran): no result\n", TOOL, names[w]);
            rc = 1;
            break;
        }
        /* a faulted run is a fault (time, cause), never an RMS beside full runs */
        br_run_print(stdout, names[w], "tracking", &rep);
        /* the drive's reference limiter (docs/modules/app.md, "Drive protections"): a reference it
         * changed is another trajectory than the log's, said beside the figure */
        if (n_limited > 0u) printf("  %s: the drive limited the reference in %u periods\n", names[w], (unsigned)n_limited);
        if (js) {
            fprintf(js, ",\n  \"%s\": {", names[w]);
            br_run_json(js, "rms_m", "max_m", &rep);
            if (w != 0) fprintf(js, ", \"ref_limited_periods\": %u", (unsigned)n_limited);
            fprintf(js, "}");
        }
    }
    if (js) fprintf(js, "\n}\n");
    for (int i = 0; i < ntraces; i++) {
        if (rc == 0 && br_outfile_commit(&traces[i], TOOL) != 0) rc = 1;
        br_outfile_discard(&traces[i]);
    }
    if (js) {
        if (rc != 0) br_outfile_discard(&out);
        else if (br_outfile_commit(&out, TOOL) != 0) rc = 1;
    }
    free(tr.ref);
    return rc;
}
