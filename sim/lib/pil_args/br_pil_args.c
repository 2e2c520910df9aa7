/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop's QEMU options (br_pil_args.h). */
#include "br_pil_args.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tool/br_args.h"

br_pil_qemu_t br_pil_qemu_default(void)
{
    const char *qe = getenv("BR_QEMU");
    return (br_pil_qemu_t){(qe != NULL && qe[0] != '\0') ? qe : "qemu-system-arm", NULL, 60.0};
}

int br_pil_arg(const char *tool, const char *opt, const char *val, br_pil_qemu_t *q)
{
    if (strcmp(opt, "--qemu") == 0) {
        q->qemu = val;
        return 0;
    }
    if (strcmp(opt, "--timeout") == 0) return br_arg_double(tool, opt, val, 1.0, BR_PIL_TIMEOUT_MAX_S, &q->timeout_s);
    if (strcmp(opt, "--work") == 0) {
        q->work = val;
        return 0;
    }
    fprintf(stderr, "%s: %s: not a QEMU option\n", tool, opt);
    return -1;
}
