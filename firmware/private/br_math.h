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


/* The constants br_exp_neg makes: 0.5, 1 and the branching forms' range
 * test's two words. br_exp_neg_k takes them as values, so that a loop over
 * particles can take them once before it (br_exp_k) and keep them in
 * registers; br_exp_neg(x) is br_exp_neg_k(x, br_exp_k()). */
typedef struct {
    float half, one;   /* 0.5f, 1.0f */
    uint32_t lo, span; /* -87 < x < 0 <=> xb - lo < span for x's bit pattern xb (below) */
} br_exp_k_t;

static inline br_exp_k_t br_exp_k(void)
{
    const br_exp_k_t k = {0.5f, 1.0f, 0x80000001u, 0xC2AE0000u - 0x80000001u};
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
 * (0 <= s <= 16): the exponent field built as an integer */
static inline float br_exp2_parts(int32_t n, float f, const br_exp_k_t *k, int32_t ebias)
{
    /* 2^(n + s) by building the exponent field */
    const uint32_t bits = (uint32_t)(n + ebias) << 23;
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return br_exp2_poly(f, k) * scale;
}

/* Three forms of e^x 2^s for x <= 0 (s = ebias - 127; top = 2^s, the value
 * for x >= 0), the same float for every one of the 2^32 inputs
 * (docs/modules/pf.md, "The exponential"; test_exp_forms):
 *   br_exp_neg_kb         the reference: branches, plain C
 *   br_exp_neg_kb_mask    branch-free, the range tests as integer masks (a
 *                         loop over particles vectorises; br_pf_kernel_simd.c)
 *   br_exp_neg_kb_rinta   x log2 e rounded by roundf, 2^(n + s) by a
 *                         fixed-point conversion: one instruction each on an
 *                         FPv5 FPU (br_pf_kernel_m7.c) */

/* The reference. The range -87 < x < 0 as a test on the bit pattern
 * (negative floats from -0 0x80000000 up to -87 0xC2AE0000, exclusive: one
 * unsigned compare, xb - 0x80000001 < 0xC2AE0000 - 0x80000001); outside it:
 * e^x = 1 for x >= 0 (+0 .. +inf, and -0), as the polynomial gives at 0; 0
 * for x <= -87 and NaN. (No fminf: on the Cortex-M4 a library call.) */
static inline float br_exp_neg_kb(float x, br_exp_k_t k, int32_t ebias, float top)
{
    uint32_t xb;
    memcpy(&xb, &x, sizeof xb);
    if (!(xb - k.lo < k.span)) {
        return (xb <= 0x7F800000u || xb == 0x80000000u) ? top : 0.0f;
    }
    /* x log2(e) = n + f, n = round-half-down, f in [-1/2, 1/2] */
    const float t = x * 1.44269504f;
    int32_t n = (int32_t)(t - k.half); /* truncation toward zero of t - 1/2, t <= 0 */
    float f = t - (float)n;
    if (f > k.half) {
        n += 1;
        f -= k.one;
    }
    return br_exp2_parts(n, f, &k, ebias);
}

/* Branch-free: x clamped to (-87, 0] by integer masks (no select the
 * compiler could turn back into a branch: GCC 12 does for SSE4.1 and up) */
static inline float br_exp_neg_kb_mask(float x, br_exp_k_t k, int32_t ebias)
{
    const int in_range = x > -87.0f;
    /* xc = x where -87 < x < 0, else +0 (e^0 2^s comes out of the polynomial) */
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

/* roundf (vrinta on FPv5: ties away from zero, which for t < 0 is
 * round-half-down) gives the reference's (n, f) for every t = x log2(e)
 * that occurs, f = t - n exact; the exponent field (n + ebias) << 23 is the
 * conversion of r + ebias to fixed point with 23 fraction bits (vcvt #23 on
 * FPv5; every step exact: 1 <= n + ebias <= 143). */
static inline float br_exp_neg_kb_rinta(float x, br_exp_k_t k, int32_t ebias, float top)
{
    uint32_t xb;
    memcpy(&xb, &x, sizeof xb);
    if (!(xb - k.lo < k.span)) {
        return (xb <= 0x7F800000u || xb == 0x80000000u) ? top : 0.0f;
    }
    const float t = x * 1.44269504f;
    const float r = roundf(t);
    const float f = t - r;
#if defined(__GNUC__) && defined(__arm__) && defined(__ARM_FP)
    float scale = r + (float)ebias;
    __asm__("vcvt.s32.f32 %0, %0, #23" : "+t"(scale));
#else
    const int32_t bits = (int32_t)((r + (float)ebias) * 8388608.0f);
    float scale;
    memcpy(&scale, &bits, sizeof scale);
#endif
    return br_exp2_poly(f, &k) * scale;
}

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
