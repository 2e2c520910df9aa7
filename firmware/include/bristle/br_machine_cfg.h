/* SPDX-License-Identifier: Apache-2.0 */
/* The firmware configurations of the machine the generated headers describe
 * (bristle_gen/: br_machine.h, br_est_machine.h, br_pf_tuned.h, br_ukf_tuned.h,
 * br_noise_table.h; docs/machine-file.md): one home for the simulator's
 * circle (sim/lib/circle/br_circle_est.c) and the STM32H743 image
 * (hal/stm32/image/br_image_main.c), which holds them const, in flash.
 *
 * Initialisers, not functions, so that a program can place the result in
 * flash (static const ... = BR_MACHINE_PF_CFG_TUNED(dt)). Every value is a
 * float constant expression, evaluated in float as the same expression at run
 * time would be (variances in counts^2 times rad_per_count, twice, in that
 * order), so a compile-time and a run-time configuration are bit-identical.
 * The model's causes are the machine file's (BR_MACHINE_CAUSES; none: the
 * thesis model). */
#ifndef BR_MACHINE_CFG_H
#define BR_MACHINE_CFG_H

#include "bristle/br_app.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/est/br_noise_table.h"
#include "bristle_gen/est/br_pf_tuned.h"
#include "bristle_gen/est/br_ukf_tuned.h"
#include "bristle_gen/machine/br_machine.h"

/* the machine's H-infinity controller at period dt (float): the synthesised
 * gains (bristle_gen/ctrl/br_hinf_gains.h), the actuator's torque limit and
 * torque per duty, the encoder's resolution and the screw's lead */
#define BR_MACHINE_CTRL_CFG(dt)                                                                    \
    {.K = BR_HINF_K,                                                                               \
     .dt_s = (dt),                                                                                 \
     .tau_max_Nm = BR_MACHINE_TORQUE_LIMIT_NM_F,                                                   \
     .tau_per_duty_Nm = BR_MACHINE_TAU_PER_DUTY_NM_F,                                              \
     .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,                                                  \
     .lead_mprad = BR_MACHINE_LEAD_MPRAD_F}

/* the machine's values the drive protections derive from (br_app_motion_cfg) */
#define BR_MACHINE_APP_MACHINE                                                                     \
    {                                                                                              \
        .lead_mprad = BR_MACHINE_LEAD_MPRAD_F, .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F,        \
        .mass_kg = BR_MACHINE_M_KG_F, .inertia_kgm2 = BR_MACHINE_J_KGM2_F,                         \
        .Fc_N = BR_MACHINE_FC_N_F, .Fs_N = BR_MACHINE_FS_N_F,                                      \
        .max_speed_mps = BR_MACHINE_MAX_SPEED_MPS_F, .max_accel_mps2 = BR_MACHINE_MAX_ACCEL_MPS2_F, \
        .max_following_m = BR_MACHINE_MAX_FOLLOWING_M_F, .travel_m = BR_MACHINE_TRAVEL_M_F,        \
        .travel_min_m = BR_MACHINE_TRAVEL_MIN_M_F, .period_s = BR_MACHINE_LOOP_PERIOD_S_F,         \
        .coast_in_stroke = (int)BR_MACHINE_COAST_IN_STROKE,                                        \
        .delay_s = BR_MACHINE_ACTUATOR_DELAY_S_F                                                   \
    }
/* the estimators' friction: the machine file's friction_model (BR_MACHINE_MSLIP, written
 * only for maxwell_slip); without it n = 0, LuGre (eqs. 3-5) */
#ifndef BR_MACHINE_MSLIP
#define BR_MACHINE_MSLIP {.n = 0}
#endif

