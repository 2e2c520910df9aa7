/* SPDX-License-Identifier: Apache-2.0 */
/* The USART byte channel (hal/stm32, bristle/br_stm32_usart.h) against fake
 * register blocks in RAM, and the link over it (docs/porting.md, "The USART
 * channel"); each part's DMA side is a case of the port suite
 * (test_stm32_port.c, port_<part>.c).
 *
 * A fake block is plain memory: the DMA does not run, so the test plays it:
 * it writes received bytes into the circular buffer and lowers NDTR as the
 * stream would, sets ISR flags, and sets NDTR to 0 for a finished transfer. */
#include "br_test.h"

#include <string.h>

#include "bristle/br_link.h"
#include "bristle/br_stm32_usart.h"

#define RX_LEN 32u
#define TX_LEN 16u
/* made-up CR words: the shared driver copies them, EN aside */
#define RX_CR 0x0510u
#define TX_CR 0x0440u
#define IFCR_MASK 0x0F40u

typedef struct {
    br_stm32_usart_t usart;
    br_stm32_dma_ch_t rx;
    br_stm32_dma_ch_t tx;
    uint32_t ifcr;
} fake_t;

typedef struct {
    fake_t f;
    uint8_t rx_buf[RX_LEN];
    uint8_t tx_buf[TX_LEN];
    br_stm32_usart_chan_t u;
} rig_t;

/* The H7 board's USART3: 120 MHz kernel clock, 115 200 baud, read every 1 ms
 * (12 bytes: a 32-byte buffer holds more than twice that). */
static br_stm32_usart_cfg_t cfg_for(rig_t *g)
{
    br_stm32_usart_cfg_t c;
    memset(&c, 0, sizeof c);
    c.usart = &g->f.usart;
    c.rx_dma = &g->f.rx;
    c.tx_dma = &g->f.tx;
    c.tx_dma_ifcr = &g->f.ifcr;
    c.tx_dma_ifcr_mask = IFCR_MASK;
    c.rx_dma_cr = RX_CR;
    c.tx_dma_cr = TX_CR;
    c.rx_buf = g->rx_buf;
    c.rx_len = RX_LEN;
    c.tx_buf = g->tx_buf;
    c.tx_len = TX_LEN;
    c.kernel_clock_hz = 120000000u;
    c.baud = 115200u;
    c.poll_period_ns = 1000000u;
    return c;
}

static void rig_up(rig_t *g)
{
    memset(g, 0, sizeof *g);
    const br_stm32_usart_cfg_t c = cfg_for(g);
    assert_int_equal(br_stm32_usart_init(&g->u, &c), BR_OK);
}

/* the DMA receiving bytes: into the buffer at its write position, NDTR down
 * (reloaded to RX_LEN at 0, as circular mode does) */
static void dma_receive(rig_t *g, const uint8_t *b, size_t n)
{
    for (size_t i = 0u; i < n; ++i) {
        const uint32_t wr = RX_LEN - g->f.rx.NDTR;
        g->rx_buf[wr] = b[i];
        g->f.rx.NDTR = (g->f.rx.NDTR == 1u) ? RX_LEN : g->f.rx.NDTR - 1u;
    }
}

static uint32_t addr32(const volatile void *p)
{
    return (uint32_t)(uintptr_t)p;
}

static void test_init_programs_registers(void **st)
{
    (void)st;
    rig_t g;
    g.f.ifcr = 0u;
    rig_up(&g);
    /* BRR = round(120 MHz / 115 200) = round(1041.7) */
    assert_int_equal(g.f.usart.BRR, 1042u);
    assert_int_equal(g.f.usart.CR1, BR_USART_CR1_UE | BR_USART_CR1_RE | BR_USART_CR1_TE);
    assert_int_equal(g.f.usart.CR2, 0u);
    assert_int_equal(g.f.usart.CR3, BR_USART_CR3_DMAR | BR_USART_CR3_DMAT);
    assert_int_equal(g.f.rx.PAR, addr32(&g.f.usart.RDR));
    assert_int_equal(g.f.rx.MAR, addr32(g.rx_buf));
    assert_int_equal(g.f.rx.NDTR, RX_LEN);
    assert_int_equal(g.f.rx.CR, RX_CR | BR_DMA_CR_EN);
    assert_int_equal(g.f.tx.PAR, addr32(&g.f.usart.TDR));
    assert_int_equal(g.f.tx.NDTR, 0u);
    assert_int_equal(g.f.tx.CR, TX_CR); /* not started */
    assert_int_equal(g.f.ifcr, IFCR_MASK);
}

