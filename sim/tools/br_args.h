/* Option values of the host tools (sim/apps): whole strings only, checked
 * against their bounds (br_tool_limits.h), with one message form:
 * "tool: OPT VALUE: must be a number in LO .. HI". */
#ifndef BR_ARGS_H
#define BR_ARGS_H

/* 1 when any argument is --help or -h, wherever it stands (so it is never
 * taken as an option's value: "--out --help" asks for help) */
int br_args_want_help(int argc, char **argv);

/* the whole of val as a finite number in [lo, hi] into *out: 0, or -1 with a
 * message on stderr (*out untouched) */
int br_arg_double(const char *tool, const char *opt, const char *val, double lo, double hi, double *out);

/* the whole of val as a decimal integer in [lo, hi]: 0 or -1, as above */
int br_arg_long(const char *tool, const char *opt, const char *val, long lo, long hi, long *out);

#endif
