/* SPDX-License-Identifier: Apache-2.0 */
/* br_math.h's exponentials in the Cortex-M7's form (no float SIMD, FPv5:
 * vrinta and the fixed-point conversion), compiled on the host for
 * test_exp_forms */
#define BR_FLOAT_SIMD 0
#define BR_FPU_MAXNM 1
#include "exp_forms.h"
#include "br_math.h"

float exp_w16_m7(float x) { return br_exp_neg_w16_k(x, br_exp_k()); }
float exp_neg_m7(float x) { return br_exp_neg_k(x, br_exp_k()); }
