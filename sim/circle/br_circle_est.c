/* Estimator configurations for the circle experiment (docs/modules/pf.md). */
#include "br_circle_est.h"

#include "bristle_gen/est/br_noise_table.h"
#include "bristle_gen/est/br_pf_tuned.h"
#include "bristle_gen/est/br_ukf_tuned.h"
#include "bristle_gen/machine/br_machine.h"

br_model_cfg_t br_ref_model_cfg(float dt_s)
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
    c.est.model = br_ref_model_cfg(dt_s);
    c.n_particles = 1500u;
    /* hand-tuned on the circle by a grid (docs/modules/pf.md) */
    c.est.q_var[BR_X_THETA] = 0.01f * rpc * rpc;
    c.est.q_var[BR_X_OMEGA] = 5.0e-6f;
    c.est.q_var[BR_X_Z] = 1.0e-14f;
    c.est.q_var[BR_X_GP] = 0.1f;
    c.est.r_var_rad2 = 0.3f * rpc * rpc;
    c.est.gp0_N = BR_MACHINE_FS_N_F;
    c.x0_std[BR_X_THETA] = 0.3f * rpc;
    c.x0_std[BR_X_OMEGA] = 1.0e-3f;
    c.x0_std[BR_X_Z] = 1.0e-7f;
    c.x0_std[BR_X_GP] = 2.0f;
    c.est.gp_min_N = 0.5f * BR_MACHINE_FC_N_F;
    c.est.gp_max_N = 1.5f * BR_MACHINE_FS_N_F;
    c.est.outlier_sigma = 30.0f;
    c.est.reanchor_after = 3u;
    c.est.rad_per_count = rpc;
    c.noise = br_noise_table;
    c.noise_len = BR_NOISE_LEN;
    c.noise_skip = 1u;
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_default(float dt_s)
{
    const float rpc = BR_MACHINE_RAD_PER_COUNT_F;
    br_ukf_cfg_t c;
    c.est.model = br_ref_model_cfg(dt_s);
    /* the values of docs/modules/ukf.md (lightly hand-tuned) */
    c.est.q_var[BR_X_THETA] = 1.0e-14f;
    c.est.q_var[BR_X_OMEGA] = 1.0e-6f;
    c.est.q_var[BR_X_Z] = 1.0e-15f;
    c.est.q_var[BR_X_GP] = 0.05f;
    c.est.r_var_rad2 = 4.0f * rpc * rpc / 12.0f;
    c.est.gp0_N = 12.0f;
    c.p0_var[BR_X_THETA] = rpc * rpc;
    c.p0_var[BR_X_OMEGA] = 1.0e-4f;
    c.p0_var[BR_X_Z] = 1.0e-12f;
    c.p0_var[BR_X_GP] = 25.0f;
    c.est.gp_min_N = 1.0f;
    c.est.gp_max_N = 40.0f;
    c.est.outlier_sigma = 50.0f;
    c.est.reanchor_after = 3u;
    c.est.rad_per_count = rpc;
    c.alpha = 1.0f;
    c.beta = 2.0f;
    c.kappa = 0.0f;
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
