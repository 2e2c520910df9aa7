/* SPDX-License-Identifier: Apache-2.0 */
/* Double-precision plant of one ball-screw axis. Scheme in br_sim_plant.h and
 * docs/modules/plant.md. */
#include "br_sim_plant.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "bristle_gen/machine/br_machine.h"

/* Fixed-point passes on the mean velocity of a substep. The map contracts by
 * about 2 sigma1 L^2 h / Jeff (6e-3 at h = 50 us), so 4 passes leave an error
 * far below double rounding of the state increments. */
#define BR_PLANT_PASSES 4

#define BR_PI 3.14159265358979323846

br_plant_cfg_t br_plant_cfg_reference(void)
{
    br_plant_cfg_t c;
    c.J_kgm2 = BR_MACHINE_J_KGM2;
    c.M_kg = BR_MACHINE_M_KG;
    c.lead_mprad = BR_MACHINE_LEAD_MPRAD;
    c.sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM;
    c.sigma0_Npm = BR_MACHINE_SIGMA0_NPM;
    c.sigma1_Nspm = BR_MACHINE_SIGMA1_NSPM;
    c.Fc_N = BR_MACHINE_FC_N;
    c.Fs_N = BR_MACHINE_FS_N;
    c.vs_mps = BR_MACHINE_VS_MPS;
    c.counts_per_rev = BR_MACHINE_COUNTS_PER_REV;
    c.tau_per_duty_Nm = BR_MACHINE_TAU_PER_DUTY_NM;
    c.n_sub = 20;
    /* causes off: every field of the registry's (bristle_gen/model/br_causes.h) */
#define CAUSE_OFF(field, cause, hook, on) c.field = 0.0;
    BR_CAUSE_FIELDS(CAUSE_OFF)
#undef CAUSE_OFF
    /* LuGre: no Maxwell-slip elements */
    memset(&c.gms, 0, sizeof c.gms);
    return c;
}

static double friction_force(const br_plant_t *p);

static double dist_force(const br_plant_cfg_t *c, double x);

int br_plant_causes_on(const br_plant_cfg_t *c)
{
    /* a field that switches its cause on (the registry's, bristle_gen/model/br_causes.h) is not 0 */
#define CAUSE_ON(field, cause, hook, on) || ((on) && c->field != 0.0)
    return 0 BR_CAUSE_FIELDS(CAUSE_ON);
#undef CAUSE_ON
}

static int bad(const char *what)
{
    fprintf(stderr, "br_plant_init: invalid %s\n", what);
    return -1;
}

#define POS(x) (isfinite(x) && (x) > 0.0)
#define NONNEG(x) (isfinite(x) && (x) >= 0.0)

