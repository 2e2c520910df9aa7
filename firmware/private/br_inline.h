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
#endif

/* BR_FLOAT_SIMD: the target has vector registers for float (x86-64 SSE2,
 * Arm NEON). There the particle filter's loops are written branch-free, so
 * that the compiler vectorises them; without (the Cortex-M7) a branch costs
 * fewer instructions than the flags and selects a branch-free body needs.
 * The results are the same either way. */
#if defined(__SSE2__) || defined(__ARM_NEON)
#define BR_FLOAT_SIMD 1
#else
#define BR_FLOAT_SIMD 0
#endif

/* BR_RESTRICT: C99 restrict, for the particle filter's structure-of-arrays
 * loops (its arrays never overlap), so that the compiler vectorises them */
#define BR_RESTRICT restrict

#endif
