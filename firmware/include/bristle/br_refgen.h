/* SPDX-License-Identifier: Apache-2.0 */
/* Sinusoidal reference for one axis of a circle test, float32.
 *
 * Load-side position and its motor-side images, at phase phi_k:
 *   x_k       = A sin(phi_k)                      (m)
 *   theta_k   = x_k / L                           (rad, motor)
 *   counts_k  = theta_k / r = (A / (L r)) sin(phi_k)
 *   omega_k   = (A / L) (2 pi / T) cos(phi_k)     (rad/s, motor)
 *   phi_k     = phi_0 + 2 pi k dt / T   (mod 2 pi)
 * with A = amplitude_m, T = period_s, L = lead_mprad, r = rad_per_count.
 * counts_k is split into ref_counts = floor(counts_k) and
 * ref_frac_counts = counts_k - ref_counts in [0, 1).
 *
 * The phase is kept as a 64-bit fixed-point fraction of a turn (Q0.64, one
 * turn = 2^64), so wrapping to [0, 2 pi) is the integer overflow itself and
 * the phase never loses precision however long the generator runs; the
 * increment dt/T is formed to ~2^-47 relative accuracy from the two floats.
 * The angle passed to sinf/cosf is the phase rounded to 2^-24 turn.
 * A circle uses two generators with phases differing by pi/2.
 * See docs/modules/refgen.md. */
#ifndef BR_REFGEN_H
#define BR_REFGEN_H

#include <stdint.h>
#include "bristle/br_ref.h"
#include "bristle/br_status.h"

/* Largest amplitude in counts (keeps ref_counts well inside int32). */
#define BR_REFGEN_AMP_COUNTS_MAX 1073741824.0f  /* 2^30 */
/* Longest period in steps: T / dt <= 2^32. */
#define BR_REFGEN_STEPS_PER_PERIOD_MAX 4294967296.0f

typedef struct {
    float amplitude_m;    /* load-side amplitude A, > 0 */
    float period_s;       /* period T, >= 2 dt_s (Nyquist) and <= 2^32 dt_s */
    float phase_rad;      /* phase at step 0, any finite value (reduced mod 2 pi) */
    float dt_s;           /* step, > 0 */
    float lead_mprad;     /* screw lead L = lead / (2 pi), > 0 */
    float rad_per_count;  /* encoder resolution on the motor r, > 0 */
} br_refgen_cfg_t;

typedef struct {
    br_refgen_cfg_t cfg;
    uint64_t phase_q64;   /* phase in turns, Q0.64 */
    uint64_t dphase_q64;  /* increment per step, Q0.64 */
    float amp_counts;     /* A / (L r) */
    float amp_radps;      /* (A / L) 2 pi / T */
    int ready;
} br_refgen_t;

br_status_t br_refgen_init(br_refgen_t *g, const br_refgen_cfg_t *cfg);

/* Writes the reference at the current phase (step k: phi_0 + 2 pi k dt / T),
 * then advances the phase by one step. */
br_status_t br_refgen_step(br_refgen_t *g, br_ref_t *ref);

/* Current phase (of the next step) in [0, 2 pi); 0 for an uninitialised g. */
float br_refgen_phase_rad(const br_refgen_t *g);

#endif
