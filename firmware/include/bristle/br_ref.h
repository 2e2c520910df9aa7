/* SPDX-License-Identifier: Apache-2.0 */
/* The reference of one control period: what the controller tracks (eq. 7's
 * r), in the encoder's integer counts with a fraction, and the reference
 * velocity. The reference generator (br_refgen.h) writes it, the application
 * (br_app.h) reads it; neither needs the other. docs/modules/refgen.md. */
#ifndef BR_REF_H
#define BR_REF_H

#include <stdint.h>

typedef struct {
    int32_t ref_counts;      /* whole counts, wraps modulo 2^32 like the encoder */
    float ref_frac_counts;   /* the fraction of a count, in [0, 1) */
    float ref_omega_radps;   /* reference velocity, motor side */
} br_ref_t;

#endif
