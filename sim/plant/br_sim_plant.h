/* Double-precision plant of one ball-screw axis (thesis eqs. 1-5): rigid
 * body + viscous + LuGre friction, encoder quantisation, amplifier.
 *
 *   (J + L^2 M) domega/dt = tau - L (sigma2 L omega + F_nl)
 *   F_nl = sigma0 z + sigma1 dz/dt,  dz/dt = L omega - sigma0 L |omega| z / g(L omega)
 *   tau = duty * tau_per_duty  (duty clamped to [-1, 1], held over the period)
 *
 * Integration (docs/modules/plant.md): substeps of h = dt / n_sub. Over each
 * substep z follows the exact solution of the bristle equation written over
 * the displacement (bounded at any speed), the friction impulse is integrated
 * in closed form (sigma0 * integral of z, sigma1 * change of z), and the rigid
 * body uses the trapezoidal rule, solved by a fixed number of fixed-point
 * iterations on the mean velocity. */
#ifndef BR_SIM_PLANT_H
#define BR_SIM_PLANT_H

#include <stdint.h>

typedef struct {
    double J_kgm2, M_kg, lead_mprad, sigma2_Nspm;
    double sigma0_Npm, sigma1_Nspm, Fc_N, Fs_N, vs_mps;
    double counts_per_rev;    /* encoder on the motor */
    double tau_per_duty_Nm;   /* amplifier gain */
    int n_sub;                /* substeps per step, >= 1 */
} br_plant_cfg_t;

typedef struct {
    double theta_rad, omega_radps, z_m;
} br_plant_state_t;

typedef struct {
    br_plant_cfg_t cfg;
    br_plant_state_t x;
    double Jeff_kgm2;
    double tau_Nm;     /* torque applied during the last step */
    double fnl_N;      /* LuGre force at the end of the last step */
} br_plant_t;

/* Reference machine of ../shared/spec/reference-machine.md. */
br_plant_cfg_t br_plant_cfg_reference(void);

/* 0 on success, -1 on an invalid configuration (message on stderr). */
int br_plant_init(br_plant_t *p, const br_plant_cfg_t *cfg, const br_plant_state_t *x0);

/* Advances by dt_s with the duty held (zero-order hold). */
void br_plant_step(br_plant_t *p, double duty, double dt_s);

/* Encoder reading: floor(theta / rad_per_count), wrapped modulo 2^32. */
int32_t br_plant_encoder(const br_plant_t *p);

/* Load-side position and velocity. */
double br_plant_pos_m(const br_plant_t *p);
double br_plant_vel_mps(const br_plant_t *p);

#endif
