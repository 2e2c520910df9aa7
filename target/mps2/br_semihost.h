/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal Arm semihosting (bkpt 0xAB, Thumb) for the QEMU replay image:
 * only the calls it needs. QEMU: -semihosting-config enable=on,target=native. */
#ifndef BR_SEMIHOST_H
#define BR_SEMIHOST_H

#include <stdint.h>

#define BR_SH_OPEN_RB 1u  /* fopen modes of SYS_OPEN */
#define BR_SH_OPEN_WB 5u

int32_t br_sh_open(const char *path, uint32_t mode);
int br_sh_close(int32_t fd);
/* Exactly n bytes; 0 on success, -1 on a short transfer. */
int br_sh_read(int32_t fd, void *buf, uint32_t n);
int br_sh_write(int32_t fd, const void *buf, uint32_t n);
void br_sh_puts(const char *s);
/* Command line (-semihosting-config ...,arg=...), NUL-terminated; 0 on success. */
int br_sh_cmdline(char *buf, uint32_t len);
/* Ends the emulation with this exit status (SYS_EXIT_EXTENDED). */
void br_sh_exit(uint32_t status) __attribute__((noreturn));
/* "image: msg" and a newline on the console, then exit status 1: how an
 * image reports a failure it cannot go on from. */
void br_sh_fail(const char *image, const char *msg) __attribute__((noreturn));

#endif
