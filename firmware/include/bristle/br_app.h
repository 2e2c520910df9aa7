/* The application: one control period of one axis, the only place where the
 * pieces are wired together. A configuration names the controller and the
 * friction estimator; br_app_step then runs
 *
 *   encoder -> estimator (PF, UKF or none) -> controller (eq. 7, the estimate
 *   as compensation) -> PWM
 *
 * through br_axis_step, over the HAL the caller binds. The production image
 * (hal/stm32h7/image), the replay image (target/mps2) and the simulator's
 * circle experiment (sim/circle) all run br_app_step. docs/modules/app.md.
 *
 * Where the estimator's state lives: in storage the caller provides
 * (br_app_mem_t), not in a union inside br_app_t. A union would make every
 * br_app_t as large as br_pf_t (~94 KB at BR_PF_MAX_PARTICLES): the
 * H-infinity-only image, whose whole state sits in a 16 KiB stack, would
 * carry 94 KB it never uses, and a UKF application (696 B of filter) too.
 * With caller storage each program sizes and places exactly its estimator:
 * on the MCU a static br_pf_t in a RAM section (.bss in the DTCM, never the
 * stack), on the host the heap. br_app_t itself is small (the axis loop). */
#ifndef BR_APP_H
#define BR_APP_H

#include "bristle/br_axis.h"
#include "bristle/br_pf.h"
#include "bristle/br_ukf.h"

typedef enum {
    BR_APP_EST_NONE = 0,  /* no compensation: H-infinity only */
    BR_APP_EST_PF = 1,    /* particle filter, cfg->pf, state in mem->pf */
    BR_APP_EST_UKF = 2,   /* unscented Kalman filter, cfg->ukf, state in mem->ukf */
    BR_APP_EST_EXTERN = 3 /* an estimator the caller runs behind br_est_t (cfg->ext): the
                             simulator's true-friction oracle, a wrapper around a PF or UKF */
} br_app_est_kind_t;

/* Can be const, in flash. Only the pointer the kind names is read. */
typedef struct {
    const br_ctrl_cfg_t *ctrl;
    br_app_est_kind_t est;
    const br_pf_cfg_t *pf;
    const br_ukf_cfg_t *ukf;
    const br_est_t *ext;
} br_app_cfg_t;

/* The estimator's state, owned by the caller (see above); only the pointer
 * the configuration's kind names is used, the others may be NULL. */
typedef struct {
    br_pf_t *pf;
    br_ukf_t *ukf;
} br_app_mem_t;

typedef struct {
    br_axis_t axis; /* the loop; axis.F_hat_N and axis.last are the period's outputs */
} br_app_t;

/* The estimator the configuration names, initialised in its storage, as the
 * br_est_t the loop drives (est->step == NULL for BR_APP_EST_NONE). For a
 * caller that puts something in front of it (the simulator's extended-model
 * wrapper) before handing it to br_app_init as BR_APP_EST_EXTERN.
 * BR_E_NULL: cfg, cfg->ctrl, est, or the config / storage / br_est_t the kind
 * needs is NULL (mem may be NULL for NONE and EXTERN). BR_E_PARAM: an unknown
 * kind, or a PF / UKF whose period (model.dt_s) is not the controller's
 * (equal to 1e-6 relative); else the filter's own init status. */
br_status_t br_app_est_init(const br_app_cfg_t *cfg, const br_app_mem_t *mem, br_est_t *est);

/* Validates and initialises: the estimator (br_app_est_init), then the axis
 * loop over hal with the controller (br_axis_init). On any error app is left
 * not ready (br_app_step then returns BR_E_STATE). */
br_status_t br_app_init(br_app_t *app, const br_app_cfg_t *cfg, const br_hal_t *hal, const br_app_mem_t *mem);

/* One control period, after the tick: br_axis_step's status (BR_OK, the
 * estimator's warning BR_W_OUTLIER with control gone on, or an error after a
 * zero-duty write). */
br_status_t br_app_step(br_app_t *app, const br_ref_t *ref);

#endif