/* each refused configuration leaves every register as it was */
static void expect_refused(br_stm32_usart_cfg_t c, rig_t *g, br_status_t want)
{
    fake_t before;
    memset(&g->f, 0xA5, sizeof g->f);
    g->f.rx.CR &= ~BR_DMA_CR_EN; /* a stream that stops when asked */
    g->f.tx.CR &= ~BR_DMA_CR_EN;
    memcpy(&before, &g->f, sizeof before);
    br_stm32_usart_chan_t u;
    assert_int_equal(br_stm32_usart_init(&u, &c), want);
    assert_memory_equal(&before, &g->f, sizeof before);
    uint8_t b[4];
    assert_int_equal(br_stm32_usart_read(&u, b, sizeof b), 0u);
    assert_int_equal(br_stm32_usart_write(&u, b, sizeof b), 0u);
    br_byte_chan_t ch;
    assert_int_equal(br_stm32_usart_chan(&u, &ch), BR_E_STATE);
}

static void test_init_guards(void **st)
{
    (void)st;
    rig_t g;
    memset(&g, 0, sizeof g);
    br_stm32_usart_chan_t u;
    const br_stm32_usart_cfg_t ok = cfg_for(&g);
    br_stm32_usart_cfg_t c;
    assert_int_equal(br_stm32_usart_init(NULL, &ok), BR_E_NULL);
    assert_int_equal(br_stm32_usart_init(&u, NULL), BR_E_NULL);
    c = ok; c.usart = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.rx_dma = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.tx_dma = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.tx_dma_ifcr = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.rx_buf = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.tx_buf = NULL; expect_refused(c, &g, BR_E_NULL);
    c = ok; c.tx_dma = c.rx_dma; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.rx_len = 1u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.rx_len = BR_DMA_NDTR_MAX + 1u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.tx_len = 0u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.tx_len = BR_DMA_NDTR_MAX + 1u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.poll_period_ns = 0u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.rx_dma_cr |= BR_DMA_CR_EN; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.tx_dma_cr |= BR_DMA_CR_EN; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.baud = 0u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.kernel_clock_hz = 0u; expect_refused(c, &g, BR_E_PARAM);
    /* BRR below 16: 120 MHz / 8 Mbaud = 15 */
    c = ok; c.baud = 8000000u; expect_refused(c, &g, BR_E_PARAM);
    /* BRR above 0xFFFF: 120 MHz / 1 800 baud = 66 667 */
    c = ok; c.baud = 1800u; expect_refused(c, &g, BR_E_PARAM);
    /* 2.4 % off: 1 MHz / 61 000 baud rounds to 16, 62 500 baud */
    c = ok; c.kernel_clock_hz = 1000000u; c.baud = 61000u; expect_refused(c, &g, BR_E_PARAM);
    /* 1.6 % off is within the tolerance: 1 MHz / 63 500 -> 16 */
    c = ok; c.kernel_clock_hz = 1000000u; c.baud = 63500u; c.rx_len = 16u;
    assert_int_equal(br_stm32_usart_init(&u, &c), BR_OK);
    /* 1 ms at 115 200 baud brings 12 bytes (11.52): 24 is the least buffer */
    c = ok; c.rx_len = 23u; expect_refused(c, &g, BR_E_PARAM);
    c = ok; c.rx_len = 24u;
    assert_int_equal(br_stm32_usart_init(&u, &c), BR_OK);
}

/* a byte the DMA wrote into the buffer comes out of read, once */
static void test_read_one_byte(void **st)
{
    (void)st;
    rig_t g;
    rig_up(&g);
    uint8_t b[8] = {0};
    assert_int_equal(br_stm32_usart_read(&g.u, b, sizeof b), 0u);
    const uint8_t x = 0x5Au;
    dma_receive(&g, &x, 1u);
    assert_int_equal(br_stm32_usart_read(&g.u, b, sizeof b), 1u);
    assert_int_equal(b[0], 0x5Au);
    assert_int_equal(br_stm32_usart_read(&g.u, b, sizeof b), 0u);
    assert_int_equal(g.u.cnt.rx_bytes, 1u);
}

