/* SPDX-License-Identifier: Apache-2.0 */
/* The link's and the recorder's cost on QEMU's Cortex-M7 (docs/link.md,
 * "Cost on the M7"; make target-bench, ctest target_link_deadline): the
 * STM32H743 image's production period (hal/stm32/image/br_image_cfg.h with the H743 board: its
 * estimator, period, link budgets, queue and recorder settings) on the bench
 * plant, each part timed with SysTick under -icount shift=0 as the other
 * bench images are (br_bench_clock.h):
 *
 *   br_svc_step          the link (one read, at most K bytes decoded), the
 *                        request, the reference, br_app_step, the reports;
 *                        br_app_step's own share is timed from the encoder
 *                        read to the PWM write (the HAL's calls) and taken
 *                        out: "svc" is the rest
 *   sample + br_tlm_step the period's sample, telemetry (every N periods)
 *   br_rec_push          the recorder's ring and triggers
 *   br_rec_command + br_rec_dump_step   the recorder's request, a dump chunk
 *
 * The host's side is a byte channel in memory that always holds bytes: a
 * cycle of frames (arm and rec_trigger first), each cycle a segment (holding
 * the start position, after the queue's last item), a live param_write, an
 * unknown id with the largest payload (its CRC checked), the same frame with
 * a bad CRC, a param_read, a setpoint, a rec_dump(0) (a dump always under
 * way once the capture is complete); the transmit side takes every byte (a
 * line fast enough for telemetry at the control rate). Frames are encoded
 * between the periods, outside the stamps.
 *
 *   qemu-system-arm -M mps2-an500 -nographic -monitor none -serial none -icount shift=0 \
 *     -semihosting-config enable=on,target=native,arg=link-bench,arg=PERIODS,arg=TLM_EVERY \
 *     -kernel br_link_bench_mps2.elf
 *
 * PERIODS 100..100000; TLM_EVERY 1..1000 (0: the image's BR_IMAGE_TLM_EVERY).
 * Prints the calibration line, "link_bench periods=... tlm_every=...
 * period_ns=... cpu_hz=..." (the period and the STM32H743's clock, from
 * their headers), one "part NAME n=... sum_ticks=... max_ticks=..." per part
 * (periods k >= 1; dump: the periods a dump chunk was queued in), the
 * counters and "hold outliers=... max_abs_counts=..." (periods k >= 1: the
 * steps whose measurement the estimator rejected, BR_W_OUTLIER, and the
 * axis's largest |count|; every request holds it at its start, 0.5 counts);
 * exit 0, or 1 on a fault, a failed init or a bad command line. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "br_bench_clock.h"
#include "br_bench_plant.h"
#include "br_image_cfg.h"
#include "br_le.h"
#include "br_semihost.h"
#include "bristle/br_app.h"
#include "bristle/br_link_pil.h"
#include "bristle/br_machine_cfg.h"
#include "bristle/br_rec.h"
#include "bristle/br_stm32h7.h"
#include "bristle/br_svc.h"
#include "bristle/br_tlm.h"
#include "bristle_gen/ctrl/br_hinf_gains.h"
#include "bristle_gen/link/br_link_params.h"

#define BENCH_WIRE_BYTES 1024u
#define BENCH_SEG_PERIODS 32u
#define BENCH_REC_CAPACITY 400u /* the ring's work per sample does not depend on its size */
#define BENCH_REC_PRE 200u
#define BENCH_UNKNOWN_ID 0x7Fu
#define BENCH_CYCLE_MAX_BYTES (7u * BR_LINK_FRAME_MAX) /* the seven frames of host_cycle */

typedef enum { PART_SVC, PART_APP, PART_TLM, PART_REC, PART_DUMP, PART_TOTAL, PART_N } part_t;
static const char *const part_name[PART_N] = {"svc", "app", "tlm", "rec", "dump", "total"};

typedef struct {
    uint32_t n, sum, max;
} stat_t;

/* the host's bytes: wire[rd..wr) not yet read by the link */
typedef struct {
    uint8_t wire[BENCH_WIRE_BYTES];
    uint32_t rd, wr;
    uint16_t seq;
    uint32_t tx_bytes;
} host_t;

/* the HAL over the plant, stamping the application's first and last call */
typedef struct {
    br_bench_plant_t plant;
    br_bench_clock_t *clk;
    uint32_t t_enc, t_pwm;
} bench_io_t;

