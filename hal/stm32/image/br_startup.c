/* SPDX-License-Identifier: Apache-2.0 */
/* Startup of every STM32 board's image (Cortex-M4F, Cortex-M7): vector table
 * and Reset_Handler; the board's br_board.h gives the number of interrupt
 * lines (BR_BOARD_IRQ_VECTORS) and whether the core has an instruction cache
 * to enable (BR_BOARD_ICACHE).
 *
 * Reset_Handler, in order: enables the FPU (CPACR CP10/CP11 full access, with
 * DSB/ISB so no floating-point instruction can execute before it takes
 * effect), enables the instruction cache (the M7), copies .data from flash to
 * the tightly coupled RAM (the H7's DTCM, the G4's CCM SRAM), zeroes .bss and
 * .xram (the board's DMA-reachable RAM: the PF's state, the recorder's ring,
 * the USART's buffers), and calls main. Every other exception and interrupt
 * goes to br_default_handler, which parks the core (a debugger shows where).
 * Symbols come from the board's linker script (stm32h743.ld, stm32g474.ld). No interrupt
 * is used by the image: the control tick is polled. */
#include <stdint.h>

#include "br_board.h"

/* Linker script symbols (addresses only; never read as values). The region
 * bounds are declared as arrays, so that copying through them indexes an
 * array rather than the address of a single object. */
extern uint32_t _estack;
extern uint32_t _sidata[];
extern uint32_t _sdata[];
extern uint32_t _edata[];
extern uint32_t _sbss[];
extern uint32_t _ebss[];
extern uint32_t _sxram[];
extern uint32_t _exram[];

int main(void);
void Reset_Handler(void);
void br_default_handler(void);

#define BR_SCB_CPACR   (*(volatile uint32_t *)0xE000ED88u)
#define BR_SCB_CCR     (*(volatile uint32_t *)0xE000ED14u)
#define BR_SCB_ICIALLU (*(volatile uint32_t *)0xE000EF50u)
#define BR_CPACR_CP10_CP11_FULL (0xFu << 20)
#define BR_SCB_CCR_IC  (1u << 17)

/* the core's exceptions + the part's interrupt lines */
#define BR_N_CORE_VECTORS 16
#define BR_N_IRQ_VECTORS BR_BOARD_IRQ_VECTORS

typedef union {
    void (*handler)(void);
    const void *stack_top;
} br_vector_t;

#define BR_DEF {.handler = br_default_handler}
#define BR_DEF_X10 BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF, BR_DEF
#define BR_DEF_X50 BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10, BR_DEF_X10

static inline void br_barrier(void)
{
    __asm__ volatile("dsb 0xF\n\tisb 0xF" ::: "memory");
}

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
    br_barrier();

#if BR_BOARD_ICACHE
    /* Instruction cache: invalidate, then enable. */
    BR_SCB_ICIALLU = 0u;
    br_barrier();
    BR_SCB_CCR |= BR_SCB_CCR_IC;
    br_barrier();
#endif

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
    /* the board's DMA-reachable RAM (clocked from reset): the NOLOAD statics placed there */
    dst = _sxram;
    n = ((uintptr_t)_exram - (uintptr_t)_sxram) / sizeof(uint32_t);
    for (i = 0u; i < n; ++i) {
        dst[i] = 0u;
    }

    (void)main();
    br_default_handler();
}

/* Vector table at the start of flash (0x08000000, the boot address and the
 * reset value of VTOR). Entry 0 is the initial stack pointer. */
__attribute__((section(".isr_vector"), used))
const br_vector_t br_vector_table[] = {
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
    /* 16..: the interrupt lines in order after [15], every one parked
     * (the board's list of BR_DEF: BR_BOARD_IRQ_PARKED) */
    BR_BOARD_IRQ_PARKED
};
/* the board's list holds exactly its BR_BOARD_IRQ_VECTORS lines (C99 has no
 * static_assert: a negative array size fails the build) */
typedef char br_vector_count_check[(sizeof br_vector_table == (BR_N_CORE_VECTORS + BR_N_IRQ_VECTORS) *
                                                                  sizeof(br_vector_t))
                                       ? 1
                                       : -1];
