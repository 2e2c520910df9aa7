/* SPDX-License-Identifier: Apache-2.0 */
/* The cause options of the simulator's command lines (br_simlog,
 * br_circle_ext, br_pil, br_link_sim): docs/simlog.md. Each sets the
 * br_plant_cfg_t fields of its rows of BR_CAUSE_PARAMS (the cause registry's,
 * bristle_gen/model/br_causes.h, through sim/lib/plant/br_model_params.h),
 * its values in their order; br_cause_usage prints them. */
#ifndef BR_CAUSE_ARGS_H
#define BR_CAUSE_ARGS_H

#include <stdio.h>

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

/* The cause options' part of a usage text on to: a heading, note on a line of
 * its own (none when ""), then one line per option with its values (the rows'
 * json names, the optional ones in brackets) and its cause. */
void br_cause_usage(FILE *to, const char *note);

#endif
