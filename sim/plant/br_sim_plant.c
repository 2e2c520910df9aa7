/* Double-precision plant of one ball-screw axis. Scheme in br_sim_plant.h and
 * docs/modules/plant.md. */
#include "br_sim_plant.h"

#include <math.h>
#include <stdio.h>

#include "br_reference_machine.h"

/* Fixed-point passes on the mean velocity of a substep. The map contracts by
 * about 2 sigma1 L^2 h / Jeff (6e-3 at h = 50 us), so 4 passes leave an error
 * far below double rounding of the state increments. */
#define BR_PLANT_PASSES 4

#define BR_PI 3.14159265358979323846

br_plant_cfg_t br_plant_cfg_reference(void)
{
    br_plant_cfg_t c;
    c.J_kgm2 = BR_REF_J_KGM2;
    c.M_kg = BR_REF_M_KG;
    c.lead_mprad = BR_REF_LEAD_MPRAD;
    c.sigma2_Nspm = BR_REF_SIGMA2_NSPM;
    c.sigma0_Npm = BR_REF_SIGMA0_NPM;
    c.sigma1_Nspm = BR_REF_SIGMA1_NSPM;
    c.Fc_N = BR_REF_FC_N;
    c.Fs_N = BR_REF_FS_N;
    c.vs_mps = BR_REF_VS_MPS;
    c.counts_per_rev = BR_REF_COUNTS_PER_REV;
    c.tau_per_duty_Nm = BR_REF_TAU_PER_DUTY_NM;
    c.n_sub = 20;
    return c;
}

static double lugre_force(const br_plant_t *p);

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
    p->cfg = *cfg;
    p->x = *x0;
    /* eq. 1: effective inertia seen by the motor */
    p->Jeff_kgm2 = cfg->J_kgm2 + cfg->lead_mprad * cfg->lead_mprad * cfg->M_kg;
    p->tau_Nm = 0.0;
    p->fnl_N = lugre_force(p);
    return 0;
}

/* eq. 5: Stribeck level */
static double stribeck_g(const br_plant_cfg_t *c, double v)
{
    return c->Fc_N + (c->Fs_N - c->Fc_N) * exp(-fabs(v) / c->vs_mps);
}

/* eq. 3 at the current state */
static double lugre_force(const br_plant_t *p)
{
    const br_plant_cfg_t *c = &p->cfg;
    const double v = c->lead_mprad * p->x.omega_radps;
    const double g = stribeck_g(c, v);
    return c->sigma0_Npm * p->x.z_m + c->sigma1_Nspm * (v - c->sigma0_Npm * fabs(v) * p->x.z_m / g);
}

static void substep(br_plant_t *p, double tau, double h)
{
    const br_plant_cfg_t *c = &p->cfg;
    const double L = c->lead_mprad;
    const double w0 = p->x.omega_radps, z0 = p->x.z_m;
    double wm = w0, dth = 0.0, z1 = z0, w1 = w0;
    for (int pass = 0; pass < BR_PLANT_PASSES; pass++) {
        dth = wm * h;
        const double dx = L * dth;
        const double g = stribeck_g(c, L * wm);
        double zint;
        if (dx != 0.0) {
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
        /* eq. 1 integrated over h: Jeff dw = tau h - L^2 sigma2 dtheta - L (sigma0 int z + sigma1 dz) (eq. 3) */
        w1 = w0 + (tau * h - L * L * c->sigma2_Nspm * dth - L * (c->sigma0_Npm * zint + c->sigma1_Nspm * (z1 - z0))) / p->Jeff_kgm2;
        /* trapezoidal rule: mean velocity of the substep */
        wm = 0.5 * (w0 + w1);
    }
    p->x.theta_rad += dth;
    p->x.omega_radps = w1;
    p->x.z_m = z1;
}

void br_plant_step(br_plant_t *p, double duty, double dt_s)
{
    const br_plant_cfg_t *c = &p->cfg;
    /* amplifier: duty clamped to [-1, 1], torque held over the period */
    double d = isfinite(duty) ? fmin(fmax(duty, -1.0), 1.0) : 0.0;
    double tau = d * c->tau_per_duty_Nm;
    double h = dt_s / c->n_sub;
    for (int i = 0; i < c->n_sub; i++) {
        substep(p, tau, h);
    }
    p->tau_Nm = tau;
    p->fnl_N = lugre_force(p); /* eq. 3 at the end of the step */
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

double br_plant_pos_m(const br_plant_t *p) { return p->cfg.lead_mprad * p->x.theta_rad; }

double br_plant_vel_mps(const br_plant_t *p) { return p->cfg.lead_mprad * p->x.omega_radps; }