static br_status_t io_enc(void *ctx, int32_t *counts)
{
    bench_io_t *io = ctx;
    io->t_enc = br_bench_clock_stamp(io->clk);
    return br_bench_plant_enc_read(&io->plant, counts);
}

static br_status_t io_pwm(void *ctx, float duty)
{
    bench_io_t *io = ctx;
    const br_status_t st = br_bench_plant_pwm_write(&io->plant, duty);
    io->t_pwm = br_bench_clock_stamp(io->clk);
    return st;
}

static size_t chan_read(void *ctx, uint8_t *buf, size_t n)
{
    host_t *h = ctx;
    const uint32_t have = h->wr - h->rd;
    const size_t k = (n < have) ? n : have;
    memcpy(buf, &h->wire[h->rd], k);
    h->rd += (uint32_t)k;
    return k;
}

static size_t chan_write(void *ctx, const uint8_t *buf, size_t n)
{
    (void)buf;
    ((host_t *)ctx)->tx_bytes += (uint32_t)n;
    return n;
}

static void fail(const char *msg)
{
    br_sh_fail("br_link_bench_mps2", msg);
}

/* appends one frame (the next seq); returns where it starts in the wire */
static uint32_t host_send(host_t *h, uint8_t id, const uint8_t *p, size_t len)
{
    size_t n = 0u;
    const uint32_t at = h->wr;
    if (br_link_encode(&h->wire[h->wr], BENCH_WIRE_BYTES - h->wr, id, h->seq++, p, len, &n) != BR_OK) {
        fail("frame encoding failed");
    }
    h->wr += (uint32_t)n;
    return at;
}

/* one cycle of the frame mix (above); next_tick: the first period free in the queue */
static void host_cycle(host_t *h, uint32_t next_tick)
{
    uint8_t p[BR_LINK_PAYLOAD_MAX];
    memset(p, 0, sizeof p);
    br_le_put(&p[BR_LINK_MSG_SEGMENT_OFF_TICK], next_tick, 4u);
    br_le_put(&p[BR_LINK_MSG_SEGMENT_OFF_PERIODS], BENCH_SEG_PERIODS, 4u);
    br_le_put_f32(&p[BR_LINK_MSG_SEGMENT_OFF_FRAC], 0.5f);
    (void)host_send(h, BR_LINK_MSG_SEGMENT, p, BR_LINK_MSG_SEGMENT_LEN);
    br_le_put(&p[BR_LINK_MSG_PARAM_WRITE_OFF_PARAM], BR_LINK_PARAM_COMP_AHEAD_PERIODS, 2u);
    br_le_put_f32(&p[BR_LINK_MSG_PARAM_WRITE_OFF_VALUE], 1.0f);
    (void)host_send(h, BR_LINK_MSG_PARAM_WRITE, p, BR_LINK_MSG_PARAM_WRITE_LEN);
    memset(p, 0x55, sizeof p); /* no zero byte: one COBS block */
    (void)host_send(h, BENCH_UNKNOWN_ID, p, BR_LINK_PAYLOAD_MAX);
    const uint32_t bad = host_send(h, BENCH_UNKNOWN_ID, p, BR_LINK_PAYLOAD_MAX);
    h->wire[bad + 10u] ^= 0x01u; /* a payload byte 0x55 -> 0x54: the CRC fails */
    memset(p, 0, sizeof p);
    br_le_put(&p[BR_LINK_MSG_PARAM_READ_OFF_PARAM], BR_LINK_PARAM_R_COUNTS2, 2u);
    (void)host_send(h, BR_LINK_MSG_PARAM_READ, p, BR_LINK_MSG_PARAM_READ_LEN);
    const br_refq_item_t sp = {BR_REFQ_SETPOINT, 0u, next_tick + BENCH_SEG_PERIODS, 1u, 0, 0.5f, 0.0f, 0.0f, 0.0f};
    br_link_setpoint_pack(p, &sp);
    (void)host_send(h, BR_LINK_MSG_SETPOINT, p, BR_LINK_MSG_SETPOINT_LEN);
    memset(p, 0, sizeof p);
    (void)host_send(h, BR_LINK_MSG_REC_DUMP, p, BR_LINK_MSG_REC_DUMP_LEN);
}

