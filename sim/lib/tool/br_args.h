/* SPDX-License-Identifier: Apache-2.0 */
/* The host tools' command lines (sim/apps; docs/tools.md): GNU
 * getopt_long underneath, with what every tool shares on top:
 *
 *   --help / -h   anywhere, even where a value is expected ("--out --help"
 *                 asks for help, never names a file --help): usage on stdout, exit 0
 *   --version     anywhere, likewise: "TOOL (bristle) X.Y.Z" (BR_VERSION_STRING), exit 0
 *   an unknown option, an option without its value, a stray argument:
 *                 one line "tool: ..." on stderr, then the tool's usage, exit 2
 *
 * and the option values: whole strings only, checked against their bounds
 * (br_tool_limits.h), with one message form "tool: OPT VALUE: must be a
 * number in LO .. HI".
 *
 * A tool's loop:
 *   static const struct option opts[] = {{"out", required_argument, NULL, 'o'}, ..., {0}};
 *   br_args_t p;
 *   if (br_args_start(&p, TOOL, argc, argv, usage)) return 0;   (--help, --version: printed)
 *   for (int c; (c = br_args_next(&p, opts, &val)) != BR_ARGS_END;)
 *       switch (c) { case 'o': ...; case BR_ARGS_BAD: return usage(...); } */
#ifndef BR_ARGS_H
#define BR_ARGS_H

#include <getopt.h>
#include <stdio.h>

enum {
    BR_ARGS_END = -1,  /* br_args_next: no more options */
    BR_ARGS_BAD = '?', /* br_args_next: a usage error, already reported */
    BR_ARGS_RUN = 0,   /* br_args_begin: parse the options */
    BR_ARGS_HELP = 1,  /* br_args_begin: --help or -h was given */
    BR_ARGS_VERSION = 2 /* br_args_begin: --version was given (and not --help) */
};

typedef struct {
    const char *tool;
    int argc;
    char **argv;
    char opt[48]; /* the last option as written on a command line ("--dt"), for messages */
} br_args_t;

/* Starts a parse (resets getopt): BR_ARGS_HELP, BR_ARGS_VERSION or BR_ARGS_RUN. */
int br_args_begin(br_args_t *p, const char *tool, int argc, char **argv);

/* A tool's usage text, printed to `to` (its return value is the tool's exit
 * code for a bad command line). */
typedef int (*br_args_usage_t)(const char *argv0, FILE *to);

/* br_args_begin, then --help (usage on stdout) or --version answered: 1 when
 * the tool is done (exit 0), 0 when the options are to be parsed. */
int br_args_start(br_args_t *p, const char *tool, int argc, char **argv, br_args_usage_t usage);

/* The next option: its val from longopts (a {0}-terminated getopt_long
 * table; long options only), its argument in *arg (NULL for a flag) and its
 * name in p->opt; BR_ARGS_END after the last; BR_ARGS_BAD after printing the
 * problem (unknown option, missing value, a stray non-option argument). */
int br_args_next(br_args_t *p, const struct option *longopts, const char **arg);

/* "TOOL (bristle) X.Y.Z" */
void br_args_print_version(const char *tool, FILE *to);

/* the options every tool has, for its usage text */
#define BR_ARGS_COMMON_USAGE "       %s --help | --version\n"

/* the whole of val as a finite number in [lo, hi] into *out: 0, or -1 with a
 * message on stderr (*out untouched) */
int br_arg_double(const char *tool, const char *opt, const char *val, double lo, double hi, double *out);

/* the whole of val as a decimal integer in [lo, hi]: 0 or -1, as above */
int br_arg_long(const char *tool, const char *opt, const char *val, long lo, long hi, long *out);

/* 1 when name is an item of the comma-separated list (no spaces), 0
 * otherwise or for a NULL list */
int br_arg_list_has(const char *list, const char *name);

#endif
