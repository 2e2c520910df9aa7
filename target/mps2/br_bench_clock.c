/* SPDX-License-Identifier: Apache-2.0 */
/* The bench images' clock (br_bench_clock.h). */
#include "br_bench_clock.h"

#include "br_semihost.h"

#define BR_SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define BR_SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define BR_SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define BR_CAL_ITER 1000000u

uint32_t br_bench_clock_stamp(br_bench_clock_t *c)
{
    const uint32_t raw = BR_SYST_CVR & 0xFFFFFFu;
    c->ext += (c->last_raw - raw) & 0xFFFFFFu;
    c->last_raw = raw;
    return c->ext;
}

void br_bench_say_u32(const char *label, uint32_t v)
{
    char t[11];
    char b[12];
    int n = 0;
    int i = 0;
    do {
        t[n++] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0) b[i++] = t[--n];
    b[i] = '\0';
    br_sh_puts(label);
    br_sh_puts(b);
}

void br_bench_clock_start(br_bench_clock_t *c)
{
    BR_SYST_RVR = 0xFFFFFFu;
    BR_SYST_CVR = 0u;
    BR_SYST_CSR = 0x5u; /* processor clock, enabled, no interrupt */
    c->last_raw = BR_SYST_CVR & 0xFFFFFFu;
    c->ext = 0u;
    const uint32_t c0 = br_bench_clock_stamp(c);
    {
        /* 2 instructions per iteration (subs, bne) */
        register uint32_t n __asm__("r4") = BR_CAL_ITER;
        __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    }
    const uint32_t c1 = br_bench_clock_stamp(c);
    br_bench_say_u32("calib insns=", 2u * BR_CAL_ITER);
    br_bench_say_u32(" ticks=", c1 - c0);
    br_sh_puts("\n");
}
