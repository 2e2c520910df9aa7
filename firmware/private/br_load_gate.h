/* SPDX-License-Identifier: Apache-2.0 */
/* Glitch or load: the discrimination the PF's and the UKF's external-force
 * states share (private to the firmware; br_load_gate_t in bristle/br_est.h;
 * docs/modules/est.md, "Glitch or load"). */
#ifndef BR_LOAD_GATE_H
#define BR_LOAD_GATE_H

#include <stdint.h>

#include "bristle/br_est.h"

/* No candidate, no live load, nothing counted */
void br_load_gate_reset(br_load_gate_t *g);

/* One period passes (the live window shrinks) */
void br_load_gate_tick(br_load_gate_t *g);

/* A measurement whose innovation passed the gate, or a re-anchoring: no candidate */
static inline void br_load_gate_pass(br_load_gate_t *g) { g->pend_nu = 0.0f; }

/* A gated innovation nu (rad, measurement - prediction) k0 >= 1 periods
 * after the last measurement; g_radpN theta's response to one newton over
 * one period, max_N the load's bound. Returns the periods k >= k0 over which
 * a change dF = nu / (g k^2) of the load explains nu (k > k0: it began before
 * the held candidate, the last measurement), to re-acquire it; or 0: an
 * outlier, held as the candidate when a force within 2 max_N explains it. */
uint32_t br_load_gate_gated(br_load_gate_t *g, float nu, uint32_t k0, float g_radpN, float max_N);

#endif
