/* SPDX-License-Identifier: Apache-2.0 */
/* The image in the loop on QEMU's mps2-an500 (Cortex-M7, FPU; docs/link.md,
 * "The image in the loop"): one axis of the production application, br_app
 * with the machine's guards and drive protections behind the command service
 * (br_svc), telemetry (br_tlm) and the recorder (br_rec), run as the
 * STM32H743 image runs them, with two of the board's CMSDK UARTs:
 *
 *   UART0 (0x40004000): the link (arm, setpoints, reports, telemetry, dumps)
 *   UART1 (0x40005000): the plant port (br_pil_port): the host's tick and
 *                       encoder count in, the period's duty out
 *
 *   qemu-system-arm -M mps2-an500 -display none -monitor none \
 *     -serial pipe:LINK -serial pipe:PLANT \
 *     -semihosting-config enable=on,target=native,arg=pil,arg=EST -kernel br_pil_mps2.elf
 *
 * EST: none (H-inf only), ukf or pf, with the simulator's circle's
 * configuration (sim/lib/circle: the machine's H-inf gains at its period, the
 * tuned filter on the machine file's model, 1.5 ms for the PF); the axis starts
 * disarmed, as the production image does. One period per pil_tick: tick_wait
 * (the lockstep), br_svc_step, the sample to telemetry and the recorder, the
 * recorder's requests and dump, then the pil_out. Exits (semihosting, status
 * 1) only when the host stops sending ticks. All state is in main's frame
 * (no mutable globals); mps2_an500.ld reserves a 512 KiB stack. */
#include <stdint.h>
#include <string.h>

#include "br_semihost.h"
#include "bristle/br_app.h"
#include "bristle/br_cmsdk_uart.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_pil_port.h"
#include "bristle/br_rec.h"
#include "bristle/br_svc.h"
#include "bristle/br_tlm.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/est/br_est_machine.h"
#include "bristle_gen/machine/br_machine.h"

#define BR_MPS2_UART0 ((br_cmsdk_uart_regs_t *)0x40004000u)
#define BR_MPS2_UART1 ((br_cmsdk_uart_regs_t *)0x40005000u)
#define BR_PIL_BAUDDIV 16u          /* the fastest the UART allows (QEMU does not pace it) */
#define BR_PIL_RX_RING 1024u
#define BR_PIL_TX_RING 1024u
#define BR_PIL_WAIT_POLLS 0xFFFFFFFFu /* a host silent for this many polls is gone */
#define BR_PIL_TLM_EVERY 10u
#define BR_PIL_STATUS_PERIODS 100u
#define BR_PIL_REC_CAPACITY 2000u
#define BR_PIL_HOLD_PERIODS 20u

typedef enum { EST_NONE, EST_UKF, EST_PF } est_t;

static void fail(const char *msg)
{
    br_sh_fail("br_pil_mps2", msg);
}

/* the estimator named on the command line ("pil EST") */
static est_t parse_est(void)
{
    char cmd[128];
    if (br_sh_cmdline(cmd, (uint32_t)sizeof cmd) != 0) fail("no command line");
    const char *e = strchr(cmd, ' ');
    e = (e == 0) ? "" : e + 1;
    if (strcmp(e, "none") == 0) return EST_NONE;
    if (strcmp(e, "ukf") == 0) return EST_UKF;
    if (strcmp(e, "pf") == 0) return EST_PF;
    fail("usage: pil none|ukf|pf");
    return EST_NONE;
}

