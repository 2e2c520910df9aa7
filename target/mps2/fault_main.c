/* SPDX-License-Identifier: Apache-2.0 */
/* br_fault_mps2.elf: the check of startup_mps2.c's fault handler (ctest
 * target_qemu_fault). An undefined instruction raises a UsageFault, taken as
 * a HardFault (the configurable faults are not enabled): the emulation must
 * end with status 3 and the handler's message instead of spinning. Returning
 * from main (status 0) means the fault was not taken. */
int main(void);

int main(void)
{
    __asm__ volatile("udf #0");
    return 0;
}