/* keeps at least half the wire's bytes unread (a step reads at most K = 64) */
static void host_refill(host_t *h, const br_svc_t *svc)
{
    if (h->wr - h->rd >= BENCH_WIRE_BYTES / 2u) {
        return;
    }
    memmove(h->wire, &h->wire[h->rd], h->wr - h->rd);
    h->wr -= h->rd;
    h->rd = 0u;
    const uint32_t t = svc->ref.have_end ? svc->ref.end_tick : svc->tick + 1u;
    while (h->wr + BENCH_CYCLE_MAX_BYTES <= BENCH_WIRE_BYTES) {
        host_cycle(h, (t > svc->tick + 1u) ? t : svc->tick + 1u);
    }
}

static void stat_add(stat_t *s, uint32_t v)
{
    ++s->n;
    s->sum += v;
    s->max = (v > s->max) ? v : s->max;
}

/* "link-bench PERIODS TLM_EVERY" */
static void parse_args(uint32_t *periods, uint32_t *tlm_every)
{
    char cmd[128];
    char *end = 0;
    if (br_sh_cmdline(cmd, (uint32_t)sizeof cmd) != 0) fail("no command line");
    const char *a = strchr(cmd, ' ');
    if (a == 0) fail("usage: link-bench PERIODS TLM_EVERY");
    const unsigned long p = strtoul(a + 1, &end, 10);
    const unsigned long e = strtoul(end, &end, 10);
    if (*end != '\0' || p < 100ul || p > 100000ul || e > 1000ul) fail("usage: link-bench PERIODS TLM_EVERY");
    *periods = (uint32_t)p;
    *tlm_every = (e == 0ul) ? BR_IMAGE_TLM_EVERY : (uint32_t)e;
}