int main(void)
{
    const est_t est = parse_est();
    /* the circle's period: the PF's own (thesis section 5), the machine's for the others */
    const float dt = (est == EST_PF) ? (float)BR_EST_PF_PERIOD_S : BR_MACHINE_CTRL_PERIOD_S_F;
    const br_ctrl_cfg_t cc = BR_MACHINE_CTRL_CFG(dt);
    br_pf_cfg_t pfc = BR_MACHINE_PF_CFG_TUNED(dt);
    br_ukf_cfg_t ukc = BR_MACHINE_UKF_CFG_TUNED(dt);
    /* the model's causes are the machine file's (BR_MACHINE_CAUSES), as the STM32H743 image's: none for
     * the reference machine (the circle's thesis model, so --compare holds bit for bit), a diagnosis's
     * for its machine.json (docs/link.md, "The chain on a running target") */
    br_pf_t pf;
    br_ukf_t ukf;
    const br_app_motion_cfg_t mc = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE);
    const br_est_t no_ext = {0, 0, 0, 0};
    const br_app_cfg_t ac = {&cc, est == EST_PF ? BR_APP_EST_PF : est == EST_UKF ? BR_APP_EST_UKF : BR_APP_EST_NONE,
                             &pfc, &ukc, &no_ext, br_app_guard_cfg(dt, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F), mc};
    const br_app_mem_t mem = {est == EST_PF ? &pf : 0, est == EST_UKF ? &ukf : 0};

    uint8_t link_rx[BR_PIL_RX_RING], link_tx[BR_PIL_TX_RING], plant_rx[BR_PIL_RX_RING], plant_tx[BR_PIL_TX_RING];
    br_cmsdk_uart_t link_uart, plant_uart;
    br_byte_chan_t link_chan, plant_chan;
    const br_cmsdk_uart_cfg_t lu = {BR_MPS2_UART0, link_rx, BR_PIL_RX_RING, link_tx, BR_PIL_TX_RING, BR_PIL_BAUDDIV};
    const br_cmsdk_uart_cfg_t pu = {BR_MPS2_UART1, plant_rx, BR_PIL_RX_RING, plant_tx, BR_PIL_TX_RING,
                                    BR_PIL_BAUDDIV};
    if (br_cmsdk_uart_init(&link_uart, &lu, &link_chan) != BR_OK ||
        br_cmsdk_uart_init(&plant_uart, &pu, &plant_chan) != BR_OK) {
        fail("UART init failed");
    }
    br_pil_port_t port;
    br_hal_t hal;
    const br_pil_port_cfg_t pc = {&plant_uart, plant_chan, &link_uart, BR_PIL_WAIT_POLLS};
    if (br_pil_port_init(&port, &pc, &hal) != BR_OK) fail("port init failed");

    /* the reference queue as br_link_sim's: the fault one period after the braking from the top speed */
    const uint32_t brake = (uint32_t)(mc.max_speed_mps / (mc.max_accel_mps2 * dt)) + 1u;
    const br_refq_cfg_t q = {BR_REFQ_MAX, dt, BR_MACHINE_RAD_PER_COUNT_F, mc.counts_per_m, mc.max_speed_mps,
                             mc.max_accel_mps2, BR_PIL_HOLD_PERIODS, BR_PIL_HOLD_PERIODS + brake + 1u};
    const br_svc_cfg_t sc = {BR_LINK_RX_BUDGET_MAX, BR_LINK_TX_BUF_BYTES, q, BR_PIL_STATUS_PERIODS, 0, 0, BR_MACHINE_NAME};
    const br_tlm_cfg_t tc = {BR_PIL_TLM_EVERY};
    br_rec_slot_t slots[BR_PIL_REC_CAPACITY];
    const br_rec_cfg_t rc = {slots, BR_PIL_REC_CAPACITY, BR_PIL_REC_CAPACITY / 2u, 0.0f, 2u};
    br_app_t app;
    br_svc_t svc;
    br_tlm_t tlm;
    br_rec_t rec;
    if (br_app_init(&app, &ac, &hal, &mem) != BR_OK || br_svc_init(&svc, &sc, &app, &ac, &mem, &link_chan) != BR_OK ||
        br_tlm_init(&tlm, &tc) != BR_OK || br_rec_init(&rec, &rc) != BR_OK) {
        fail("firmware init failed");
    }
    for (;;) {
        uint32_t tick;
        if (hal.tick_wait(hal.ctx, &tick) != BR_OK) fail("no tick from the host");
        const br_status_t st = br_svc_step(&svc);
        br_rec_sample_t s;
        (void)br_rec_sample_take(&s, &app, tick, st);
        (void)br_tlm_step(&tlm, &svc.link, &s); /* a drop is counted */
        (void)br_rec_push(&rec, &s);
        (void)br_rec_command(&rec, &svc.cmd);
        (void)br_rec_dump_step(&rec, &svc.link);
        if (br_pil_port_report(&port, &s) != BR_OK) fail("the plant port could not take the output");
    }
}
