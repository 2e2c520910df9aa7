/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's shared external force (cfg.load; private to the
 * firmware; docs/modules/pf.md, "External force"). br_pf.c calls these; off
 * (cfg.load all 0) each leaves the filter's arithmetic untouched. */
#ifndef BR_PF_LOAD_H
#define BR_PF_LOAD_H

#include <stdint.h>

#include "bristle/br_pf.h"

/* The compensation's notch at the PF's Nyquist frequency: its pole, -r
 * (docs/modules/pf.md, "The period-2 mode": the loop's map stays inside the
 * unit circle for actuator delays up to 3.5 ms and q up to 3e5 N^2/s with
 * r <= 0.3) */
#define BR_PF_LOAD_NOTCH_R 0.2f

/* A glitch's hypotheses (spike, slip) are tested at twice the gate's distance:
 * their log-weight >= this times the gate's (docs/modules/pf.md, "A glitch is
 * not a load": the glitch period's compensation moves the real axis as the
 * model knows the plant, on the hardware-like plant 1.44 gates off) */
#define BR_PF_LOAD_UNDO_GATE2 4.0f

/* 1 when cfg.load is on */
static inline int br_pf_load_on(const br_pf_t *pf) { return pf->cfg.load.max_N > 0.0f; }

/* Checks cfg.load against the rest of the configuration and sets the load's
 * state and constants (pf->model and pf->r_gate set). BR_E_PARAM for a bad
 * configuration. */
br_status_t br_pf_load_init(br_pf_t *pf);

/* The torque the particles are predicted with: u - L F_d (u itself when off) */
float br_pf_load_torque(const br_pf_t *pf, float u_Nm);

/* One period passes: F_d's variance grows by its random walk, F_d's value at
 * the period's start kept for the compensation (nothing when off) */
void br_pf_load_tick(br_pf_t *pf);

/* After a measured step's prediction and weighing (at least one valid
 * particle, lmax their largest log-weight, sums[] = the sums of d_j = theta_j
 * - y_rel and d_j^2): F_d's Kalman update on the cloud's mean innovation
 * (re-acquisition when gated), the cloud moved by what the change explains,
 * its f_nl, log-weights and sums made again. Returns the new largest
 * log-weight (lmax itself when nothing moved). */
float br_pf_load_update(br_pf_t *pf, float y_rel, float lmax, float sums[2], uint32_t n_valid);

/* The compensation, once a period: F (the mean f_nl) + F_d through the
 * notch at the PF's Nyquist frequency (its state advanced), kept within
 * +-max_N (F itself when off) */
float br_pf_load_comp_N(br_pf_t *pf, float F_N);

#endif
