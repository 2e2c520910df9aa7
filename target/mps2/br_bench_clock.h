/* SPDX-License-Identifier: Apache-2.0 */
/* The bench images' clock (docs/target.md, "Cost on the target"): SysTick
 * on the processor clock, reload 2^24 - 1, read as an up-count extended to
 * 32 bits; under QEMU's -icount shift=0 one tick is 40 instructions, which
 * br_bench_clock_start's calibration loop measures and prints
 * ("calib insns=... ticks=..."). Stamps must be < 2^24 ticks apart. */
#ifndef BR_BENCH_CLOCK_H
#define BR_BENCH_CLOCK_H

#include <stdint.h>

typedef struct {
    uint32_t last_raw; /* SysTick VAL at the last stamp (down-counter, 24 bit) */
    uint32_t ext;      /* ticks since the start */
} br_bench_clock_t;

/* Starts SysTick, times 2 x 10^6 known instructions and prints the
 * calibration line. */
void br_bench_clock_start(br_bench_clock_t *c);

/* ticks since the start */
uint32_t br_bench_clock_stamp(br_bench_clock_t *c);

/* prints label then v in decimal on the semihosting console */
void br_bench_say_u32(const char *label, uint32_t v);

#endif
