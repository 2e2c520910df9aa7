/* SPDX-License-Identifier: Apache-2.0 */
/* Startup for the STM32G474 (Cortex-M4F): vector table and Reset_Handler.
 *
 * Reset_Handler, in order: enables the FPU (CPACR CP10/CP11 full access, then
 * DSB/ISB so that no floating-point instruction runs before it takes effect),
 * copies .data from flash to CCM SRAM, zeroes .bss, and calls main. The M4
 * has no cache of its own (the flash's ART accelerator is enabled with the
 * wait states, br_stm32g4_clock_170). Every other exception and interrupt goes
 * to br_default_handler, which parks the core. Symbols from stm32g474.ld. No
 * interrupt is used by the image: the control tick is polled. */
#include <stdint.h>

/* Linker script symbols (addresses only; never read as values); the region
 * bounds are arrays, so copying through them indexes an array. */
extern uint32_t _estack;
extern uint32_t _sidata[];
extern uint32_t _sdata[];
extern uint32_t _edata[];
extern uint32_t _sbss[];
extern uint32_t _ebss[];

int main(void);
void Reset_Handler(void);
void br_default_handler(void);

#define BR_SCB_CPACR (*(volatile uint32_t *)0xE000ED88u)
#define BR_CPACR_CP10_CP11_FULL (0xFu << 20)

/* Cortex-M4 core exceptions + the 102 STM32G474 interrupt lines (RM0440). */
#define BR_N_CORE_VECTORS 16
#define BR_N_IRQ_VECTORS 102

typedef union {
    void (*handler)(void);
    const void *stack_top;
} br_vector_t;

#define BR_DEF {.handler = br_default_handler}
#define BR_DEF_X10 BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF

void br_default_handler(void)
{
    for (;;) {
        __asm__ volatile("nop");
    }
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

    (void)main();
    br_default_handler();
}

/* Vector table at the start of flash (0x08000000, the boot address). */
__attribute__((section(".isr_vector"), used))
const br_vector_t br_vector_table[BR_N_CORE_VECTORS + BR_N_IRQ_VECTORS] = {
    [0] = {.stack_top = &_estack},
    [1] = {.handler = Reset_Handler},
    [2] = {.handler = br_default_handler},  /* NMI */
    [3] = {.handler = br_default_handler},  /* HardFault */
    [4] = {.handler = br_default_handler},  /* MemManage */
    [5] = {.handler = br_default_handler},  /* BusFault */
    [6] = {.handler = br_default_handler},  /* UsageFault */
    /* 7..10 reserved */
    [11] = {.handler = br_default_handler}, /* SVCall */
    [12] = {.handler = br_default_handler}, /* DebugMonitor */
    /* 13 reserved */
    [14] = {.handler = br_default_handler}, /* PendSV */
    [15] = {.handler = br_default_handler}, /* SysTick (not enabled: polled) */
    /* 16..117: the interrupt lines */
    BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, /*  0..49 */
    BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, /* 50..99 */
    BR_DEF, BR_DEF,                                             /* 100..101 */
};
