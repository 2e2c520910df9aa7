/* SPDX-License-Identifier: Apache-2.0 */
/* Minimal Arm semihosting: see br_semihost.h. */
#include "br_semihost.h"

#define BR_SYS_OPEN 0x01u
#define BR_SYS_CLOSE 0x02u
#define BR_SYS_WRITE0 0x04u
#define BR_SYS_WRITE 0x05u
#define BR_SYS_READ 0x06u
#define BR_SYS_GET_CMDLINE 0x15u
#define BR_SYS_EXIT_EXTENDED 0x20u
#define BR_ADP_STOPPED_APPLICATION_EXIT 0x20026u

static uint32_t br_sh_call(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static uint32_t br_strlen(const char *s)
{
    uint32_t n = 0u;
    while (s[n] != '\0') ++n;
    return n;
}

int32_t br_sh_open(const char *path, uint32_t mode)
{
    const uint32_t a[3] = {(uint32_t)(uintptr_t)path, mode, br_strlen(path)};
    return (int32_t)br_sh_call(BR_SYS_OPEN, a);
}

int br_sh_close(int32_t fd)
{
    const uint32_t a[1] = {(uint32_t)fd};
    return (br_sh_call(BR_SYS_CLOSE, a) == 0u) ? 0 : -1;
}

int br_sh_read(int32_t fd, void *buf, uint32_t n)
{
    const uint32_t a[3] = {(uint32_t)fd, (uint32_t)(uintptr_t)buf, n};
    return (br_sh_call(BR_SYS_READ, a) == 0u) ? 0 : -1; /* returns the bytes NOT read */
}

int br_sh_write(int32_t fd, const void *buf, uint32_t n)
{
    const uint32_t a[3] = {(uint32_t)fd, (uint32_t)(uintptr_t)buf, n};
    return (br_sh_call(BR_SYS_WRITE, a) == 0u) ? 0 : -1;
}

void br_sh_puts(const char *s)
{
    (void)br_sh_call(BR_SYS_WRITE0, s);
}

int br_sh_cmdline(char *buf, uint32_t len)
{
    uint32_t a[2] = {(uint32_t)(uintptr_t)buf, len};
    return (br_sh_call(BR_SYS_GET_CMDLINE, a) == 0u) ? 0 : -1;
}

void br_sh_exit(uint32_t status)
{
    const uint32_t a[2] = {BR_ADP_STOPPED_APPLICATION_EXIT, status};
    (void)br_sh_call(BR_SYS_EXIT_EXTENDED, a);
    for (;;) {
        __asm__ volatile("nop");
    }
}

void br_sh_fail(const char *image, const char *msg)
{
    br_sh_puts(image);
    br_sh_puts(": ");
    br_sh_puts(msg);
    br_sh_puts("\n");
    br_sh_exit(1u);
}
