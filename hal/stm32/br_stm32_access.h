/* SPDX-License-Identifier: Apache-2.0 */
/* Register access of the PWM write path (br_stm32_pwm_write): every
 * compare-register store goes through BR_STM32_REG_WRITE, so that a host
 * test can see each store in order, not only the final state. On the target
 * (and in every build without BR_STM32_REG_HOOK) it is the plain volatile
 * store: the image is unchanged. A host test builds the driver with
 * BR_STM32_REG_HOOK and defines br_stm32_reg_write, which records the store
 * and makes it (tests/target/test_stm32_pwm_writes.c). */
#ifndef BR_STM32_ACCESS_H
#define BR_STM32_ACCESS_H

#include <stdint.h>

#ifdef BR_STM32_REG_HOOK
void br_stm32_reg_write(volatile uint32_t *reg, uint32_t value);
#define BR_STM32_REG_WRITE(reg, value) br_stm32_reg_write(&(reg), (value))
#else
#define BR_STM32_REG_WRITE(reg, value) ((reg) = (value))
#endif

#endif
