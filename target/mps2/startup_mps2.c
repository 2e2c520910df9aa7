/* SPDX-License-Identifier: Apache-2.0 */
/* Startup of the replay image on QEMU's mps2-an500 (Cortex-M7 with FPU):
 * vector table, Reset_Handler and the fault handler.
 *
 * Reset_Handler: enables the FPU (CPACR CP10/CP11 full access, then DSB/ISB
 * so that no floating-point instruction runs before it takes effect), copies
 * .data, zeroes .bss, calls main and ends the emulation with main's status.
 * Any other exception (NMI, the faults, SVC, PendSV, SysTick) is unexpected:
 * the image polls SysTick and enables no interrupt, so br_mps2_fault says so
 * on the semihosting console and ends the emulation with status 3 rather than
 * leaving QEMU spinning until the test's timeout. Symbols from mps2_an500.ld. */
#include <stdint.h>

#include "br_semihost.h"

/* Linker script symbols (addresses only; never read as values). The region
 * bounds are declared as arrays, so that copying through them indexes an
 * array rather than the address of a single object. */
extern uint32_t _estack;
extern uint32_t _sidata[];
extern uint32_t _sdata[];
extern uint32_t _edata[];
extern uint32_t _sbss[];
extern uint32_t _ebss[];

int main(void);
void Reset_Handler(void);
void br_mps2_fault(void);

#define BR_SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define BR_CPACR_CP10_CP11_FULL (0xFu << 20)
#define BR_MPS2_FAULT_STATUS 3u
#define BR_N_CORE_VECTORS 16

typedef union {
    void (*handler)(void);
    const void *stack_top;
} br_vector_t;

void br_mps2_fault(void)
{
    br_sh_puts("mps2: unexpected exception (fault)\n");
    br_sh_exit(BR_MPS2_FAULT_STATUS);
}

void Reset_Handler(void)
{
    volatile uint32_t *dst;
    const volatile uint32_t *src;
    uintptr_t n;
    uintptr_t i;

    /* FPU first: the -mfloat-abi=hard code may use s-registers anywhere. */
    BR_SCB_CPACR |= BR_CPACR_CP10_CP11_FULL;
    __asm__ volatile("dsb 0xF\n\tisb 0xF" ::: "memory");

    /* Word loops through volatile pointers: no call to memcpy/memset here. */
    src = _sidata;
    dst = _sdata;
    n = ((uintptr_t)_edata - (uintptr_t)_sdata) / sizeof(uint32_t);
    for (i = 0u; i < n; ++i) {
        dst[i] = src[i];
    }
    dst = _sbss;
    n = ((uintptr_t)_ebss - (uintptr_t)_sbss) / sizeof(uint32_t);
    for (i = 0u; i < n; ++i) {
        dst[i] = 0u;
    }

    br_sh_exit((uint32_t)main());
}

/* The core's exceptions only: the image enables no interrupt line. Entry 0 is
 * the initial stack pointer; QEMU boots from the table at 0 (VTOR reset value). */
__attribute__((section(".isr_vector"), used))
const br_vector_t br_mps2_vectors[BR_N_CORE_VECTORS] = {
    [0] = {.stack_top = &_estack},
    [1] = {.handler = Reset_Handler},
    [2] = {.handler = br_mps2_fault},  /* NMI */
    [3] = {.handler = br_mps2_fault},  /* HardFault */
    [4] = {.handler = br_mps2_fault},  /* MemManage */
    [5] = {.handler = br_mps2_fault},  /* BusFault */
    [6] = {.handler = br_mps2_fault},  /* UsageFault */
    /* 7..10 reserved */
    [11] = {.handler = br_mps2_fault}, /* SVCall */
    [12] = {.handler = br_mps2_fault}, /* DebugMonitor */
    /* 13 reserved */
    [14] = {.handler = br_mps2_fault}, /* PendSV */
    [15] = {.handler = br_mps2_fault}, /* SysTick (polled, never enabled) */
};
