/* SPDX-License-Identifier: Apache-2.0 */
/* Float32 helpers whose results are bit-identical on every IEEE-754 target
 * (only +, -, *, comparisons and integer bit operations; the firmware builds
 * with -ffp-contract=off so no fused multiply-add changes the rounding). The
 * particle filter's weights go through br_exp_neg so that host and target pick
 * identical resampling indices. Inline: it runs once per particle per step. */
#ifndef BR_MATH_H
#define BR_MATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "br_inline.h"

/* The constants br_exp_neg makes: 0.5, 1 and (without float SIMD) the
 * range test's two words. br_exp_neg_k takes them as values, so that a loop
 * over particles can take them once before it (br_exp_k) and keep them in
 * registers (BR_HOLD_F, BR_HOLD_U: the Cortex-M7's loop made them afresh
 * for every particle, 5 instructions); br_exp_neg(x) is
 * br_exp_neg_k(x, br_exp_k()). */
typedef struct {
    float half, one;   /* 0.5f, 1.0f */
    uint32_t lo, span; /* -87 < x < 0 <=> xb - lo < span for x's bit pattern xb (below) */
} br_exp_k_t;

static inline br_exp_k_t br_exp_k(void)
{
    br_exp_k_t k = {0.5f, 1.0f, 0x80000001u, 0xC2AE0000u - 0x80000001u};
#if !BR_FLOAT_SIMD
    BR_HOLD_F(k.half);
    BR_HOLD_F(k.one);
    BR_HOLD_U(k.lo);
    BR_HOLD_U(k.span);
#endif
    return k;
}

/* e^(f ln 2) for |f| <= 1/2 */
static inline float br_exp2_poly(float f, const br_exp_k_t *k)
{
    /* e^y, y = f ln 2 in [-0.347, 0.347]: Taylor to degree 6 (Horner) */
    const float y = f * 0.693147181f;
    float p = 1.0f / 720.0f;
    p = p * y + 1.0f / 120.0f;
    p = p * y + 1.0f / 24.0f;
    p = p * y + 1.0f / 6.0f;
    p = p * y + k->half;
    p = p * y + k->one;
    p = p * y + k->one;
    return p;
}

/* 2^(n + s) e^(f ln 2) for n >= -126, |f| <= 1/2, with ebias = 127 + s
 * (0 <= s <= 16): both forms of br_exp_neg end here (s = 0; s = 16 for
 * br_exp_neg_w), but the Cortex-M7's (BR_FPU_MAXNM), which makes the
 * same 2^(n + s) in the FPU */
static inline float br_exp2_parts(int32_t n, float f, const br_exp_k_t *k, int32_t ebias)
{
    /* 2^(n + s) by building the exponent field */
    const uint32_t bits = (uint32_t)(n + ebias) << 23;
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return br_exp2_poly(f, k) * scale;
}

#if BR_FLOAT_SIMD
/* with float SIMD: branch-free, so that a loop over particles vectorises; the
 * range tests are integer masks rather than selects, which the compiler could
 * turn back into branches (GCC 12 does for SSE4.1 and up). The same result
 * as the branchy form below for every one of the 2^32 inputs (checked
 * exhaustively once, docs/modules/pf.md). */
static inline float br_exp_neg_kb(float x, br_exp_k_t k, int32_t ebias, float top)
{
    (void)top; /* e^0 2^s comes out of the polynomial */
    const int in_range = x > -87.0f;
    /* x clamped to (-87, 0] by integer masks (no select the compiler could
     * turn into a branch): xc = x where -87 < x < 0, else +0 */
    uint32_t xb;
    memcpy(&xb, &x, sizeof xb);
    const uint32_t keep = (uint32_t)0u - (uint32_t)(in_range & (x < 0.0f));
    const uint32_t xcb = xb & keep;
    float xc;
    memcpy(&xc, &xcb, sizeof xc);
    /* x log2(e) = n + f, n = round-half-down, f in [-1/2, 1/2] */
    const float t = xc * 1.44269504f;
    const int32_t n0 = (int32_t)(t - k.half); /* truncation toward zero of t - 1/2, t <= 0 */
    const float f0 = t - (float)n0;
    const int up = f0 > k.half;
    const int32_t n = n0 + up;
    const float f = f0 - (float)up; /* f0 - 0 = f0 exactly */
    const float r = br_exp2_parts(n, f, &k, ebias);
    /* 0 below the normal range and for NaN */
    uint32_t rb;
    memcpy(&rb, &r, sizeof rb);
    const uint32_t ob = rb & ((uint32_t)0u - (uint32_t)in_range);
    float o;
    memcpy(&o, &ob, sizeof o);
    return o;
}
#else
/* without (the Cortex-M7): the same operations with branches, fewer
 * instructions there; the same result for every x */
