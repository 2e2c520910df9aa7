/* SPDX-License-Identifier: Apache-2.0 */
/* The host tools' command lines (br_args.h). */
#include "br_args.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bristle/br_version.h"

int br_args_begin(br_args_t *p, const char *tool, int argc, char **argv)
{
    p->tool = tool;
    p->argc = argc;
    p->argv = argv;
    p->opt[0] = '\0';
    optind = 0; /* glibc: a full re-initialisation of getopt's state */
    opterr = 0; /* the messages are ours */
    int version = 0;
    /* wherever they stand, so that neither is ever taken as an option's value */
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--help") == 0 || strcmp(argv[i], "-h") == 0) return BR_ARGS_HELP;
        if (strcmp(argv[i], "--version") == 0) version = 1;
    }
    return version ? BR_ARGS_VERSION : BR_ARGS_RUN;
}

int br_args_start(br_args_t *p, const char *tool, int argc, char **argv, br_args_usage_t usage)
{
    const int st = br_args_begin(p, tool, argc, argv);
    if (st == BR_ARGS_HELP) {
        (void)usage(argv[0], stdout);
    } else if (st == BR_ARGS_VERSION) {
        br_args_print_version(tool, stdout);
    }
    return st != BR_ARGS_RUN;
}

/* how many different long options start with what "--" word (before any '=') names */
static int prefix_matches(const struct option *longopts, const char *word)
{
    if (strncmp(word, "--", 2) != 0) return 0;
    word += 2;
    const size_t n = strcspn(word, "=");
    int count = 0;
    for (const struct option *o = longopts; o->name; o++) {
        if (strncmp(o->name, word, n) != 0) continue;
        int seen = 0; /* a name repeated in the table (the cause options) counts once */
        for (const struct option *q = longopts; q < o; q++) seen |= strcmp(q->name, o->name) == 0;
        count += !seen;
    }
    return count;
}

int br_args_next(br_args_t *p, const struct option *longopts, const char **arg)
{
    int idx = -1;
    /* ':' first: a missing value is told apart (':') from an unknown option ('?') */
    const int c = getopt_long(p->argc, p->argv, ":", longopts, &idx);
    *arg = NULL;
    if (c == -1) {
        if (optind < p->argc) {
            fprintf(stderr, "%s: unexpected argument %s\n", p->tool, p->argv[optind]);
            return BR_ARGS_BAD;
        }
        return BR_ARGS_END;
    }
    const char *written = p->argv[optind - 1]; /* the option as given (for a missing value, the last word) */
    if (c == ':') {
        fprintf(stderr, "%s: %s needs a value\n", p->tool, written);
        return BR_ARGS_BAD;
    }
    if (c == '?' || idx < 0) {
        const int matches = prefix_matches(longopts, written);
        if (strncmp(written, "--", 2) != 0)
            fprintf(stderr, "%s: unknown option -%c\n", p->tool, optopt ? optopt : '?');
        else if (matches > 1)
            fprintf(stderr, "%s: ambiguous option %s (the start of more than one option)\n", p->tool, written);
        else if (matches == 1 && strchr(written, '='))
            fprintf(stderr, "%s: %s: the option takes no value\n", p->tool, written);
        else
            fprintf(stderr, "%s: unknown option %s\n", p->tool, written);
        return BR_ARGS_BAD;
    }
    snprintf(p->opt, sizeof p->opt, "--%s", longopts[idx].name);
    *arg = optarg;
    return c;
}

void br_args_print_version(const char *tool, FILE *to)
{
    fprintf(to, "%s (bristle) %s\n", tool, BR_VERSION_STRING);
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

int br_arg_list_has(const char *list, const char *name)
{
    const size_t n = strlen(name);
    for (const char *p = list; p && *p;) {
        const char *e = strchr(p, ',');
        const size_t len = e ? (size_t)(e - p) : strlen(p);
        if (len == n && strncmp(p, name, n) == 0) return 1;
        p = e ? e + 1 : NULL;
    }
    return 0;
}