int br_plant_init(br_plant_t *p, const br_plant_cfg_t *cfg, const br_plant_state_t *x0)
{
    if (!p || !cfg || !x0) return bad("NULL argument");
    if (!POS(cfg->J_kgm2)) return bad("J_kgm2 (must be > 0)");
    if (!NONNEG(cfg->M_kg)) return bad("M_kg (must be >= 0)");
    if (!POS(cfg->lead_mprad)) return bad("lead_mprad (must be > 0)");
    if (!NONNEG(cfg->sigma2_Nspm)) return bad("sigma2_Nspm (must be >= 0)");
    if (!POS(cfg->sigma0_Npm)) return bad("sigma0_Npm (must be > 0)");
    if (!NONNEG(cfg->sigma1_Nspm)) return bad("sigma1_Nspm (must be >= 0)");
    if (!POS(cfg->Fc_N)) return bad("Fc_N (must be > 0)");
    if (!(isfinite(cfg->Fs_N) && cfg->Fs_N >= cfg->Fc_N)) return bad("Fs_N (must be >= Fc_N)");
    if (!POS(cfg->vs_mps)) return bad("vs_mps (must be > 0)");
    if (!POS(cfg->counts_per_rev)) return bad("counts_per_rev (must be > 0)");
    if (!POS(cfg->tau_per_duty_Nm)) return bad("tau_per_duty_Nm (must be > 0)");
    if (cfg->n_sub < 1 || cfg->n_sub > 100000) return bad("n_sub (must be in 1..100000)");
    if (!isfinite(x0->theta_rad) || !isfinite(x0->omega_radps) || !isfinite(x0->z_m)) return bad("initial state");
    /* causes */
    if (!isfinite(cfg->offset_N)) return bad("offset_N (must be finite)");
    if (!(isfinite(cfg->dFc_neg_N) && cfg->Fc_N + cfg->dFc_neg_N > 0.0)) return bad("dFc_neg_N (Fc_N + dFc_neg_N must be > 0)");
    if (!(isfinite(cfg->dsigma2_neg_Nspm) && cfg->sigma2_Nspm + cfg->dsigma2_neg_Nspm >= 0.0))
        return bad("dsigma2_neg_Nspm (sigma2_Nspm + dsigma2_neg_Nspm must be >= 0)");
    if (!isfinite(cfg->ripple_amp_N)) return bad("ripple_amp_N (must be finite)");
    if (!isfinite(cfg->ripple_phase_rad)) return bad("ripple_phase_rad (must be finite)");
    if (!(isfinite(cfg->ripple_period_m) && (cfg->ripple_amp_N == 0.0 || cfg->ripple_period_m > 0.0)))
        return bad("ripple_period_m (must be > 0 with a ripple)");
    if (!isfinite(cfg->grad_per_m)) return bad("grad_per_m (must be finite)");
    if (!isfinite(cfg->drift_per_s)) return bad("drift_per_s (must be finite)");
    if (!(isfinite(cfg->delay_s) && cfg->delay_s >= 0.0 && cfg->delay_s <= BR_PLANT_DELAY_MAX_S))
        return bad("delay_s (must be in 0..BR_PLANT_DELAY_MAX_S)");
    const char *gms_bad = br_gms_check(&cfg->gms);
    if (gms_bad) return bad(gms_bad);
    p->cfg = *cfg;
    p->x = *x0;
    /* eq. 1: effective inertia seen by the motor */
    p->Jeff_kgm2 = cfg->J_kgm2 + cfg->lead_mprad * cfg->lead_mprad * cfg->M_kg;
    p->tau_Nm = 0.0;
    p->t_s = 0.0;
    p->cmd_head = 0;
    p->cmd_n = 0;
    p->cmd_pushed = 0;
    p->delay_overruns = 0;
    memset(&p->gms, 0, sizeof p->gms);
    p->fnl_N = friction_force(p);
    /* the offset and ripple act from the start: the oracle sees them in the first period */
    p->fdist_N = br_plant_causes_on(cfg) ? dist_force(cfg, br_plant_pos_m(p)) : 0.0;
    return 0;
}

/* eq. 5: Stribeck level; in -x the whole curve is scaled by
 * (Fc_N + dFc_neg_N) / Fc_N (dFc_neg_N = 0, symmetric friction, leaves the
 * expression as it was) */
static double stribeck_g(const br_plant_cfg_t *c, double v)
{
    const double g = c->Fc_N + (c->Fs_N - c->Fc_N) * exp(-fabs(v) / c->vs_mps);
    if (v < 0.0 && c->dFc_neg_N != 0.0) return g * ((c->Fc_N + c->dFc_neg_N) / c->Fc_N);
    return g;
}

/* The Maxwell-slip elements' Stribeck level s(v) = Fc + (Fs - Fc) exp(-(|v| / vs)^delta)
 * (presliding.md), scaled in -x like g; delta = 1 is g itself */
static double gms_level(const br_plant_cfg_t *c, double v)
{
    if (c->gms.delta == 1.0) return stribeck_g(c, v);
    const double s = c->Fc_N + (c->Fs_N - c->Fc_N) * exp(-pow(fabs(v) / c->vs_mps, c->gms.delta));
    if (v < 0.0 && c->dFc_neg_N != 0.0) return s * ((c->Fc_N + c->dFc_neg_N) / c->Fc_N);
    return s;
}

/* position factor of the friction, k(x) = max(0, 1 + grad_per_m x) */
static double grad_k(const br_plant_cfg_t *c, double x)
{
    return fmax(0.0, 1.0 + c->grad_per_m * x);
}

/* time factor of the friction (friction_drift), s(t) = max(0, 1 + drift_per_s t) */
static double drift_s(const br_plant_cfg_t *c, double t)
{
    return fmax(0.0, 1.0 + c->drift_per_s * t);
}

/* offset + ripple at load position x */
static double dist_force(const br_plant_cfg_t *c, double x)
{
    double f = c->offset_N;
    if (c->ripple_amp_N != 0.0) f += c->ripple_amp_N * sin(2.0 * BR_PI * x / c->ripple_period_m + c->ripple_phase_rad);
    return f;
}

/* eq. 3 at the current state, or the Maxwell-slip force (times k(x) with a
 * gradient, s(t) with a drift) */