/* across the circular buffer's end, in order; a short read leaves the rest */
static void test_read_wraps(void **st)
{
    (void)st;
    rig_t g;
    rig_up(&g);
    uint8_t in[RX_LEN];
    uint8_t out[RX_LEN];
    for (uint32_t i = 0u; i < RX_LEN; ++i) in[i] = (uint8_t)(i + 1u);
    dma_receive(&g, in, RX_LEN - 2u); /* write position 30 */
    assert_int_equal(br_stm32_usart_read(&g.u, out, sizeof out), RX_LEN - 2u);
    assert_memory_equal(out, in, RX_LEN - 2u);
    const uint8_t w[5] = {0xA0u, 0xA1u, 0xA2u, 0xA3u, 0xA4u};
    dma_receive(&g, w, sizeof w); /* 30, 31, then 0, 1, 2 */
    assert_int_equal(g.f.rx.NDTR, RX_LEN - 3u);
    assert_int_equal(br_stm32_usart_read(&g.u, out, 2u), 2u);
    assert_memory_equal(out, w, 2u);
    assert_int_equal(br_stm32_usart_read(&g.u, out, sizeof out), 3u);
    assert_memory_equal(out, &w[2], 3u);
    /* many laps of the buffer, each read in pieces */
    for (uint32_t k = 0u; k < 100u; ++k) {
        uint8_t v[7];
        for (uint32_t i = 0u; i < sizeof v; ++i) v[i] = (uint8_t)(k * 7u + i);
        dma_receive(&g, v, sizeof v);
        assert_int_equal(br_stm32_usart_read(&g.u, out, 4u), 4u);
        assert_int_equal(br_stm32_usart_read(&g.u, &out[4], 4u), 3u);
        assert_memory_equal(out, v, sizeof v);
    }
    /* a count a running circular stream never shows: nothing read */
    g.f.rx.NDTR = 0u;
    assert_int_equal(br_stm32_usart_read(&g.u, out, sizeof out), 0u);
    g.f.rx.NDTR = RX_LEN + 1u;
    assert_int_equal(br_stm32_usart_read(&g.u, out, sizeof out), 0u);
}

/* ORE, FE and NE counted at a read, their flags cleared */
static void test_line_errors_counted(void **st)
{
    (void)st;
    rig_t g;
    rig_up(&g);
    uint8_t b[4];
    g.f.usart.ICR = 0u;
    g.f.usart.ISR = BR_USART_ISR_ORE;
    (void)br_stm32_usart_read(&g.u, b, sizeof b);
    assert_int_equal(g.u.cnt.rx_overruns, 1u);
    assert_int_equal(g.u.cnt.rx_errors, 0u);
    assert_true((g.f.usart.ICR & BR_USART_ICR_ORECF) != 0u);
    g.f.usart.ISR = BR_USART_ISR_FE;
    (void)br_stm32_usart_read(&g.u, b, sizeof b);
    g.f.usart.ISR = BR_USART_ISR_NE | BR_USART_ISR_ORE;
    (void)br_stm32_usart_read(&g.u, b, sizeof b);
    assert_int_equal(g.u.cnt.rx_overruns, 2u);
    assert_int_equal(g.u.cnt.rx_errors, 2u);
    g.f.usart.ISR = 0u;
    (void)br_stm32_usart_read(&g.u, b, sizeof b);
    assert_int_equal(g.u.cnt.rx_overruns, 2u);
}

/* a write starts one transfer; while it runs, writes take nothing and return
 * at once; more than tx_len: tx_len taken, the short write counted */
static void test_write_never_blocks(void **st)
{
    (void)st;
    rig_t g;
    rig_up(&g);
    uint8_t b[40];
    for (uint32_t i = 0u; i < sizeof b; ++i) b[i] = (uint8_t)(0x10u + i);
    assert_int_equal(br_stm32_usart_write(&g.u, b, 10u), 10u);
    assert_memory_equal(g.tx_buf, b, 10u);
    assert_int_equal(g.f.tx.NDTR, 10u);
    assert_int_equal(g.f.tx.MAR, addr32(g.tx_buf));
    assert_int_equal(g.f.tx.CR, TX_CR | BR_DMA_CR_EN);
    /* the transfer never ends (a stalled line): every write returns 0 */
    for (int k = 0; k < 1000; ++k) {
        assert_int_equal(br_stm32_usart_write(&g.u, b, 5u), 0u);
    }
    assert_int_equal(g.u.cnt.tx_busy, 1000u);
    assert_memory_equal(g.tx_buf, b, 10u); /* the running transfer's bytes untouched */
    /* the G4's end: EN set, NDTR 0 */
    g.f.tx.NDTR = 0u;
    g.f.ifcr = 0u;
    assert_int_equal(br_stm32_usart_write(&g.u, &b[10], sizeof b - 10u), TX_LEN);
    assert_memory_equal(g.tx_buf, &b[10], TX_LEN);
    assert_int_equal(g.f.tx.NDTR, TX_LEN);
    assert_int_equal(g.f.ifcr, IFCR_MASK); /* the last transfer's flags cleared */
    assert_int_equal(g.u.cnt.tx_short, 1u);
    /* the H7's end: EN cleared by the stream, NDTR 0 */
    g.f.tx.CR = TX_CR;
    g.f.tx.NDTR = 0u;
    assert_int_equal(br_stm32_usart_write(&g.u, b, 3u), 3u);
    assert_int_equal(g.u.cnt.tx_bytes, 10u + TX_LEN + 3u);
    assert_int_equal(br_stm32_usart_write(&g.u, b, 0u), 0u);
    assert_int_equal(br_stm32_usart_write(&g.u, NULL, 3u), 0u);
}

