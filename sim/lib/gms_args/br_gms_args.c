/* SPDX-License-Identifier: Apache-2.0 */
/* The Maxwell-slip plant's options (br_gms_args.h). */
#include "br_gms_args.h"

#include <string.h>

#include "cause_args/br_cause_args.h"
#include "circle/br_circle.h"
#include "tool/br_args.h"
#include "tool/br_tool_limits.h"

/* --gms D1,..,DN: N in 1..BR_GMS_MAX breakaway displacements, each in (0, BR_TOOL_GMS_D_MAX_M] */
static int parse_d(const char *tool, const char *val, br_gms_args_t *g)
{
    double d[BR_GMS_MAX + 1];
    const int n = br_parse_numbers(val, d, BR_GMS_MAX + 1);
    if (n < 1 || n > BR_GMS_MAX) {
        fprintf(stderr, "%s: bad value for --gms: %s (1 to %d breakaway displacements in m, comma-separated)\n",
                tool, val, BR_GMS_MAX);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        if (!(d[i] > 0.0 && d[i] <= BR_TOOL_GMS_D_MAX_M)) {
            fprintf(stderr, "%s: bad value for --gms: %s (each breakaway displacement must be in (0, %g] m)\n",
                    tool, val, BR_TOOL_GMS_D_MAX_M);
            return -1;
        }
    }
    for (int i = 0; i < n; i++) g->d_m[i] = d[i];
    g->n = n;
    return 0;
}

int br_gms_arg(const char *tool, const char *opt, const char *val, br_gms_args_t *g)
{
    if (strcmp(opt, "--gms") == 0) return parse_d(tool, val, g);
    if (strcmp(opt, "--gms-zeta") == 0)
        return br_arg_double(tool, opt, val, BR_TOOL_GMS_ZETA_MIN, BR_TOOL_GMS_ZETA_MAX, &g->zeta);
    fprintf(stderr, "%s: %s: not a Maxwell-slip option\n", tool, opt);
    return -1;
}

int br_gms_args_check(const char *tool, const br_gms_args_t *g)
{
    if (g->zeta > 0.0 && g->n == 0) {
        fprintf(stderr, "%s: --gms-zeta applies with --gms only (the damping of its elements)\n", tool);
        return -1;
    }
    return 0;
}

void br_gms_args_apply(const br_gms_args_t *g, br_plant_cfg_t *plant)
{
    if (g->n == 0) return;
    double share[BR_GMS_MAX];
    for (int i = 0; i < g->n; i++) share[i] = 1.0 / g->n;
    br_gms_from_breakaway(&plant->gms, g->n, g->d_m, share, plant->Fs_N, BR_CIRCLE_HW_SIGMA1_NSPM);
    plant->gms.clamp = 0;
    plant->gms.C_mps = BR_CIRCLE_HW_C_MPS;
    plant->gms.delta = 1.0;
    if (g->zeta > 0.0) br_gms_damping_ratio(&plant->gms, g->zeta, br_plant_meff_kg(plant));
}

void br_gms_usage(FILE *to)
{
    fprintf(to,
            "  --gms D1,..,DN      the plant's friction Maxwell-slip: N <= %d equal elements breaking away at\n"
            "                      D1..DN m at Fs (the slip law and damping of the demo's hardware-like plant)\n"
            "  --gms-zeta Z        with --gms: each element's damping for a damping ratio Z of its mode on the\n"
            "                      moving mass (sigma1_i = 2 Z sqrt(k_i M)) instead of the demo's %g N s/m\n"
            "bounds: --gms D in (0, %g] m, --gms-zeta %g .. %g (docs/tools.md)\n",
            BR_GMS_MAX, BR_CIRCLE_HW_SIGMA1_NSPM, BR_TOOL_GMS_D_MAX_M, BR_TOOL_GMS_ZETA_MIN, BR_TOOL_GMS_ZETA_MAX);
}
