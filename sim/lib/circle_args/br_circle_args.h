/* SPDX-License-Identifier: Apache-2.0 */
/* The circle's options of the tools that run the thesis circle
 * (br_demo_circle, br_circle_ext, br_robust_run; docs/circle-test.md,
 * docs/tools.md):
 *
 *   --radius-m R        the radius A, m (BR_TOOL_RADIUS_MIN_M .. BR_TOOL_RADIUS_MAX_M)
 *   --feed-mm-min F     the tangential feed, mm/min (BR_TOOL_FEED_MIN_MM_MIN .. BR_TOOL_FEED_MAX_MM_MIN)
 *   --direction cw|ccw  clockwise (the thesis) or counter-clockwise; br_demo_circle also "both";
 *                       --dir the same where a tool has no --dir of its own (br_demo_circle,
 *                       br_circle_ext; br_robust_run's --dir is its trace folder)
 *
 * and, after the options, one check of the pair: a revolution, 2 pi A / v,
 * must last BR_TOOL_DURATION_MIN_S .. BR_TOOL_DURATION_MAX_S. Without any of
 * them the thesis circle (radius 1e-4 m, 8 s a revolution, clockwise). */
#ifndef BR_CIRCLE_ARGS_H
#define BR_CIRCLE_ARGS_H

#include "circle/br_circle.h"

enum { BR_CIRCLE_DIR_CW = 0, BR_CIRCLE_DIR_CCW = 1, BR_CIRCLE_DIR_BOTH = 2 };

typedef struct {
    double radius_m; /* <= 0: the configuration's */
    double feed_mps; /* <= 0: the configuration's */
    int dir;         /* BR_CIRCLE_DIR_* */
} br_circle_path_t;

#define BR_CIRCLE_PATH_DEFAULT {0.0, 0.0, BR_CIRCLE_DIR_CW}

/* getopt_long entries (sim/lib/tool/br_args.h), all with the value
 * BR_CIRCLE_OPT: put BR_CIRCLE_LONGOPTS in a tool's table and hand
 * BR_CIRCLE_OPT's option name and value to br_circle_arg. */
#define BR_CIRCLE_OPT 0x200
#define BR_CIRCLE_LONGOPTS                                                                                             \
    {"radius-m", 1 /* required_argument */, NULL, BR_CIRCLE_OPT},                                                     \
        {"feed-mm-min", 1, NULL, BR_CIRCLE_OPT}, {"direction", 1, NULL, BR_CIRCLE_OPT},
/* --dir, for the tools without a --dir of their own */
#define BR_CIRCLE_LONGOPT_DIR {"dir", 1 /* required_argument */, NULL, BR_CIRCLE_OPT},

/* the options' lines of a tool's usage text; dirs: "--dir cw|ccw|both " (the
 * option as the tool spells it, padded to 19 characters) */
#define BR_CIRCLE_USAGE(dirs)                                                                                          \
    "  --radius-m R        the circle's radius, m (default 1e-4, the thesis's)\n"                                       \
    "  --feed-mm-min F     the tangential feed, mm/min (default the thesis's: 8 s a revolution)\n"                       \
    "  " dirs " the direction, clockwise (the thesis, default) or counter-clockwise\n"

/* opt (as written, "--radius-m") with its value into p: 0, or -1 with a
 * message on stderr (p unchanged). both_ok: "--dir both" is accepted. */
int br_circle_arg(const char *tool, const char *opt, const char *val, int both_ok, br_circle_path_t *p);

/* The pair's check against the circle of base (the one the options change):
 * 0, or -1 with a message on stderr when a revolution lasts outside the
 * duration bounds. */
int br_circle_path_check(const char *tool, const br_circle_path_t *p, const br_circle_cfg_t *base);

#endif
