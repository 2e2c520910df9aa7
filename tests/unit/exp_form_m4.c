/* SPDX-License-Identifier: Apache-2.0 */
/* br_math.h's exponentials in the Cortex-M4's form (no float SIMD, FPv4:
 * the branches), compiled on the host for test_exp_forms */
#define BR_FLOAT_SIMD 0
#define BR_FPU_MAXNM 0
#include "exp_forms.h"
#include "br_math.h"

float exp_w16_m4(float x) { return br_exp_neg_w16_k(x, br_exp_k()); }
float exp_neg_m4(float x) { return br_exp_neg_k(x, br_exp_k()); }
