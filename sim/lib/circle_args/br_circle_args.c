/* SPDX-License-Identifier: Apache-2.0 */
/* The circle's options (br_circle_args.h). */
#include "br_circle_args.h"

#include <stdio.h>
#include <string.h>

#include "tool/br_args.h"
#include "tool/br_tool_limits.h"

#define MM_MIN_PER_MPS 60000.0

int br_circle_arg(const char *tool, const char *opt, const char *val, int both_ok, br_circle_path_t *p)
{
    if (strcmp(opt, "--radius-m") == 0)
        return br_arg_double(tool, opt, val, BR_TOOL_RADIUS_MIN_M, BR_TOOL_RADIUS_MAX_M, &p->radius_m);
    if (strcmp(opt, "--feed-mm-min") == 0) {
        double f;
        if (br_arg_double(tool, opt, val, BR_TOOL_FEED_MIN_MM_MIN, BR_TOOL_FEED_MAX_MM_MIN, &f) != 0) return -1;
        p->feed_mps = f / MM_MIN_PER_MPS;
        return 0;
    }
    if (strcmp(opt, "--direction") == 0 || strcmp(opt, "--dir") == 0) {
        if (strcmp(val, "cw") == 0) p->dir = BR_CIRCLE_DIR_CW;
        else if (strcmp(val, "ccw") == 0) p->dir = BR_CIRCLE_DIR_CCW;
        else if (both_ok && strcmp(val, "both") == 0) p->dir = BR_CIRCLE_DIR_BOTH;
        else {
            fprintf(stderr, "%s: %s %s: must be cw or ccw%s\n", tool, opt, val, both_ok ? " or both" : "");
            return -1;
        }
        return 0;
    }
    fprintf(stderr, "%s: %s: not a circle option\n", tool, opt);
    return -1;
}

int br_circle_path_check(const char *tool, const br_circle_path_t *p, const br_circle_cfg_t *base)
{
    br_circle_cfg_t c = *base;
    br_circle_use_path(&c, p->radius_m, p->feed_mps, 0);
    if (!(c.period_s >= BR_TOOL_DURATION_MIN_S && c.period_s <= BR_TOOL_DURATION_MAX_S)) {
        fprintf(stderr,
                "%s: a revolution of radius %g m at %g mm/min lasts %g s: must be %g .. %g s "
                "(--radius-m, --feed-mm-min)\n",
                tool, c.radius_m, br_circle_feed_mps(&c) * MM_MIN_PER_MPS, c.period_s, BR_TOOL_DURATION_MIN_S,
                BR_TOOL_DURATION_MAX_S);
        return -1;
    }
    return 0;
}
