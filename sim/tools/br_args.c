/* Option values (br_args.h). */
#include "br_args.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int br_args_want_help(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return 1;
    return 0;
}

int br_arg_double(const char *tool, const char *opt, const char *val, double lo, double hi, double *out)
{
    char *end = NULL;
    errno = 0;
    const double v = strtod(val, &end);
    if (end == val || *end != '\0' || errno == ERANGE || !isfinite(v) || v < lo || v > hi) {
        fprintf(stderr, "%s: %s %s: must be a number in %g .. %g\n", tool, opt, val, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int br_arg_long(const char *tool, const char *opt, const char *val, long lo, long hi, long *out)
{
    char *end = NULL;
    errno = 0;
    const long v = strtol(val, &end, 10);
    if (end == val || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        fprintf(stderr, "%s: %s %s: must be a whole number in %ld .. %ld\n", tool, opt, val, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}
