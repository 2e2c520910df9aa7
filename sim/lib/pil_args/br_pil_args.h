/* SPDX-License-Identifier: Apache-2.0 */
/* The QEMU options of the tools that run the image in the loop (br_pil,
 * br_pil_tune; docs/link.md, "The image in the loop"; docs/tools.md):
 *
 *   --qemu PATH   qemu-system-arm to run (default $BR_QEMU, else qemu-system-arm on PATH)
 *   --timeout S   seconds to wait for one answer of the image, 1 .. BR_PIL_TIMEOUT_MAX_S (default 60)
 *   --work DIR    folder for the FIFOs and QEMU's logs (default new ones under /tmp, removed)
 *
 * handed to br_pil_loop_open as they are. */
#ifndef BR_PIL_ARGS_H
#define BR_PIL_ARGS_H

typedef struct {
    const char *qemu; /* never NULL */
    const char *work; /* NULL: new folders under /tmp, removed at the end */
    double timeout_s;
} br_pil_qemu_t;

#define BR_PIL_TIMEOUT_MAX_S 3600

/* the defaults: $BR_QEMU when set and not empty, else qemu-system-arm; 60 s; no folder */
br_pil_qemu_t br_pil_qemu_default(void);

/* getopt_long entries (sim/lib/tool/br_args.h), all with the value
 * BR_PIL_OPT: put BR_PIL_LONGOPTS in a tool's table and hand BR_PIL_OPT's
 * option name and value to br_pil_arg. */
#define BR_PIL_OPT 0x300
#define BR_PIL_LONGOPTS                                                                                                \
    {"qemu", 1 /* required_argument */, NULL, BR_PIL_OPT}, {"timeout", 1, NULL, BR_PIL_OPT},                           \
        {"work", 1, NULL, BR_PIL_OPT},

#define BR_PIL_STR_(x) #x
#define BR_PIL_STR(x) BR_PIL_STR_(x)
/* the options' lines of a tool's usage text */
#define BR_PIL_USAGE                                                                                                   \
    "  --qemu      qemu-system-arm to run (default $BR_QEMU, else qemu-system-arm on PATH)\n"                           \
    "  --timeout   seconds to wait for one answer of the image, 1 .. " BR_PIL_STR(BR_PIL_TIMEOUT_MAX_S)                 \
    " (default 60)\n"                                                                                                    \
    "  --work      folder for the FIFOs and QEMU's logs (default new ones under /tmp, removed)\n"

/* opt (as written, "--timeout") with its value into q: 0, or -1 with a
 * message on stderr (q unchanged). */
int br_pil_arg(const char *tool, const char *opt, const char *val, br_pil_qemu_t *q);

#endif
