/* SPDX-License-Identifier: Apache-2.0 */
/* The particle filter's kernel on targets without one of their own (the
 * Cortex-M4, hosts without float SIMD; firmware/CMakeLists.txt): the
 * reference kernel itself (br_pf_kernel_ref.c). */
#include "br_pf_kernel.h"

uint32_t br_pf_kernel_predict(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                              br_pf_lsum_t *ls)
{
    return br_pf_kref_predict(pf, c, j0, j1, nz, ls);
}

float br_pf_kernel_resample(br_pf_t *pf, float lmax, int outlier) { return br_pf_kref_resample(pf, lmax, outlier); }

uint32_t br_pf_kernel_predict_ms(br_pf_t *pf, const br_pf_kc_t *c, uint32_t j0, uint32_t j1, const float *nz,
                                 br_pf_lsum_t *ls)
{
    return br_pf_kref_predict_ms(pf, c, j0, j1, nz, ls);
}
