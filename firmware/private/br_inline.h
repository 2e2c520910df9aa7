/* SPDX-License-Identifier: Apache-2.0 */
/* BR_INLINE: a function the compiler must inline (private to the firmware).
 * For a hot loop written once and specialised at its call sites by constant
 * arguments (the PF's prediction for the thesis model and for the extended
 * one), so that the common case carries no per-particle test of the other. */
#ifndef BR_INLINE_H
#define BR_INLINE_H

#if defined(__GNUC__)
#define BR_INLINE static inline __attribute__((always_inline))
#else
#define BR_INLINE static inline
/* BR_RESTRICT: C99 restrict, for the particle filter's structure-of-arrays
 * loops (its arrays never overlap), so that the compiler vectorises them */
#define BR_RESTRICT restrict

#endif

/* BR_RESTRICT: C99 restrict, for the particle filter's structure-of-arrays
 * loops (its arrays never overlap), so that the compiler vectorises them */
#define BR_RESTRICT restrict

#endif
