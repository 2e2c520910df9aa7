/* SPDX-License-Identifier: Apache-2.0 */
/* BR_INLINE: a function the compiler must inline (private to the firmware):
 * br_model's RK4 kernel (br_model_kernel.h), inside br_model_step. */
#ifndef BR_INLINE_H
#define BR_INLINE_H

#if defined(__GNUC__)
#define BR_INLINE static inline __attribute__((always_inline))
#else
#define BR_INLINE static inline
#endif

/* BR_NO_IVOPTS: a function whose loops GCC compiles without its induction
 * variable optimisation (elsewhere nothing): the PF's in-place copy passes
 * (br_pf_kernel_ref.c), with it every access addressed by the loop's own
 * index as a register offset; without it 2.0 instructions more per
 * particle-step on the Cortex-M7 and -M4 (make target-bench, docs/target.md,
 * "What the kernels keep"). Two loops of integer loads and stores; the
 * replays' bit-identity (target_qemu_replay, _m4) checks what they compile to. */
#if defined(__GNUC__) && !defined(__clang__)
#define BR_NO_IVOPTS __attribute__((optimize("no-ivopts")))
#else
#define BR_NO_IVOPTS
#endif

/* BR_HOLD_F(v), BR_HOLD_U(v): the float or uint32_t variable v keeps its
 * value, but the compiler no longer knows it (GCC on 32-bit Arm with an FPU:
 * an empty asm that takes v and gives it back in a register; elsewhere
 * nothing). Before a loop, for its constants: GCC 12 for the Cortex-M7 and
 * -M4 makes a constant it can encode (0.5f, 1.0f) or load from the literal
 * pool afresh in every iteration, even with registers free; an unknown value
 * it keeps in a register. The exponential's constants in the M7 and M4
 * kernels' weight loops: without it 2.0 and 5.0 instructions more per
 * particle-step (docs/target.md, "What the kernels keep"). */
#if defined(__GNUC__) && defined(__arm__) && defined(__ARM_FP)
#define BR_HOLD_F(v) __asm__("" : "+t"(v))
#define BR_HOLD_U(v) __asm__("" : "+r"(v))
#else
#define BR_HOLD_F(v) ((void)0)
#define BR_HOLD_U(v) ((void)0)
#endif

/* br_load4_f(&p, n): n[0..3] = p[0..3] and p += 4. br_store_f_inc(&p, v):
 * *p = v and p += 1. On 32-bit Arm with an FPU one vldmia into four
 * consecutive float registers (s12-s15; the compiler moves them on where it
 * needs those registers) where GCC makes four loads and an add, and one
 * vstmia with the pointer written back where GCC makes a store and an add
 * (the prediction loops of the PF's Cortex-M7 and -M4 kernels: the noise
 * samples, and f_nl and l, the two arrays the loop stores but does not load;
 * without them 6.0 and 2.0 instructions more per particle-step on the M7,
 * docs/target.md, "What the kernels keep"); elsewhere the plain loads and
 * stores. The same values. */
#if defined(__GNUC__) && defined(__arm__) && defined(__ARM_FP)
typedef struct {
    float v[4];
} br_f4_t; /* the four floats the vldmia reads, for its memory operand */
static inline void br_load4_f(const float **p, float n[4])
{
    register float n0 __asm__("s12");
    register float n1 __asm__("s13");
    register float n2 __asm__("s14");
    register float n3 __asm__("s15");
    __asm__("vldmia %4!, {s12-s15}" : "=t"(n0), "=t"(n1), "=t"(n2), "=t"(n3), "+r"(*p) : "m"(*(const br_f4_t *)*p));
    n[0] = n0;
    n[1] = n1;
    n[2] = n2;
    n[3] = n3;
}
static inline void br_store_f_inc(float **p, float v)
{
    __asm__("vstmia %0!, {%2}" : "+r"(*p), "=m"(**p) : "t"(v));
}
#else
static inline void br_store_f_inc(float **p, float v)
{
    **p = v;
    *p += 1;
}
static inline void br_load4_f(const float **p, float n[4])
{
    const float *const q = *p;
    n[0] = q[0];
    n[1] = q[1];
    n[2] = q[2];
    n[3] = q[3];
    *p = q + 4;
}
#endif

/* BR_RESTRICT: C99 restrict, for the particle filter's structure-of-arrays
 * loops (its arrays never overlap), so that the compiler vectorises them */
#define BR_RESTRICT restrict

#endif
