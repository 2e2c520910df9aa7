/* Deterministic float32 helpers. See br_math.h. */
#include "bristle/br_math.h"

#include <stdint.h>
#include <string.h>

float br_exp_neg(float x)
{
    if (!(x > -87.0f)) {
        return 0.0f; /* below the normal range, or NaN */
    }
    if (x > 0.0f) {
        x = 0.0f;
    }
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
