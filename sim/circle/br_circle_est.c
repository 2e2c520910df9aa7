/* Estimator configurations for the circle experiment, from the machine
 * description: the firmware's one home for them, bristle/br_machine_cfg.h
 * (bristle_gen/est/, docs/machine-file.md; docs/modules/pf.md), which the
 * STM32H743 image uses too. */
#include "br_circle_est.h"

#include "bristle/br_machine_cfg.h"

br_model_cfg_t br_machine_model_cfg(float dt_s)
{
    const br_model_cfg_t m = BR_MACHINE_MODEL_CFG(dt_s); /* no causes: the thesis model */
    return m;
}

br_pf_cfg_t br_circle_pf_cfg_default(float dt_s)
{
    const br_pf_cfg_t c = BR_MACHINE_PF_CFG_DEFAULT(dt_s);
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_default(float dt_s)
{
    const br_ukf_cfg_t c = BR_MACHINE_UKF_CFG_DEFAULT(dt_s);
    return c;
}

br_pf_cfg_t br_circle_pf_cfg_tuned(float dt_s)
{
    const br_pf_cfg_t c = BR_MACHINE_PF_CFG_TUNED(dt_s);
    return c;
}

br_ukf_cfg_t br_circle_ukf_cfg_tuned(float dt_s)
{
    const br_ukf_cfg_t c = BR_MACHINE_UKF_CFG_TUNED(dt_s);
    return c;
}