static double friction_force(const br_plant_t *p)
{
    const br_plant_cfg_t *c = &p->cfg;
    const double v = c->lead_mprad * p->x.omega_radps;
    double f;
    if (c->gms.n > 0) {
        /* F = sum_i (k_i z_i + sigma1_i dz_i/dt) */
        f = br_gms_force_N(&c->gms, &p->gms, v, gms_level(c, v));
    } else {
        const double g = stribeck_g(c, v);
        f = c->sigma0_Npm * p->x.z_m + c->sigma1_Nspm * (v - c->sigma0_Npm * fabs(v) * p->x.z_m / g);
    }
    if (c->grad_per_m != 0.0 || c->drift_per_s != 0.0)
        return grad_k(c, c->lead_mprad * p->x.theta_rad) * drift_s(c, p->t_s) * f;
    return f;
}

/* Integral of the commanded torque over [a, b] (a < b), from the ring: each
 * command holds from its t_s to the next one's (the newest: onwards). Before
 * the first command the torque is 0; before the oldest kept one (history
 * overrun) the oldest is used and the overrun is counted. */
static double cmd_integral(br_plant_t *p, double a, double b)
{
    double s = 0.0, t_next = INFINITY;
    int idx = p->cmd_head;
    for (int i = 0; i < p->cmd_n; i++) {
        const br_plant_cmd_t *e = &p->cmd[idx];
        const double lo = fmax(a, e->t_s), hi = fmin(b, t_next);
        if (hi > lo) s += e->tau_Nm * (hi - lo);
        if (e->t_s <= a) return s;
        t_next = e->t_s;
        idx = (idx + BR_PLANT_DELAY_RING - 1) % BR_PLANT_DELAY_RING;
    }
    /* [a, oldest command) is left */
    if (p->cmd_pushed > p->cmd_n && p->cmd_n > 0) {
        const int oldest = (p->cmd_head + BR_PLANT_DELAY_RING - (p->cmd_n - 1)) % BR_PLANT_DELAY_RING;
        s += p->cmd[oldest].tau_Nm * (fmin(b, t_next) - a);
        p->delay_overruns++;
    }
    return s;
}

/* One substep of h with the mean torque tau over it, tm the substep's middle
 * time. With the causes on (causes != 0): the viscous coefficient and g by the
 * direction of the mean velocity, the friction impulse times k(x) s(tm) and
 * offset + ripple, at the substep's mean position and time (midpoint rule,
 * second order like the rest). */
static void substep(br_plant_t *p, double tau, double h, int causes, double tm)
{
    const br_plant_cfg_t *c = &p->cfg;
    const double L = c->lead_mprad;
    const int gms = c->gms.n > 0;
    const double w0 = p->x.omega_radps, z0 = p->x.z_m;
    double wm = w0, dth = 0.0, z1 = z0, w1 = w0;
    br_gms_state_t g1 = p->gms;
    for (int pass = 0; pass < BR_PLANT_PASSES; pass++) {
        dth = wm * h;
        const double dx = L * dth;
        double zint = 0.0, imp = 0.0;
        if (gms) {
            /* Maxwell-slip: every element's exact update at the held velocity;
             * imp = integral of sum_i (k_i z_i + sigma1_i dz_i/dt) over h */
            imp = br_gms_advance(&c->gms, &p->gms, &g1, L * wm, h, gms_level(c, L * wm));
        } else if (dx != 0.0) {
            const double g = stribeck_g(c, L * wm);
            /* eq. 4 solved exactly over the displacement with g held */
            const double zss = copysign(g / c->sigma0_Npm, dx);
            const double r = c->sigma0_Npm * fabs(dx) / g;
            const double q = -expm1(-r); /* 1 - e^{-r} */
            z1 = z0 + (zss - z0) * q;
            /* integral of z over the substep (velocity held): h (zss + (z0 - zss) q / r) */
            zint = h * (zss + (z0 - zss) * (r > 1e-12 ? q / r : 1.0 - 0.5 * r));
        } else {
            z1 = z0;
            zint = z0 * h;
        }
        if (causes) {
            const double xm = L * (p->x.theta_rad + 0.5 * dth);
            const double s2 = dth < 0.0 ? c->sigma2_Nspm + c->dsigma2_neg_Nspm : c->sigma2_Nspm;
            const double lin = L * s2 * dth;
            const double fr = gms ? lin + imp : lin + c->sigma0_Npm * zint + c->sigma1_Nspm * (z1 - z0);
            const double fric = grad_k(c, xm) * drift_s(c, tm) * fr;
            w1 = w0 + (tau * h - L * (fric + dist_force(c, xm) * h)) / p->Jeff_kgm2;
        } else {
            /* eq. 1 integrated over h: Jeff dw = tau h - L^2 sigma2 dtheta - L (sigma0 int z + sigma1 dz) (eq. 3),
             * or - L imp with the Maxwell-slip friction */
            const double fz = gms ? imp : c->sigma0_Npm * zint + c->sigma1_Nspm * (z1 - z0);
            w1 = w0 + (tau * h - L * L * c->sigma2_Nspm * dth - L * fz) / p->Jeff_kgm2;
        }
        /* trapezoidal rule: mean velocity of the substep */
        wm = 0.5 * (w0 + w1);
    }
    p->x.theta_rad += dth;
    p->x.omega_radps = w1;
    p->x.z_m = z1;
    p->gms = g1;
}

