/* SPDX-License-Identifier: Apache-2.0 */
/* Estimator configurations for the circle experiment on the configured
 * machine (BR_MACHINE; the reference machine by default). */
#ifndef BR_CIRCLE_EST_H
#define BR_CIRCLE_EST_H

#include "bristle/br_ff.h"
#include "bristle/br_pf.h"
#include "bristle/br_qec.h"
#include "bristle/br_ukf.h"

/* The eq. 6 estimation model of the machine at period dt_s. */
br_model_cfg_t br_machine_model_cfg(float dt_s);

/* The machine file's causes (BR_MACHINE_CAUSES: what a diagnosis found, the
 * actuator delay among them), which the image's estimators carry; the
 * configurations below clear them (the thesis model). */
br_causes_t br_machine_causes(void);

/* The PF of thesis section 5 at period dt_s with the machine file's settings
 * (particles, hand-tuned noise variances, gates): the start of the
 * Nelder-Mead tuning. */
br_pf_cfg_t br_circle_pf_cfg_default(float dt_s);

/* The UKF of thesis section 5 at period dt_s with the machine file's settings
 * (hand-tuned; the tuning's start). */
br_ukf_cfg_t br_circle_ukf_cfg_default(float dt_s);

/* The same with the variances found by Nelder-Mead (firmware/gen/bristle_gen/est/, make tune):
 * what the demo runs. */
br_pf_cfg_t br_circle_pf_cfg_tuned(float dt_s);
br_ukf_cfg_t br_circle_ukf_cfg_tuned(float dt_s);

/* Width of the feedforward's smoothed sign on the circle (docs/modules/ff.md:
 * chosen by measurement on the nominal plant). */
#define BR_CIRCLE_FF_VEPS_MPS 4.0e-5

/* The static friction feedforward from the machine's nominal model (eq. 5 and
 * the viscous coefficient; no causes, no inertia term), clamped to the
 * machine's torque limit / L. */
br_ff_cfg_t br_circle_ff_cfg_machine(void);

/* The reversal compensation at period dt_s from the machine file's
 * reversal_comp (A0, A1, tau; docs/modules/qec.md), the pulse alone (no
 * feedforward under it), clamped like the feedforward; a machine without the
 * section: amplitude 0 (no pulse). */
br_qec_cfg_t br_circle_qec_cfg_machine(float dt_s);

#endif
