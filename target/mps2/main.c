/* SPDX-License-Identifier: Apache-2.0 */
/* Replay image for QEMU's mps2-an500 (Cortex-M7, FPU): reads a recorded
 * stream through semihosting, runs it through br_app_step with the PF
 * (target/replay/br_replay.h) and writes one output record per step.
 *
 *   qemu-system-arm -M mps2-an500 -nographic -kernel br_replay_mps2.elf \
 *     -semihosting-config enable=on,target=native,arg=replay,arg=IN,arg=OUT,arg=M
 *
 * M = 0 keeps the stream's particle count. Exit status 0 on success.
 * The cost field of each record is the SysTick (25 MHz in QEMU's model, CPU
 * clock source) difference around br_app_step, extended to 32 bits; with
 * `-icount shift=0` it counts executed instructions / 40. Before the replay,
 * a calibration loop of 2 x BR_CAL_ITER instructions is timed the same way
 * and printed ("calib insns=... ticks=..."), so the conversion is measured,
 * not assumed (docs/target.md).
 *
 * All state (br_replay_t, two axes of ~62 KB) is in main's stack frame: no mutable
 * globals; mps2_an500.ld reserves a 512 KiB stack. */
#include <stdint.h>

#include "replay/br_replay.h"
#include "br_semihost.h"

#define BR_SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define BR_SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define BR_SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define BR_CAL_ITER 1000000u

typedef struct {
    int32_t in_fd;
    int32_t out_fd;
    uint32_t last_raw;  /* SysTick VAL at the last stamp (down-counter, 24 bit) */
    uint32_t ext;       /* extended up-count */
} br_mps2_io_t;

static int io_read(void *ctx, void *buf, uint32_t n)
{
    return br_sh_read(((br_mps2_io_t *)ctx)->in_fd, buf, n);
}

static int io_write(void *ctx, const void *buf, uint32_t n)
{
    return br_sh_write(((br_mps2_io_t *)ctx)->out_fd, buf, n);
}

/* Up-counting 32-bit extension of the 24-bit down-counter: exact as long as
 * two stamps are less than 2^24 ticks apart. */
static uint32_t io_stamp(void *ctx)
{
    br_mps2_io_t *io = ctx;
    const uint32_t raw = BR_SYST_CVR & 0xFFFFFFu;
    io->ext += (io->last_raw - raw) & 0xFFFFFFu;
    io->last_raw = raw;
    return io->ext;
}

static void put_u32(char *p, uint32_t v)
{
    char t[11];
    int n = 0;
    do {
        t[n++] = (char)('0' + (char)(v % 10u));
        v /= 10u;
    } while (v != 0u);
    while (n > 0) *p++ = t[--n];
    *p = '\0';
}

static void say_u32(const char *label, uint32_t v)
{
    char b[12];
    put_u32(b, v);
    br_sh_puts(label);
    br_sh_puts(b);
}

/* Next space-separated token of the command line: NUL-terminates it in place. */
static char *next_tok(char **s)
{
    char *p = *s;
    while (*p == ' ') ++p;
    if (*p == '\0') return 0;
    char *t = p;
    while (*p != '\0' && *p != ' ') ++p;
    if (*p == ' ') *p++ = '\0';
    *s = p;
    return t;
}

static uint32_t parse_u32(const char *s)
{
    uint32_t v = 0u;
    while (*s >= '0' && *s <= '9') v = v * 10u + (uint32_t)(*s++ - '0');
    return v;
}

static void fail(const char *msg)
{
    br_sh_fail("br_replay_mps2", msg);
}

int main(void)
{
    br_replay_t replay;
    br_mps2_io_t mio = {-1, -1, 0u, 0u};
    char cmd[512];
    char *p = cmd;

    if (br_sh_cmdline(cmd, (uint32_t)sizeof cmd) != 0) fail("no command line");
    (void)next_tok(&p); /* program name */
    const char *in = next_tok(&p);
    const char *out = next_tok(&p);
    const char *m = next_tok(&p);
    const char *sp = next_tok(&p); /* optional: 1 = the PF's scalar reference path */
    if (in == 0 || out == 0) fail("usage: replay IN OUT [M [SCALAR_PATH]]");

    BR_SYST_RVR = 0xFFFFFFu;
    BR_SYST_CVR = 0u;
    BR_SYST_CSR = 0x5u; /* CLKSOURCE = processor clock, ENABLE, no interrupt */
    mio.last_raw = BR_SYST_CVR & 0xFFFFFFu;

    /* calibration: 2 instructions per iteration (subs, bne) */
    const uint32_t c0 = io_stamp(&mio);
    {
        register uint32_t n __asm__("r4") = BR_CAL_ITER;
        __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
    }
    const uint32_t c1 = io_stamp(&mio);
    say_u32("calib insns=", 2u * BR_CAL_ITER);
    say_u32(" ticks=", c1 - c0);
    br_sh_puts("\n");

    mio.in_fd = br_sh_open(in, BR_SH_OPEN_RB);
    if (mio.in_fd < 0) fail("cannot open the input stream");
    mio.out_fd = br_sh_open(out, BR_SH_OPEN_WB);
    if (mio.out_fd < 0) fail("cannot open the output file");

    const br_replay_io_t io = {&mio, io_read, io_write, io_stamp};
    const int rc = br_replay_run(&replay, &io, (m != 0) ? parse_u32(m) : 0u, (sp != 0) ? parse_u32(sp) : 0u);
    (void)br_sh_close(mio.in_fd);
    (void)br_sh_close(mio.out_fd);
    if (rc != 0) {
        say_u32("br_replay_mps2: replay failed, code -", (uint32_t)(-rc));
        br_sh_puts("\n");
        br_sh_exit(2u);
    }
    say_u32("replay steps=", replay.cfg.n_steps);
    say_u32(" m=", replay.cfg.pf.n_particles);
    say_u32(" sizeof_replay=", (uint32_t)sizeof replay);
    say_u32(" axes=", replay.cfg.n_axes);
    say_u32(" sizeof_pf=", (uint32_t)sizeof replay.ax[0].pf);
    br_sh_puts("\n");
    br_sh_exit(0u);
}