/* the link over the channel: a host's arm request put into the RX buffer by
 * the "DMA" is decoded by br_link_step; the status the target queues goes out
 * through the TX buffer as a frame the decoder reads back */
static void test_link_over_usart(void **st)
{
    (void)st;
    rig_t g;
    rig_up(&g);
    br_byte_chan_t ch;
    assert_int_equal(br_stm32_usart_chan(NULL, &ch), BR_E_NULL);
    assert_int_equal(br_stm32_usart_chan(&g.u, NULL), BR_E_NULL);
    assert_int_equal(br_stm32_usart_chan(&g.u, &ch), BR_OK);
    br_link_t link;
    const br_link_cfg_t lc = {RX_LEN, BR_LINK_TX_BUF_BYTES, NULL, NULL};
    assert_int_equal(br_link_init(&link, &lc, &ch), BR_OK);
    uint8_t frame[BR_LINK_FRAME_MAX];
    size_t n = 0u;
    assert_int_equal(br_link_encode(frame, sizeof frame, BR_LINK_MSG_ARM, 7u, NULL, 0u, &n), BR_OK);
    /* the frame arrives in two pieces, across the buffer's end */
    uint8_t pad[RX_LEN - 4u];
    memset(pad, 0, sizeof pad);
    dma_receive(&g, pad, sizeof pad);
    br_link_cmd_t cmd;
    assert_int_equal(br_link_step(&link, &cmd), BR_OK);
    assert_int_equal(cmd.kind, BR_LINK_CMD_NONE);
    dma_receive(&g, frame, 5u);
    assert_int_equal(br_link_step(&link, &cmd), BR_OK);
    assert_int_equal(cmd.kind, BR_LINK_CMD_NONE);
    dma_receive(&g, &frame[5], n - 5u);
    assert_int_equal(br_link_step(&link, &cmd), BR_OK);
    assert_int_equal(cmd.kind, BR_LINK_CMD_ARM);
    assert_int_equal(cmd.seq, 7u);

    const br_link_status_t s = {1234u, 0u, 0u, 1u};
    assert_int_equal(br_link_send_status(&link, &s), BR_OK);
    assert_int_equal(br_link_step(&link, &cmd), BR_OK);
    /* a status frame is longer than TX_LEN: the first TX_LEN bytes went, the rest waits */
    const size_t sent1 = g.f.tx.NDTR;
    assert_int_equal(sent1, TX_LEN);
    uint8_t wire[2u * BR_LINK_FRAME_MAX];
    memcpy(wire, g.tx_buf, sent1);
    size_t got = sent1;
    for (int k = 0; k < 8 && link.tx_len > 0u; ++k) {
        g.f.tx.NDTR = 0u; /* the transfer ended */
        assert_int_equal(br_link_step(&link, &cmd), BR_OK);
        memcpy(&wire[got], g.tx_buf, g.f.tx.NDTR);
        got += g.f.tx.NDTR;
    }
    assert_int_equal(link.tx_len, 0u);
    br_link_dec_t dec;
    br_link_dec_init(&dec);
    int frames = 0;
    br_link_frame_t f;
    for (size_t i = 0u; i < got; ++i) {
        if (br_link_dec_push(&dec, wire[i], &f) == 1) {
            ++frames;
            assert_int_equal(f.id, BR_LINK_MSG_STATUS);
            assert_int_equal(f.payload[BR_LINK_MSG_STATUS_OFF_TICK], 1234u & 0xFFu);
        }
    }
    assert_int_equal(frames, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_init_programs_registers),
        cmocka_unit_test(test_init_guards),
        cmocka_unit_test(test_read_one_byte),
        cmocka_unit_test(test_read_wraps),
        cmocka_unit_test(test_line_errors_counted),
        cmocka_unit_test(test_write_never_blocks),
        cmocka_unit_test(test_link_over_usart),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
