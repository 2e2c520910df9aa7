/* Float32 helpers whose results are bit-identical on every IEEE-754 target
 * (only +, -, *, comparisons and integer bit operations; the firmware builds
 * with -ffp-contract=off so no fused multiply-add changes the rounding). The
 * particle filter's weights go through br_exp_neg so that host and target pick
 * identical resampling indices. */
#ifndef BR_MATH_H
#define BR_MATH_H

/* e^x for x <= 0: 2^n * p(f), n = round(x log2 e), |f| <= 1/2, p the degree-6
 * Taylor polynomial of e^(f ln 2); relative error < 5e-6 over [-87, 0], set by
 * the rounding of x log2 e (measured in tests/unit/test_math.c); 0 below x = -87
 * (and for NaN). */
float br_exp_neg(float x);

#endif
