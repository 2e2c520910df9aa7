/* SPDX-License-Identifier: Apache-2.0 */
/* The Maxwell-slip plant's options of the tools that simulate an axis
 * (br_simlog, br_robust_run, br_track; docs/tools.md, docs/simlog.md):
 *
 *   --gms D1,..,DN   the plant's friction Maxwell-slip (docs/modules/plant.md):
 *                    N <= BR_GMS_MAX equal elements breaking away at D1..DN m
 *                    at Fs, each in (0, BR_TOOL_GMS_D_MAX_M], with the slip law
 *                    and element damping of the demo's hardware-like plant
 *   --gms-zeta Z     with --gms: each element's damping for a damping ratio Z
 *                    of its mode on the moving mass, sigma1_i = 2 Z sqrt(k_i Meff)
 *
 * and, after the options, one check of the pair (--gms-zeta needs --gms).
 * Without them the plant keeps its LuGre friction. */
#ifndef BR_GMS_ARGS_H
#define BR_GMS_ARGS_H

#include <stdio.h>

#include "plant/br_gms.h"
#include "plant/br_sim_plant.h"

typedef struct {
    int n;                   /* --gms: elements, 0 = the plant's LuGre */
    double d_m[BR_GMS_MAX];  /* their breakaway displacements at Fs */
    double zeta;             /* --gms-zeta: the element modes' damping ratio, 0 = the demo's damping */
} br_gms_args_t;

#define BR_GMS_ARGS_DEFAULT {0, {0.0}, 0.0}

/* getopt_long entries (sim/lib/tool/br_args.h), both with the value
 * BR_GMS_OPT: put BR_GMS_LONGOPTS in a tool's table and hand BR_GMS_OPT's
 * option name and value to br_gms_arg. */
#define BR_GMS_OPT 0x300
#define BR_GMS_LONGOPTS {"gms", 1 /* required_argument */, NULL, BR_GMS_OPT}, {"gms-zeta", 1, NULL, BR_GMS_OPT},

/* opt (as written, "--gms") with its value into g: 0, or -1 with a message
 * on stderr (g unchanged). */
int br_gms_arg(const char *tool, const char *opt, const char *val, br_gms_args_t *g);

/* After the options: 0, or -1 with a message on stderr (--gms-zeta without --gms). */
int br_gms_args_check(const char *tool, const br_gms_args_t *g);

/* The elements on plant (after its model and causes: they read its Fs and
 * moving mass): equal shares, k_i = Fs / (N d_i), the hardware-like plant's
 * finite-C slip law and damping, or the damping of --gms-zeta. Nothing when
 * g->n == 0. */
void br_gms_args_apply(const br_gms_args_t *g, br_plant_cfg_t *plant);

/* the options' lines of a tool's usage text, and their bounds line */
void br_gms_usage(FILE *to);

#endif