static inline float br_exp_neg_kb(float x, br_exp_k_t k, int32_t ebias, float top)
{
    /* the range -87 < x < 0 as a test on the bit pattern (negative
     * floats from -0 0x80000000 up to -87 0xC2AE0000, exclusive: one
     * unsigned compare, xb - 0x80000001 < 0xC2AE0000 - 0x80000001); outside
     * it: e^x = 1 for x >= 0 (+0 .. +inf, and -0), as the polynomial gives
     * at 0; 0 for x <= -87 and NaN. No fminf: on the Cortex-M4 a library
     * call with two __fpclassifyf. */
    uint32_t xb;
    memcpy(&xb, &x, sizeof xb);
    if (!(xb - k.lo < k.span)) {
        return (xb <= 0x7F800000u || xb == 0x80000000u) ? top : 0.0f;
    }
    /* x log2(e) = n + f, n = round-half-down, f in [-1/2, 1/2] */
    const float t = x * 1.44269504f;
#if BR_FPU_MAXNM
    /* FPv5's vrinta (roundf): t's nearest integer, ties away from zero,
     * which for t < 0 is round-half-down; f = t - n is exact. The (n, f)
     * of the branches below for every t = x log2(e) that occurs (one t < 0
     * that no float x gives, -0x1.fffffep-2, differs), so the same float
     * for all 2^32 x (docs/modules/pf.md) */
    const float r = roundf(t);
    const float f = t - r;
    /* 2^(n + s): the exponent field (n + ebias) << 23 as the conversion of
     * r + ebias to fixed point with 23 fraction bits (vcvt #23, in the FPU;
     * every step exact: 1 <= n + ebias <= 143) */
#if defined(__GNUC__) && defined(__arm__) && defined(__ARM_FP)
    /* as an asm on the register itself: GCC's own vcvt #23 (the C form
     * below) first copied its operand to another register */
    float scale = r + (float)ebias;
    __asm__("vcvt.s32.f32 %0, %0, #23" : "+t"(scale));
#else
    const int32_t bits = (int32_t)((r + (float)ebias) * 8388608.0f);
    float scale;
    memcpy(&scale, &bits, sizeof scale);
#endif
    return br_exp2_poly(f, &k) * scale;
#else
    int32_t n = (int32_t)(t - k.half); /* truncation toward zero of t - 1/2, t <= 0 */
    float f = t - (float)n;
    if (f > k.half) {
        n += 1;
        f -= k.one;
    }
    return br_exp2_parts(n, f, &k, ebias);
#endif
}
#endif

/* e^x for x <= 0 with the constants k (br_exp_k) */
static inline float br_exp_neg_k(float x, br_exp_k_t k) { return br_exp_neg_kb(x, k, 127, k.one); }

/* e^x 2^16 for x <= 0, the particle filter's quantisation scale built into
 * the exponent field (one multiplication fewer): (uint32_t) of it equals
 * (uint32_t)(br_exp_neg_k(x, k) * 65536.0f) for every x. Where 2^n e^y is
 * normal, both products by powers of two are exact; where it is subnormal
 * (n = -126) both are below 2^-109 and truncate to 0; x >= 0 gives 2^16
 * and x <= -87 or NaN 0 in both (checked over all 2^32 inputs, docs/modules/pf.md). */
static inline float br_exp_neg_w16_k(float x, br_exp_k_t k) { return br_exp_neg_kb(x, k, 127 + 16, 65536.0f); }

/* e^x for x <= 0: 2^n * p(f), n = round(x log2 e), |f| <= 1/2, p the degree-6
 * Taylor polynomial of e^(f ln 2); relative error < 5e-6 over [-87, 0], set by
 * the rounding of x log2 e (measured in tests/unit/test_math.c); 0 below x = -87
 * (and for NaN). */
static inline float br_exp_neg(float x) { return br_exp_neg_k(x, br_exp_k()); }

#endif
