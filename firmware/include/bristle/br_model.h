/* Four-state estimation model of one ball-screw axis (thesis eq. 6), float32.
 *
 * State x = [theta (rad), omega (rad/s), z (m), g_p (N)] on the motor side;
 * g_p is the Stribeck level treated as a slowly varying parameter.
 *   dtheta/dt = omega
 *   domega/dt = (u - L (sigma2 L omega + f_nl(x))) / (J + L^2 M)
 *   dz/dt     = L omega - sigma0 L |omega| z / g_p
 *   dg_p/dt   = 0
 *   f_nl(x)   = sigma0 z + sigma1 dz/dt              (the lumped friction)
 * See docs/modules/model.md for the discretisation. */
#ifndef BR_MODEL_H
#define BR_MODEL_H

#include "bristle/br_lugre.h"
#include "bristle/br_status.h"

enum { BR_X_THETA = 0, BR_X_OMEGA = 1, BR_X_Z = 2, BR_X_GP = 3, BR_NX = 4 };

/* RK4 is used while the bristle rate times the step, a h = sigma0 L |omega| h / g_p,
 * stays at or below this value (RK4's real-axis stability bound is 2.785);
 * beyond it the step switches to the bounded displacement-exact scheme. */
#define BR_MODEL_RK4_AH_MAX 2.0f

typedef struct {
    float J_kgm2;       /* motor + screw inertia, > 0 */
    float M_kg;         /* table mass, >= 0 */
    float lead_mprad;   /* L = lead / (2 pi), > 0 */
    float sigma2_Nspm;  /* viscous friction, >= 0 */
    br_lugre_cfg_t lugre;
    float dt_s;         /* discretisation step, > 0 */
} br_model_cfg_t;

typedef struct {
    br_model_cfg_t cfg;
    float inv_Jeff;     /* 1 / (J + L^2 M) */
    float visc_Nmsprad; /* L^2 sigma2 */
    int ready;
} br_model_t;

br_status_t br_model_init(br_model_t *m, const br_model_cfg_t *cfg);

/* Eq. 6 right-hand side f(x, u). */
void br_model_deriv(const br_model_t *m, const float x[BR_NX], float u_Nm, float dx[BR_NX]);

/* Lumped friction f_nl(x) in N (load side). */
float br_model_fnl_N(const br_model_t *m, const float x[BR_NX]);

/* One discretisation step of dt_s with the torque u_Nm held:
 * RK4 where a h <= BR_MODEL_RK4_AH_MAX, otherwise the bounded scheme.
 * Non-finite input or g_p <= 0 gives BR_E_INPUT and x_next = x. */
br_status_t br_model_step(const br_model_t *m, const float x[BR_NX], float u_Nm, float x_next[BR_NX]);

#endif
