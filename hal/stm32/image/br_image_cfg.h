/* SPDX-License-Identifier: Apache-2.0 */
/* The STM32 image's settings (hal/stm32/image/br_image_main.c, docs/link.md
 * "The STM32H743 image", docs/porting.md): its estimator and period on the
 * board (br_board.h), the link's budgets, telemetry's decimation, the
 * reference queue and the recorder. One home: the image and the link's cost
 * bench on QEMU's Cortex-M7 (target/mps2/link_bench_main.c, make
 * target-bench, with the STM32H743 board's br_board.h) include it, so the
 * bench runs the period as shipped. Needs bristle_gen/machine/br_machine.h
 * and bristle_gen/est/br_est_machine.h. */
#ifndef BR_IMAGE_CFG_H
#define BR_IMAGE_CFG_H

#include <stdint.h>

#include "br_board.h"
#include "bristle/br_app.h"
#include "bristle/br_link.h"
#include "bristle/br_refq.h"
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

/* The reference queue with the machine's limits; the underrun's fault comes
 * one period after the braking from the top speed (br_refq_fault_periods_min). */
static inline br_refq_cfg_t br_image_refq(const br_app_motion_cfg_t *m)
{
    br_refq_cfg_t c = {BR_IMAGE_REFQ_LEN, BR_IMAGE_DT_S, BR_MACHINE_RAD_PER_COUNT_F, m->counts_per_m,
                       m->max_speed_mps, m->max_accel_mps2, BR_IMAGE_HOLD_PERIODS, 0u};
    c.fault_periods = br_refq_fault_periods_min(&c);
    return c;
}

#endif
