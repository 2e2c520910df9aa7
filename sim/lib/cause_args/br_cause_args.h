/* SPDX-License-Identifier: Apache-2.0 */
/* The cause options of the simulator's command lines (br_simlog,
 * br_circle_ext): docs/simlog.md. Each sets the br_plant_cfg_t fields of its
 * rows in sim/lib/plant/br_model_params.h, its values in their order:
 *
 *   --offset F           offset_N: constant load force, N
 *   --asym DFC,DFV       dFc_neg_N, dsigma2_neg_Nspm: friction in -x, Coulomb (and stiction) + DFC N,
 *                        viscous + DFV N s/m
 *   --ripple A,P[,PH]    ripple_amp_N, ripple_period_m, ripple_phase_rad: A sin(2 pi x / P + PH), N, m, rad
 *   --gradient S         grad_per_m: friction times max(0, 1 + S x), 1/m
 *   --delay D            delay_s: actuator dead time, s
 *   --drift R            drift_per_s: friction level times max(0, 1 + R t), t since the start, 1/s */
#ifndef BR_CAUSE_ARGS_H
#define BR_CAUSE_ARGS_H

#include "plant/br_model_params.h"
#include "plant/br_sim_plant.h"

/* The cause options as getopt_long entries (sim/lib/tool/br_args.h), one per
 * row (an option of several rows appears as often; getopt_long takes the
 * first exact match), all with the value BR_CAUSE_OPT: put BR_CAUSE_LONGOPTS
 * in a tool's table and hand BR_CAUSE_OPT's option and value to br_cause_arg. */
#define BR_CAUSE_OPT 0x100
#define BR_CAUSE_LONGOPT_(json, fld, unit, lo, hi, cause, option, req) {(option) + 2, 1 /* required_argument */, NULL, BR_CAUSE_OPT},
#define BR_CAUSE_LONGOPTS BR_CAUSE_PARAMS(BR_CAUSE_LONGOPT_)

/* Parses "a[,b[,c]]" into up to n numbers: how many, or -1. */
int br_parse_numbers(const char *s, double *v, int n);

/* 1 when opt is a cause option and val was applied to c; 0 when opt is not a
 * cause option; -1 (message on stderr, c unchanged) when val is malformed or
 * a value is outside its parameter's bounds. */
int br_cause_arg(const char *opt, const char *val, br_plant_cfg_t *c);

/* The causes the options set in causes (a br_plant_cfg_reference() that
 * br_cause_arg wrote into) put on plant: each cause whose parameters differ
 * from the reference machine's replaces plant's; the others are left as
 * plant has them. */
void br_causes_apply(br_plant_cfg_t *plant, const br_plant_cfg_t *causes);

#endif
