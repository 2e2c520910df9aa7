/* SPDX-License-Identifier: Apache-2.0 */
/* The bristle firmware image of every STM32 board (docs/porting.md, "Adding
 * a board"): one axis under the command service (bristle/br_svc.h,
 * docs/link.md), with the H-infinity gains of
 * firmware/gen/bristle_gen/ctrl/br_hinf_gains.h and the friction compensation
 * of the machine file's estimator (control.estimator): the first of the list
 * the board runs in real time, the particle filter (1500 particles for the
 * reference machine) in a loop at its period (1.5 ms) where the board's core
 * can (BR_BOARD_RUNS_PF), else the UKF or H-infinity only at the control
 * period (bristle/br_machine_cfg.h: the same generated headers, one home).
 *
 * What differs from board to board comes from the board (br_board.h of
 * hal/<part>/board, on the include path of the board's image): its table
 * br_board (clocks, pins, timers, the USART and its DMA, the watchdog;
 * bristle/br_stm32_board.h) and a few compile-time values (BR_BOARD_*: the
 * PF or not, the section of the DMA-reachable RAM, the recorder's size, the
 * line's baud rate).
 *
 * main: board bring-up (the part's clock tree, outputs off; the USART by
 * DMA) -> after a watchdog reset, park with the outputs off -> the watchdog
 * started -> br_app_init (DISARMED: duty 0, outputs off) -> the service, the
 * recorder and telemetry -> per tick: the deadline (while armed), br_svc_step
 * (the host's request, the reference from the setpoint / segment queue,
 * br_app_step, the reports), the recorder's request, the period's sample to
 * telemetry (every BR_IMAGE_TLM_EVERY periods) and to the recorder's ring,
 * the dump's frames, and the watchdog refresh. The axis moves only after the
 * host's arm; a fault latches (duty 0, TIM1 outputs off), is reported and
 * captured by the recorder, and the loop goes on disarmed so the host can
 * read it and dump the capture; a fault_reset and an arm restart it. A tick
 * that never comes parks the board without refreshing: the watchdog resets
 * the part, which then stays off (br_board.reset_by_watchdog) until a pin or
 * power-on reset.
 *
 * State: the configurations are const (flash); the port, the application,
 * the service, the recorder's state and telemetry are on main's stack. The
 * statics are the documented exceptions to "no mutable globals", in the
 * board's BR_BOARD_XRAM (a NOLOAD section zeroed by the startup): the
 * particle filter's state (br_pf_t, ~71 KB: not for the 16 KiB stack), the
 * recorder's ring (BR_BOARD_REC_SAMPLES samples) and the USART's DMA buffers
 * (the DMA does not reach the tightly coupled RAM that holds the stack).
 * docs/modules/hal.md, docs/porting.md. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "br_board.h"
#include "bristle/br_app.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_rec.h"
#include "bristle/br_svc.h"
#include "bristle/br_tlm.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

/* The estimator is the first of the machine file's control.estimator that
 * the board runs: the PF in a loop at its own period (estimator.pf.period_s)
 * where BR_BOARD_RUNS_PF, the UKF and H-infinity only at control.period_s
 * (bristle_gen/machine/br_machine.h: each rank 1 first, 0 not listed). */
#if BR_BOARD_RUNS_PF && BR_MACHINE_EST_RANK_PF == 1
#define BR_IMAGE_USES_PF 1
#define BR_IMAGE_USES_UKF 0
#define BR_IMAGE_EST BR_APP_EST_PF
#define BR_IMAGE_DT_S BR_EST_PF_PERIOD_S_F
#define BR_IMAGE_PERIOD_NS BR_EST_PF_PERIOD_NS
#else
#define BR_IMAGE_USES_PF 0
#if BR_MACHINE_EST_RANK_UKF && (!BR_MACHINE_EST_RANK_NONE || BR_MACHINE_EST_RANK_UKF < BR_MACHINE_EST_RANK_NONE)
#define BR_IMAGE_USES_UKF 1
#define BR_IMAGE_EST BR_APP_EST_UKF
#elif BR_MACHINE_EST_RANK_NONE
#define BR_IMAGE_USES_UKF 0
#define BR_IMAGE_EST BR_APP_EST_NONE
#else
#error "control.estimator lists only pf: this board cannot run the PF in its period (BR_BOARD_RUNS_PF 0; docs/target.md); add ukf or none to the list, or build BOARD=stm32h7"
#endif
#define BR_IMAGE_DT_S BR_MACHINE_CTRL_PERIOD_S_F
#define BR_IMAGE_PERIOD_NS BR_MACHINE_CTRL_PERIOD_NS
#endif