/* an estimator's delay identification (E: PF or UKF; docs/modules/dlyid.md; 0 candidates: off) */
#define BR_MACHINE_DELAY_ID_CFG(E)                                                                 \
    {                                                                                              \
        .n_cand = BR_EST_##E##_DELAY_ID_CANDIDATES, .step_s = BR_EST_##E##_DELAY_ID_STEP_S_F,      \
        .q_force_N2ps = BR_EST_##E##_DELAY_ID_Q_FORCE_N2PS_F,                                      \
        .memory_s = BR_EST_##E##_DELAY_ID_MEMORY_S_F, .warmup_s = BR_EST_##E##_DELAY_ID_WARMUP_S_F, \
        .switch_ratio = BR_EST_##E##_DELAY_ID_SWITCH_RATIO_F,                                      \
        .steady_after_s = BR_EST_##E##_DELAY_ID_STEADY_AFTER_S_F,                                  \
        .steady_memory_s = BR_EST_##E##_DELAY_ID_STEADY_MEMORY_S_F,                                \
        .steady_switch_ratio = BR_EST_##E##_DELAY_ID_STEADY_SWITCH_RATIO_F                         \
    }

/* the PF's shared external force: the machine file's estimator.pf.load (BR_EST_PF_LOAD_*,
 * written only with the block); without it off, both 0 (docs/modules/pf.md, "External force") */
#ifndef BR_EST_PF_LOAD_Q_N2_F
#define BR_EST_PF_LOAD_Q_N2_F 0.0f
#define BR_EST_PF_LOAD_MAX_N_F 0.0f
#endif

/* the eq. 6 estimation model of the machine at period dt (float) */
#define BR_MACHINE_MODEL_CFG(dt)                                                                   \
    {                                                                                              \
        .J_kgm2 = BR_MACHINE_J_KGM2_F, .M_kg = BR_MACHINE_M_KG_F,                                  \
        .lead_mprad = BR_MACHINE_LEAD_MPRAD_F, .sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM_F,            \
        .lugre = {.sigma0_Npm = BR_MACHINE_SIGMA0_NPM_F, .sigma1_Nspm = BR_MACHINE_SIGMA1_NSPM_F,  \
                  .Fc_N = BR_MACHINE_FC_N_F, .Fs_N = BR_MACHINE_FS_N_F,                            \
                  .vs_mps = BR_MACHINE_VS_MPS_F},                                                  \
        .dt_s = (dt), .causes = BR_MACHINE_CAUSES, .mslip = BR_MACHINE_MSLIP                       \
    }

/* What both filters take from the estimator section (br_est_cfg_t; E: PF or
 * UKF): the model at period dt, the process noise q_* (rad^2, (rad/s)^2, m^2,
 * N^2) and the measurement noise r (rad^2), the g_p range, the gates, the
 * lead and the delay identification. */
#define BR_MACHINE_EST_CFG(E, dt, q_theta, q_omega, q_z, q_gp, r)                                  \
    {                                                                                              \
        .model = BR_MACHINE_MODEL_CFG(dt), .q_var = {(q_theta), (q_omega), (q_z), (q_gp)},         \
        .r_var_rad2 = (r), .gp0_N = BR_EST_##E##_GP0_N_F, .gp_min_N = BR_EST_##E##_GP_MIN_N_F,     \
        .gp_max_N = BR_EST_##E##_GP_MAX_N_F, .outlier_sigma = BR_EST_##E##_OUTLIER_SIGMA_F,        \
        .outlier_transient_rad = BR_EST_##E##_OUTLIER_TRANSIENT_RAD_F,                             \
        .reanchor_after = BR_EST_##E##_REANCHOR_AFTER, .rad_per_count = BR_MACHINE_RAD_PER_COUNT_F, \
        .comp_ahead_periods = BR_EST_##E##_COMP_AHEAD_PERIODS_F,                                   \
        .delay_id = BR_MACHINE_DELAY_ID_CFG(E)                                                     \
    }

/* The PF at period dt with the process noise q_omega, q_z, q_gp and the
 * measurement noise r (rad^2); the rest from the machine file's estimator
 * section (particles, theta noise and spreads in counts, g_p range, gates). */
