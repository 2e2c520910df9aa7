/* Estimator configurations for the circle experiment, from the machine
 * description (bristle_gen/est/, docs/machine-file.md; docs/modules/pf.md). */
#include "br_circle_est.h"

#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/est/br_noise_table.h"
#include "bristle_gen/est/br_pf_tuned.h"
#include "bristle_gen/est/br_ukf_tuned.h"
#include "bristle_gen/machine/br_machine.h"

br_model_cfg_t br_machine_model_cfg(float dt_s)
{
    br_model_cfg_t m = {0}; /* no causes: the thesis model */
    m.J_kgm2 = BR_MACHINE_J_KGM2_F;
    m.M_kg = BR_MACHINE_M_KG_F;
    m.lead_mprad = BR_MACHINE_LEAD_MPRAD_F;
    m.sigma2_Nspm = BR_MACHINE_SIGMA2_NSPM_F;
    m.lugre.sigma0_Npm = BR_MACHINE_SIGMA0_NPM_F;
    m.lugre.sigma1_Nspm = BR_MACHINE_SIGMA1_NSPM_F;
    m.lugre.Fc_N = BR_MACHINE_FC_N_F;
    m.lugre.Fs_N = BR_MACHINE_FS_N_F;
    m.lugre.vs_mps = BR_MACHINE_VS_MPS_F;
    m.dt_s = dt_s;
    return m;
}

br_pf_cfg_t br_circle_pf_cfg_default(float dt_s)
{
    const float rpc = BR_MACHINE_RAD_PER_COUNT_F;
    br_pf_cfg_t c;
    c.est.model = br_machine_model_cfg(dt_s);
    c.n_particles = BR_EST_PF_N_PARTICLES;
    /* the machine file's estimator section (hand-tuned on the reference circle by a grid,
     * docs/modules/pf.md); theta in counts */
    c.est.q_var[BR_X_THETA] = BR_EST_PF_Q_THETA_COUNTS2_F * rpc * rpc;
    c.est.q_var[BR_X_OMEGA] = BR_EST_PF_Q_OMEGA_RAD2PS2_F;
    c.est.q_var[BR_X_Z] = BR_EST_PF_Q_Z_M2_F;
    c.est.q_var[BR_X_GP] = BR_EST_PF_Q_GP_N2_F;
    c.est.r_var_rad2 = BR_EST_PF_R_COUNTS2_F * rpc * rpc;
    c.est.gp0_N = BR_EST_PF_GP0_N_F;
    c.x0_std[BR_X_THETA] = BR_EST_PF_X0_STD_THETA_COUNTS_F * rpc;
    c.x0_std[BR_X_OMEGA] = BR_EST_PF_X0_STD_OMEGA_RADPS_F;
    c.x0_std[BR_X_Z] = BR_EST_PF_X0_STD_Z_M_F;
    c.x0_std[BR_X_GP] = BR_EST_PF_X0_STD_GP_N_F;
    c.est.gp_min_N = BR_EST_PF_GP_MIN_N_F;
    c.est.gp_max_N = BR_EST_PF_GP_MAX_N_F;
    c.est.outlier_sigma = BR_EST_PF_OUTLIER_SIGMA_F;
    c.est.reanchor_after = BR_EST_PF_REANCHOR_AFTER;
    c.est.rad_per_count = rpc;
    c.noise = br_noise_table;
    c.noise_len = BR_NOISE_LEN;
    c.noise_skip = BR_EST_PF_NOISE_SKIP;
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_default(float dt_s)
{
    const float rpc = BR_MACHINE_RAD_PER_COUNT_F;
    br_ukf_cfg_t c;
    c.est.model = br_machine_model_cfg(dt_s);
    /* the machine file's estimator section (docs/modules/ukf.md, lightly hand-tuned) */
    c.est.q_var[BR_X_THETA] = BR_EST_UKF_Q_THETA_RAD2_F;
    c.est.q_var[BR_X_OMEGA] = BR_EST_UKF_Q_OMEGA_RAD2PS2_F;
    c.est.q_var[BR_X_Z] = BR_EST_UKF_Q_Z_M2_F;
    c.est.q_var[BR_X_GP] = BR_EST_UKF_Q_GP_N2_F;
    c.est.r_var_rad2 = BR_EST_UKF_R_COUNTS2_F * rpc * rpc;
    c.est.gp0_N = BR_EST_UKF_GP0_N_F;
    c.p0_var[BR_X_THETA] = BR_EST_UKF_P0_THETA_COUNTS2_F * rpc * rpc;
    c.p0_var[BR_X_OMEGA] = BR_EST_UKF_P0_OMEGA_RAD2PS2_F;
    c.p0_var[BR_X_Z] = BR_EST_UKF_P0_Z_M2_F;
    c.p0_var[BR_X_GP] = BR_EST_UKF_P0_GP_N2_F;
    c.est.gp_min_N = BR_EST_UKF_GP_MIN_N_F;
    c.est.gp_max_N = BR_EST_UKF_GP_MAX_N_F;
    c.est.outlier_sigma = BR_EST_UKF_OUTLIER_SIGMA_F;
    c.est.reanchor_after = BR_EST_UKF_REANCHOR_AFTER;
    c.est.rad_per_count = rpc;
    c.alpha = BR_EST_UKF_ALPHA_F;
    c.beta = BR_EST_UKF_BETA_F;
    c.kappa = BR_EST_UKF_KAPPA_F;
    return c;
}

br_pf_cfg_t br_circle_pf_cfg_tuned(float dt_s)
{
    br_pf_cfg_t c = br_circle_pf_cfg_default(dt_s);
    c.est.q_var[BR_X_OMEGA] = BR_PF_TUNED_q_omega;
    c.est.q_var[BR_X_Z] = BR_PF_TUNED_q_z;
    c.est.q_var[BR_X_GP] = BR_PF_TUNED_q_gp;
    c.est.r_var_rad2 = BR_PF_TUNED_r;
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_tuned(float dt_s)
{
    br_ukf_cfg_t c = br_circle_ukf_cfg_default(dt_s);
    c.est.q_var[BR_X_THETA] = BR_UKF_TUNED_q_theta;
    c.est.q_var[BR_X_OMEGA] = BR_UKF_TUNED_q_omega;
    c.est.q_var[BR_X_Z] = BR_UKF_TUNED_q_z;
    c.est.q_var[BR_X_GP] = BR_UKF_TUNED_q_gp;
    c.est.r_var_rad2 = BR_UKF_TUNED_r;
    return c;
}