/* The link (docs/link.md): a tlm_sample frame is 39 bytes on the wire, so
 * every BR_IMAGE_TLM_EVERY periods it takes 39 / (N T) bytes/s; kept below
 * half of the line's baud / 10 bytes/s (the rest for the reports, the
 * recorder's dump and the gaps between DMA transfers). */
#define BR_IMAGE_TLM_EVERY      2u
#define BR_IMAGE_TLM_FRAME_BYTES 39u
typedef char br_image_tlm_fits[(2ull * BR_IMAGE_TLM_FRAME_BYTES * 1000000000ull * 10ull <=
                                (unsigned long long)BR_BOARD_USART_BAUD * BR_IMAGE_TLM_EVERY * BR_IMAGE_PERIOD_NS)
                                   ? 1
                                   : -1];
/* the link's budgets: bytes decoded per period, the transmit queue */
#define BR_IMAGE_RX_BUDGET      64u
/* the USART's DMA buffers: RX 1024 bytes (11 ms at 921 600 baud: the host's
 * bursts between two periods), TX one transmit queue */
#define BR_IMAGE_UART_RX_BYTES  1024u
#define BR_IMAGE_UART_TX_BYTES  BR_LINK_TX_BUF_BYTES
/* status and ref_status every 100 periods */
#define BR_IMAGE_STATUS_PERIODS 100u
/* the reference queue: its length, and the periods an underrun holds the
 * last reference before braking */
#define BR_IMAGE_REFQ_LEN       BR_REFQ_MAX
#define BR_IMAGE_HOLD_PERIODS   20u
/* The recorder: the board's ring (BR_BOARD_REC_SAMPLES, BR_BOARD_REC_PRE
 * before the trigger); one dump frame per period. */
#define BR_IMAGE_REC_DUMP_FRAMES 1u

/* Deadline: more missed ticks than this since the arm turn the outputs off. */
#define BR_IMAGE_MAX_MISSED 2u

static const br_ctrl_cfg_t br_image_ctrl = BR_MACHINE_CTRL_CFG(BR_IMAGE_DT_S);

#if BR_IMAGE_USES_PF
static const br_pf_cfg_t br_image_pf_cfg = BR_MACHINE_PF_CFG_TUNED(BR_IMAGE_DT_S);
#elif BR_IMAGE_USES_UKF
static const br_ukf_cfg_t br_image_ukf_cfg = BR_MACHINE_UKF_CFG_TUNED(BR_IMAGE_DT_S);
#endif

#if BR_IMAGE_USES_PF
/* The documented exception: the PF's state, in the board's RAM (see above). */
static br_pf_t br_image_pf BR_BOARD_XRAM;
#endif
/* The recorder's ring and the USART's DMA buffers (see above). */
static br_rec_slot_t br_image_ring[BR_BOARD_REC_SAMPLES] BR_BOARD_XRAM;
static uint8_t br_image_uart_rx[BR_IMAGE_UART_RX_BYTES] BR_BOARD_XRAM;
static uint8_t br_image_uart_tx[BR_IMAGE_UART_TX_BYTES] BR_BOARD_XRAM;

/* The reference queue with the machine's limits; the underrun's fault comes
 * one period after the braking from the top speed (br_refq_init's rule). */
static br_refq_cfg_t br_image_refq(const br_app_motion_cfg_t *m)
{
    br_refq_cfg_t c = {BR_IMAGE_REFQ_LEN, BR_IMAGE_DT_S, BR_MACHINE_RAD_PER_COUNT_F, m->counts_per_m,
                       m->max_speed_mps, m->max_accel_mps2, BR_IMAGE_HOLD_PERIODS, 0u};
    c.fault_periods = BR_IMAGE_HOLD_PERIODS + (uint32_t)ceilf(c.max_speed_mps / (c.max_accel_mps2 * c.dt_s)) + 1u;
    return c;
}