int main(void)
{
    uint32_t periods = 0u, tlm_every = 0u;
    parse_args(&periods, &tlm_every);
    br_bench_clock_t clk;
    br_bench_clock_start(&clk);

    const br_ctrl_cfg_t cc = {BR_HINF_K, BR_IMAGE_DT_S, BR_MACHINE_TORQUE_LIMIT_NM_F, BR_MACHINE_TAU_PER_DUTY_NM_F,
                              BR_MACHINE_RAD_PER_COUNT_F, BR_MACHINE_LEAD_MPRAD_F};
    const br_pf_cfg_t pfc = BR_MACHINE_PF_CFG_TUNED(BR_IMAGE_DT_S);
    const br_ukf_cfg_t ukc = BR_MACHINE_UKF_CFG_TUNED(BR_IMAGE_DT_S);
    br_pf_t pf;
    br_ukf_t ukf;
    const br_est_t no_ext = {0, 0, 0, 0};
    const br_app_motion_cfg_t mc = br_app_motion_cfg(&(const br_app_machine_t)BR_MACHINE_APP_MACHINE);
    const br_app_cfg_t ac = {&cc, BR_IMAGE_EST, &pfc, &ukc, &no_ext,
                             br_app_guard_cfg(BR_IMAGE_DT_S, BR_MACHINE_MAX_SPEED_COUNTS_PER_S_F), mc};
    const br_app_mem_t mem = {BR_IMAGE_USES_PF ? &pf : 0, BR_IMAGE_USES_UKF ? &ukf : 0};
    bench_io_t io;
    io.clk = &clk;
    io.t_enc = io.t_pwm = 0u;
    const br_hal_t hal = {&io, io_enc, io_pwm, br_bench_plant_tick_wait, 0, 0};
    host_t host;
    host.rd = host.wr = host.tx_bytes = 0u;
    host.seq = 1u;
    const br_byte_chan_t chan = {&host, chan_read, chan_write};
    const br_svc_cfg_t sc = {BR_IMAGE_RX_BUDGET, BR_LINK_TX_BUF_BYTES, br_image_refq(&mc), BR_IMAGE_STATUS_PERIODS, 0, 0,
                             BR_MACHINE_NAME};
    br_rec_slot_t slots[BENCH_REC_CAPACITY];
    const br_rec_cfg_t rc = {slots, BENCH_REC_CAPACITY, BENCH_REC_PRE, 0.0f, BR_IMAGE_REC_DUMP_FRAMES};
    const br_tlm_cfg_t tc = {tlm_every};
    br_app_t app;
    br_svc_t svc;
    br_tlm_t tlm;
    br_rec_t rec;
    if (br_bench_plant_init(&io.plant, BR_IMAGE_DT_S) != BR_OK || br_app_init(&app, &ac, &hal, &mem) != BR_OK ||
        br_svc_init(&svc, &sc, &app, &ac, &mem, &chan) != BR_OK ||
        br_tlm_init(&tlm, &tc) != BR_OK || br_rec_init(&rec, &rc) != BR_OK) {
        fail("firmware init failed");
    }
    (void)host_send(&host, BR_LINK_MSG_ARM, 0, 0u);
    (void)host_send(&host, BR_LINK_MSG_REC_TRIGGER, 0, 0u);

    stat_t st[PART_N];
    memset(st, 0, sizeof st);
    uint32_t n_outlier = 0u, max_abs_counts = 0u; /* the held axis: the filter's rejections, its excursion */
    for (uint32_t k = 0u; k < periods; ++k) {
        if (br_bench_plant_period(&io.plant) != BR_OK) {
            fail("the bench plant's step failed");
        }
        host_refill(&host, &svc);
        const uint32_t t0 = br_bench_clock_stamp(&clk);
        const br_status_t s = br_svc_step(&svc);
        const uint32_t t1 = br_bench_clock_stamp(&clk);
        br_rec_sample_t smp;
        (void)br_rec_sample_take(&smp, &app, k, s);
        (void)br_tlm_step(&tlm, &svc.link, &smp);
        const uint32_t t2 = br_bench_clock_stamp(&clk);
        (void)br_rec_push(&rec, &smp);
        const uint32_t t3 = br_bench_clock_stamp(&clk);
        const uint32_t frames1 = svc.link.dec.cnt.tx_frames;
        (void)br_rec_command(&rec, &svc.cmd);
        const int dumping = rec.dump_active;
        (void)br_rec_dump_step(&rec, &svc.link);
        const uint32_t t4 = br_bench_clock_stamp(&clk);
        if (k > 0u && app.fault != BR_APP_FAULT_NONE) {
            br_bench_say_u32("br_link_bench_mps2: fault ", (uint32_t)app.fault);
            br_bench_say_u32(" at period ", k);
            br_sh_puts("\n");
            br_sh_exit(1u);
        }
        if (k == 0u) {
            continue; /* the arm, the filter's first step */
        }
        n_outlier += (s == BR_W_OUTLIER) ? 1u : 0u;
        const uint32_t ax = (io.plant.counts < 0) ? 0u - (uint32_t)io.plant.counts : (uint32_t)io.plant.counts;
        max_abs_counts = (ax > max_abs_counts) ? ax : max_abs_counts;
        const uint32_t app_t = io.t_pwm - io.t_enc;
        stat_add(&st[PART_APP], app_t);
        stat_add(&st[PART_SVC], (t1 - t0) - app_t);
        stat_add(&st[PART_TLM], t2 - t1);
        stat_add(&st[PART_REC], t3 - t2);
        if (dumping && svc.link.dec.cnt.tx_frames != frames1) {
            stat_add(&st[PART_DUMP], t4 - t3);
        }
        stat_add(&st[PART_TOTAL], t4 - t0);
    }
    br_bench_say_u32("link_bench periods=", periods);
    br_bench_say_u32(" tlm_every=", tlm_every);
    br_bench_say_u32(" period_ns=", BR_IMAGE_PERIOD_NS);
    br_bench_say_u32(" cpu_hz=", BR_STM32H7_SYSCLK_HZ);
    br_sh_puts("\n");
    for (int i = 0; i < PART_N; ++i) {
        br_sh_puts("part ");
        br_sh_puts(part_name[i]);
        br_bench_say_u32(" n=", st[i].n);
        br_bench_say_u32(" sum_ticks=", st[i].sum);
        br_bench_say_u32(" max_ticks=", st[i].max);
        br_sh_puts("\n");
    }
    br_bench_say_u32("counters rx_frames=", svc.link.dec.cnt.rx_frames);
    br_bench_say_u32(" rx_bad_crc=", svc.link.dec.cnt.rx_bad_crc);
    br_bench_say_u32(" rx_unknown_id=", svc.link.dec.cnt.rx_unknown_id);
    br_bench_say_u32(" tx_frames=", svc.link.dec.cnt.tx_frames);
    br_bench_say_u32(" tx_busy=", svc.link.dec.cnt.tx_busy);
    br_bench_say_u32(" tlm_dropped=", tlm.n_dropped);
    br_bench_say_u32(" ref_dropped=", svc.ref.cnt.dropped);
    br_bench_say_u32(" rec_state=", (uint32_t)rec.state);
    br_sh_puts("\n");
    br_bench_say_u32("hold outliers=", n_outlier);
    br_bench_say_u32(" max_abs_counts=", max_abs_counts);
    br_sh_puts("\n");
    br_sh_exit(0u);
}
