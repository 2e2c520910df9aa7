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

/* e^x for x <= 0: 2^n * p(f), n = round(x log2 e), |f| <= 1/2, p the degree-6
 * Taylor polynomial of e^(f ln 2); relative error < 5e-6 over [-87, 0], set by
 * the rounding of x log2 e (measured in tests/unit/test_math.c); 0 below x = -87
 * (and for NaN). */
static inline float br_exp_neg(float x)
{
    if (!(x > -87.0f)) {
        return 0.0f; /* below the normal range, or NaN */
    }
    x = fminf(x, 0.0f); /* x > 0 is taken as 0 */
    /* x log2(e) = n + f, n = round-half-down, f in [-1/2, 1/2] */
    const float t = x * 1.44269504f;
    int32_t n = (int32_t)(t - 0.5f); /* truncation toward zero of t - 1/2, t <= 0 */
    float f = t - (float)n;
    if (f > 0.5f) {
        n += 1;
        f -= 1.0f;
    }
    /* e^y, y = f ln 2 in [-0.347, 0.347]: Taylor to degree 6 (Horner) */
    const float y = f * 0.693147181f;
    float p = 1.0f / 720.0f;
    p = p * y + 1.0f / 120.0f;
    p = p * y + 1.0f / 24.0f;
    p = p * y + 1.0f / 6.0f;
    p = p * y + 0.5f;
    p = p * y + 1.0f;
    p = p * y + 1.0f;
    /* 2^n by building the exponent field; n >= -126 here since x > -87 */
    const uint32_t bits = (uint32_t)(n + 127) << 23;
    float scale;
    memcpy(&scale, &bits, sizeof scale);
    return p * scale;
}

#endif