/* Motor stopped and outputs off (br_stm32_pwm_disable); then park without
 * refreshing the watchdog: a running watchdog resets the part, which comes
 * up with its outputs off and stays off (br_board.reset_by_watchdog). */
static void br_image_halt(br_stm32_t *port) __attribute__((noreturn));
static void br_image_halt(br_stm32_t *port)
{
    (void)br_stm32_pwm_disable(port);
    for (;;) {
        __asm__ volatile("nop");
    }
}

int main(void)
{
    br_stm32_t port = {0};
    br_hal_t hal = {0};
    br_app_t app = {0};
    br_stm32_usart_chan_t uart = {0};
    br_byte_chan_t chan = {0};
    br_svc_t svc = {0};
    br_rec_t rec = {0};
    br_tlm_t tlm = {0};
    br_rec_sample_t sample = {0};
    uint32_t tick = 0u;
#if BR_IMAGE_USES_UKF
    br_ukf_t ukf = {0};
#endif
    const br_app_cfg_t app_cfg = {
        .ctrl = &br_image_ctrl,
        .est = BR_IMAGE_EST,
#if BR_IMAGE_USES_PF
        .pf = &br_image_pf_cfg,
#elif BR_IMAGE_USES_UKF
        .ukf = &br_image_ukf_cfg,
#endif
        .guard = br_app_guard_cfg(BR_IMAGE_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F),
        .motion = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE),
    };
#if BR_IMAGE_USES_PF
    const br_app_mem_t mem = {.pf = &br_image_pf};
#elif BR_IMAGE_USES_UKF
    const br_app_mem_t mem = {.ukf = &ukf};
#else
    const br_app_mem_t mem = {0};
#endif
    /* no enable input on this board: armed by the host's request only */
    const br_svc_cfg_t svc_cfg = {BR_IMAGE_RX_BUDGET, BR_LINK_TX_BUF_BYTES, br_image_refq(&app_cfg.motion),
                                  BR_IMAGE_STATUS_PERIODS, NULL, NULL};
    const br_rec_cfg_t rec_cfg = {br_image_ring, BR_BOARD_REC_SAMPLES, BR_BOARD_REC_PRE, 0.0f,
                                  BR_IMAGE_REC_DUMP_FRAMES};
    const br_tlm_cfg_t tlm_cfg = {BR_IMAGE_TLM_EVERY};

    if (br_stm32_board_init(&br_board, BR_IMAGE_PERIOD_NS, &port, &hal) != BR_OK || br_board.reset_by_watchdog() ||
        br_stm32_board_usart_init(&br_board, &uart, br_image_uart_rx, BR_IMAGE_UART_RX_BYTES, br_image_uart_tx,
                                  BR_IMAGE_UART_TX_BYTES, BR_IMAGE_PERIOD_NS) != BR_OK ||
        br_stm32_usart_chan(&uart, &chan) != BR_OK || br_stm32_board_watchdog_start(&br_board) != BR_OK ||
        br_app_init(&app, &app_cfg, &hal, &mem) != BR_OK ||
        br_svc_init(&svc, &svc_cfg, &app, &app_cfg, &mem, &chan) != BR_OK || br_rec_init(&rec, &rec_cfg) != BR_OK ||
        br_tlm_init(&tlm, &tlm_cfg) != BR_OK) {
        br_image_halt(&port);
    }
    for (;;) {
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_HAL);
            br_image_halt(&port);
        }
        /* missed ticks since the arm: the outputs off (by the check), the
         * fault latched, reported by the service this period */
        if (app.fault == BR_APP_FAULT_NONE && br_stm32_deadline_check(&port, BR_IMAGE_MAX_MISSED) != BR_OK) {
            (void)br_app_fault(&app, BR_APP_FAULT_DEADLINE);
        }
        /* BR_OK, BR_W_OUTLIER, or BR_E_FAULT while disarmed or faulted: the
         * loop goes on, the outputs off, the link alive */
        const br_status_t st = br_svc_step(&svc);
        (void)br_rec_command(&rec, &svc.cmd);
        (void)br_rec_sample_take(&sample, &app, tick, st);
        (void)br_tlm_step(&tlm, &svc.link, &sample);
        (void)br_rec_push(&rec, &sample);
        (void)br_rec_dump_step(&rec, &svc.link);
        br_stm32_board_watchdog_refresh(&br_board);
    }
}
