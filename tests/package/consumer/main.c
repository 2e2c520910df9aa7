/* SPDX-License-Identifier: Apache-2.0 */
/* A consumer of bristle's public API (tests/package): the reference
 * machine's friction from its generated header through br_lugre, a period's
 * reference (br_ref.h) from br_refgen, the application's header on its own,
 * and the version macros. Exits 0 when the installed headers and library
 * agree with what the test expects. */
#include <stdio.h>
#include <string.h>

#include "bristle/br_app.h"
#include "bristle/br_lugre.h"
#include "bristle/br_refgen.h"
#include "bristle/br_version.h"
#include "bristle_gen/machine/br_machine.h"

/* the consumer's CMakeLists adds -ffast-math; bristle::firmware's usage
 * requirements must turn it off again for the code that calls the library */
#ifdef __FAST_MATH__
#error "bristle::firmware's usage requirements (-fno-fast-math) did not reach this file"
#endif

int main(void)
{
    static const br_lugre_cfg_t cfg = {.sigma0_Npm = BR_MACHINE_SIGMA0_NPM_F,
                                       .sigma1_Nspm = BR_MACHINE_SIGMA1_NSPM_F,
                                       .Fc_N = BR_MACHINE_FC_N_F,
                                       .Fs_N = BR_MACHINE_FS_N_F,
                                       .vs_mps = BR_MACHINE_VS_MPS_F};
    br_lugre_t s;
    if (br_lugre_init(&s, &cfg) != BR_OK) return 1;
    /* sliding at 10 mm/s for 0.1 s, far above the Stribeck velocity: the
     * friction settles at the Coulomb level plus the bristle damping's share */
    float F_N = 0.0f;
    for (int k = 0; k < 100; k++)
        if (br_lugre_step(&s, 0.01f, 1e-3f, &F_N) != BR_OK) return 1;
    if (!(F_N > 0.99f * cfg.Fc_N && F_N < 1.01f * cfg.Fc_N)) {
        printf("friction %g N, expected about Fc = %g N\n", (double)F_N, (double)cfg.Fc_N);
        return 1;
    }
    /* the first reference of a 1 mm sine at phase pi/2: its peak, A / (L r) counts */
    const br_refgen_cfg_t rc = {1e-3f, 1.0f, 1.57079637f, BR_MACHINE_CTRL_PERIOD_S_F, BR_MACHINE_LEAD_MPRAD_F,
                                BR_MACHINE_RAD_PER_COUNT_F};
    br_refgen_t g;
    br_ref_t r;
    if (br_refgen_init(&g, &rc) != BR_OK || br_refgen_step(&g, &r) != BR_OK) return 1;
    const float peak = 1e-3f / (BR_MACHINE_LEAD_MPRAD_F * BR_MACHINE_RAD_PER_COUNT_F);
    if (!((float)r.ref_counts > 0.999f * peak && (float)r.ref_counts < 1.001f * peak)) {
        printf("reference %ld counts, expected about %g\n", (long)r.ref_counts, (double)peak);
        return 1;
    }
    /* the application's guards for the machine's period and top speed: at
     * least one count a period (br_app.h on its own, br_app.c linked) */
    const br_app_guard_cfg_t gc = br_app_guard_cfg(BR_MACHINE_CTRL_PERIOD_S_F, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F);
    if (gc.enc_max_delta_counts < 1u) {
        printf("guards: %lu counts a period\n", (unsigned long)gc.enc_max_delta_counts);
        return 1;
    }
    char v[32];
    snprintf(v, sizeof v, "%d.%d.%d", BR_VERSION_MAJOR, BR_VERSION_MINOR, BR_VERSION_PATCH);
    if (strcmp(v, BR_VERSION_STRING) != 0 || strcmp(BR_VERSION_STRING, BR_EXPECT_VERSION) != 0) {
        printf("version %s (macros %s), expected %s\n", BR_VERSION_STRING, v, BR_EXPECT_VERSION);
        return 1;
    }
    printf("bristle %s: sliding friction %.4f N\n", BR_VERSION_STRING, (double)F_N);
    return 0;
}
