/* SPDX-License-Identifier: Apache-2.0 */
/* Estimator configurations for the circle experiment, from the machine
 * description: the firmware's one home for them, bristle/br_machine_cfg.h
 * (bristle_gen/est/, docs/machine-file.md; docs/modules/pf.md), which the
 * STM32H743 image uses too. The image takes the machine file's causes
 * (BR_MACHINE_CAUSES); here the estimators are on the thesis model, so that
 * "nominal" stays nominal for any machine: the tools that run the extended
 * model set est.model.causes themselves (br_circle_ext, br_track), and
 * --machine-causes (br_robust_run, br_track) puts the machine file's back, as
 * the image has them (br_machine_causes). */
#include "br_circle_est.h"

#include "bristle/br_machine_cfg.h"
#include "bristle_gen/machine/br_machine.h"

br_model_cfg_t br_machine_model_cfg(float dt_s)
{
    br_model_cfg_t m = BR_MACHINE_MODEL_CFG(dt_s);
    m.causes = (br_causes_t){0}; /* the thesis model */
    return m;
}

br_causes_t br_machine_causes(void)
{
    const br_causes_t c = BR_MACHINE_CAUSES;
    return c;
}

br_pf_cfg_t br_circle_pf_cfg_default(float dt_s)
{
    br_pf_cfg_t c = BR_MACHINE_PF_CFG_DEFAULT(dt_s);
    c.est.model.causes = (br_causes_t){0}; /* the thesis model */
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_default(float dt_s)
{
    br_ukf_cfg_t c = BR_MACHINE_UKF_CFG_DEFAULT(dt_s);
    c.est.model.causes = (br_causes_t){0}; /* the thesis model */
    return c;
}

br_pf_cfg_t br_circle_pf_cfg_tuned(float dt_s)
{
    br_pf_cfg_t c = BR_MACHINE_PF_CFG_TUNED(dt_s);
    c.est.model.causes = (br_causes_t){0}; /* the thesis model */
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_tuned(float dt_s)
{
    br_ukf_cfg_t c = BR_MACHINE_UKF_CFG_TUNED(dt_s);
    c.est.model.causes = (br_causes_t){0}; /* the thesis model */
    return c;
}

br_ff_cfg_t br_circle_ff_cfg_machine(void)
{
    br_ff_cfg_t c = {0};
    const br_model_cfg_t m = BR_MACHINE_MODEL_CFG(1.0e-3f);
    c.Fc_N = m.lugre.Fc_N;
    c.Fs_N = m.lugre.Fs_N;
    c.vs_mps = m.lugre.vs_mps;
    c.sigma2_Nspm = m.sigma2_Nspm;
    c.v_eps_mps = (float)BR_CIRCLE_FF_VEPS_MPS;
    c.mass_kg = 0.0f;
    c.comp_max_N = BR_MACHINE_TORQUE_LIMIT_NM_F / m.lead_mprad;
    return c;
}

br_qec_cfg_t br_circle_qec_cfg_machine(float dt_s)
{
    br_qec_cfg_t c = {0};
#ifdef BR_MACHINE_QEC_A0_N
    c.A0_N = BR_MACHINE_QEC_A0_N_F;
    c.A1_kg = BR_MACHINE_QEC_A1_KG_F;
    c.tau_s = BR_MACHINE_QEC_TAU_S_F;
#else
    c.tau_s = dt_s; /* no reversal_comp: no pulse (A0 = A1 = 0) */
#endif
    c.dt_s = dt_s;
    c.comp_max_N = br_circle_ff_cfg_machine().comp_max_N;
    c.with_ff = 0;
    c.ff = br_circle_ff_cfg_machine();
    return c;
}
