/* The board: how the STM32H743 of the bristle image is wired and clocked.
 *
 * Pins (RM0433, all AF1): TIM2 encoder on PA0 (CH1) / PA1 (CH2); TIM1 PWM on
 * PA8 (CH1), PA9 (CH2), PB13 (CH1N), PB14 (CH2N); the control tick is SysTick.
 * Clocks: the reset clock (HSI 64 MHz, every bus prescaler 1), so the core
 * and the timer kernel clocks are both 64 MHz. A bring-up that starts PLL1
 * (480 MHz core, 240 MHz timers) only changes BR_BOARD_CPU_HZ and
 * BR_BOARD_TIM_HZ. PWM 20 kHz centre-aligned with 500 ns dead time, encoder
 * input filter f_CK_INT with N = 8. docs/modules/hal.md. */
#ifndef BR_STM32H7_BOARD_H
#define BR_STM32H7_BOARD_H

#include <stdint.h>

#include "bristle/br_hal.h"
#include "bristle/br_stm32h7.h"

#define BR_BOARD_CPU_HZ     64000000u /* HSI after reset */
#define BR_BOARD_TIM_HZ     64000000u /* APB timer kernel clock */
#define BR_BOARD_PWM_HZ     20000u
#define BR_BOARD_DEADTIME   32u       /* timer ticks: 500 ns at 64 MHz */
#define BR_BOARD_ENC_FILTER 3u        /* f_CK_INT, N = 8 */

/* The port configuration of this board (peripheral bases, clocks, PWM,
 * encoder) for a control tick of control_hz. */
br_stm32h7_cfg_t br_stm32h7_board_cfg(uint32_t control_hz);

/* Brings the board up: peripheral clocks, pins to their timers, then the
 * port (br_stm32h7_init validates the configuration before writing a timer
 * register) and its br_hal_t. br_stm32h7_init's status. */
br_status_t br_stm32h7_board_init(br_stm32h7_t *port, uint32_t control_hz, br_hal_t *hal);

/* Motor stopped and outputs off (br_stm32h7_pwm_disable); then waits for a
 * reset or a debugger. */
void br_stm32h7_board_halt(br_stm32h7_t *port) __attribute__((noreturn));

#endif