#define BR_MACHINE_PF_CFG_Q(dt, q_omega, q_z, q_gp, r)                                             \
    {                                                                                              \
        .est = BR_MACHINE_EST_CFG(PF, dt,                                                          \
                                  BR_EST_PF_Q_THETA_COUNTS2_F * BR_MACHINE_RAD_PER_COUNT_F *       \
                                      BR_MACHINE_RAD_PER_COUNT_F,                                  \
                                  q_omega, q_z, q_gp, r),                                          \
        .n_particles = BR_EST_PF_N_PARTICLES,                                                      \
        .x0_std = {BR_EST_PF_X0_STD_THETA_COUNTS_F * BR_MACHINE_RAD_PER_COUNT_F,                   \
                   BR_EST_PF_X0_STD_OMEGA_RADPS_F, BR_EST_PF_X0_STD_Z_M_F, BR_EST_PF_X0_STD_GP_N_F}, \
        .noise = br_noise_table, .noise_len = BR_NOISE_LEN, .noise_skip = BR_EST_PF_NOISE_SKIP,    \
        .adapt = {.nis_ref = BR_EST_PF_ADAPT_NIS_REF_F, .alpha = BR_EST_PF_ADAPT_ALPHA_F,            \
                  .max_scale = BR_EST_PF_ADAPT_MAX_SCALE_F},                                       \
        .gp_curve = {.on = BR_EST_PF_GP_CURVE_ON, .rho = BR_EST_PF_GP_CURVE_RHO_F},                \
        .load = {BR_EST_PF_LOAD_Q_N2_F, BR_EST_PF_LOAD_MAX_N_F}                                    \
    }

/* the machine file's (hand-tuned) variances: the start of the tuning */
#define BR_MACHINE_PF_CFG_DEFAULT(dt)                                                              \
    BR_MACHINE_PF_CFG_Q(dt, BR_EST_PF_Q_OMEGA_RAD2PS2_F, BR_EST_PF_Q_Z_M2_F, BR_EST_PF_Q_GP_N2_F,  \
                        BR_EST_PF_R_COUNTS2_F * BR_MACHINE_RAD_PER_COUNT_F * BR_MACHINE_RAD_PER_COUNT_F)
/* the variances found by Nelder-Mead (br_pf_tuned.h): what the demo runs */
#define BR_MACHINE_PF_CFG_TUNED(dt)                                                                \
    BR_MACHINE_PF_CFG_Q(dt, BR_PF_TUNED_q_omega, BR_PF_TUNED_q_z, BR_PF_TUNED_q_gp, BR_PF_TUNED_r)

/* The UKF at period dt with the process noise q_* (rad^2, (rad/s)^2, m^2, N^2)
 * and measurement noise r (rad^2); the rest from the estimator section. */
#define BR_MACHINE_UKF_CFG_Q(dt, q_theta, q_omega, q_z, q_gp, r)                                   \
    {                                                                                              \
        .est = BR_MACHINE_EST_CFG(UKF, dt, q_theta, q_omega, q_z, q_gp, r),                        \
        .p0_var = {BR_EST_UKF_P0_THETA_COUNTS2_F * BR_MACHINE_RAD_PER_COUNT_F *                    \
                       BR_MACHINE_RAD_PER_COUNT_F,                                                 \
                   BR_EST_UKF_P0_OMEGA_RAD2PS2_F, BR_EST_UKF_P0_Z_M2_F, BR_EST_UKF_P0_GP_N2_F},    \
        .alpha = BR_EST_UKF_ALPHA_F, .beta = BR_EST_UKF_BETA_F, .kappa = BR_EST_UKF_KAPPA_F,       \
        .load = {BR_EST_UKF_LOAD_Q_N2_F, BR_EST_UKF_LOAD_P0_N2_F, BR_EST_UKF_LOAD_MAX_N_F}         \
    }

#define BR_MACHINE_UKF_CFG_DEFAULT(dt)                                                             \
    BR_MACHINE_UKF_CFG_Q(dt, BR_EST_UKF_Q_THETA_RAD2_F, BR_EST_UKF_Q_OMEGA_RAD2PS2_F,              \
                         BR_EST_UKF_Q_Z_M2_F, BR_EST_UKF_Q_GP_N2_F,                                \
                         BR_EST_UKF_R_COUNTS2_F * BR_MACHINE_RAD_PER_COUNT_F * BR_MACHINE_RAD_PER_COUNT_F)
#define BR_MACHINE_UKF_CFG_TUNED(dt)                                                               \
    BR_MACHINE_UKF_CFG_Q(dt, BR_UKF_TUNED_q_theta, BR_UKF_TUNED_q_omega, BR_UKF_TUNED_q_z,         \
                         BR_UKF_TUNED_q_gp, BR_UKF_TUNED_r)

#endif