void br_plant_step(br_plant_t *p, double duty, double dt_s)
{
    const br_plant_cfg_t *c = &p->cfg;
    /* amplifier: duty clamped to [-1, 1], torque held over the period */
    double d = isfinite(duty) ? fmin(fmax(duty, -1.0), 1.0) : 0.0;
    double tau = d * c->tau_per_duty_Nm;
    double h = dt_s / c->n_sub;
    const int causes = br_plant_causes_on(c);
    if (c->delay_s > 0.0) {
        /* keep the command; each substep gets the mean of the delayed command over it */
        p->cmd_head = (p->cmd_head + 1) % BR_PLANT_DELAY_RING;
        p->cmd[p->cmd_head].t_s = p->t_s;
        p->cmd[p->cmd_head].tau_Nm = tau;
        if (p->cmd_n < BR_PLANT_DELAY_RING) p->cmd_n++;
        p->cmd_pushed++;
        const long over0 = p->delay_overruns;
        double sum = 0.0;
        for (int i = 0; i < c->n_sub; i++) {
            const double ta = p->t_s + (double)i * h - c->delay_s;
            const double ti = cmd_integral(p, ta, ta + h) / h;
            sum += ti;
            substep(p, ti, h, causes, p->t_s + ((double)i + 0.5) * h);
        }
        /* one overrun per step at most */
        if (p->delay_overruns > over0) p->delay_overruns = over0 + 1;
        tau = sum / c->n_sub;
    } else {
        for (int i = 0; i < c->n_sub; i++) {
            substep(p, tau, h, causes, p->t_s + ((double)i + 0.5) * h);
        }
    }
    p->t_s += dt_s;
    p->tau_Nm = tau;
    p->fnl_N = friction_force(p); /* eq. 3 (or the Maxwell-slip force) at the end of the step */
    if (causes) p->fdist_N = dist_force(c, br_plant_pos_m(p));
}

int32_t br_plant_encoder(const br_plant_t *p)
{
    const double rpc = 2.0 * BR_PI / p->cfg.counts_per_rev;
    /* quantisation: floor, then wrap modulo 2^32 like a free-running counter */
    double c = fmod(floor(p->x.theta_rad / rpc), 4294967296.0);
    if (c < 0.0) c += 4294967296.0;
    uint32_t u = (uint32_t)c;
    return u <= (uint32_t)INT32_MAX ? (int32_t)u : -(int32_t)(~u) - 1;
}

double br_plant_meff_kg(const br_plant_cfg_t *c) { return c->M_kg + c->J_kgm2 / (c->lead_mprad * c->lead_mprad); }

double br_plant_pos_m(const br_plant_t *p) { return p->cfg.lead_mprad * p->x.theta_rad; }

double br_plant_vel_mps(const br_plant_t *p) { return p->cfg.lead_mprad * p->x.omega_radps; }

double br_plant_comp_force_N(const br_plant_t *p)
{
    const br_plant_cfg_t *c = &p->cfg;
    const double v = br_plant_vel_mps(p);
    /* fnl_N carries k(x) s(t) already; the viscous part k s sigma2_d v - sigma2 v
     * is zero without a gradient, a drift or an asymmetry */
    const double s2 = v < 0.0 ? c->sigma2_Nspm + c->dsigma2_neg_Nspm : c->sigma2_Nspm;
    const double ks = grad_k(c, br_plant_pos_m(p)) * drift_s(c, p->t_s);
    return p->fnl_N + p->fdist_N + (ks * s2 - c->sigma2_Nspm) * v;
}
