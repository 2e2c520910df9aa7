/* SPDX-License-Identifier: Apache-2.0 */
/* br_exp_neg_w16_k and br_exp_neg_k in the forms br_math.h selects for the
 * Cortex-M7 (exp_form_m7.c) and the Cortex-M4 (exp_form_m4.c) */
#ifndef EXP_FORMS_H
#define EXP_FORMS_H

float exp_w16_m7(float x);
float exp_neg_m7(float x);
float exp_w16_m4(float x);
float exp_neg_m4(float x);

#endif
