/* SPDX-License-Identifier: Apache-2.0 */
/* The link over a byte channel: init, the bounded step, the transmit queue
 * (bristle/br_link.h, docs/link.md). */
#include "bristle/br_link.h"

#include <math.h>
#include <string.h>

br_status_t br_link_init(br_link_t *l, const br_link_cfg_t *cfg, const br_byte_chan_t *chan)
{
    if (l == NULL || cfg == NULL || chan == NULL) {
        return BR_E_NULL;
    }
    l->ready = 0;
    if (chan->read == NULL || chan->write == NULL) {
        return BR_E_NULL;
    }
    if (cfg->rx_budget_bytes < 1u || cfg->rx_budget_bytes > BR_LINK_RX_BUDGET_MAX ||
        cfg->tx_budget_bytes < 1u || cfg->tx_budget_bytes > BR_LINK_TX_BUF_BYTES) {
        return BR_E_PARAM;
    }
    l->cfg = *cfg;
    l->chan = *chan;
    br_link_dec_init(&l->dec);
    l->rx_pos = 0u;
    l->rx_end = 0u;
    l->rx_done = 0u;
    l->rx_have_read = 0u;
    l->tx_len = 0u;
    l->tx_seq = 0u;
    l->ready = 1;
    return BR_OK;
}

br_status_t br_link_send(br_link_t *l, uint8_t id, const uint8_t *payload, size_t len)
{
    if (l == NULL || (payload == NULL && len > 0u)) {
        return BR_E_NULL;
    }
    if (!l->ready) {
        return BR_E_STATE;
    }
    if (len > BR_LINK_PAYLOAD_MAX) {
        return BR_E_PARAM;
    }
    /* the frame's length on the wire (br_link_encode) */
    const size_t body = len + BR_LINK_BODY_MIN;
    if (BR_LINK_TX_BUF_BYTES - l->tx_len < body + 1u + body / 254u + 2u) {
        ++l->dec.cnt.tx_busy;
        return BR_E_BUSY;
    }
    size_t n = 0u;
    const br_status_t st = br_link_encode(&l->tx[l->tx_len], BR_LINK_TX_BUF_BYTES - l->tx_len, id, l->tx_seq,
                                          payload, len, &n);
    if (st != BR_OK) {
        return st;
    }
    l->tx_len += n;
    l->tx_seq = (uint16_t)(l->tx_seq + 1u);
    ++l->dec.cnt.tx_frames;
    return BR_OK;
}

/* One write of at most tx_budget_bytes; what the channel took leaves the queue. */
static void tx_flush(br_link_t *l)
{
    if (l->tx_len == 0u) {
        return;
    }
    const size_t want = l->tx_len < l->cfg.tx_budget_bytes ? l->tx_len : l->cfg.tx_budget_bytes;
    size_t took = l->chan.write(l->chan.ctx, l->tx, want);
    if (took > want) {
        took = want; /* a port that claims more than it was offered took what it was offered */
    }
    memmove(l->tx, &l->tx[took], l->tx_len - took);
    l->tx_len -= took;
}

/* A decoded frame as a command; 1 when it goes to the application. */
static int frame_to_cmd(br_link_t *l, const br_link_frame_t *f, br_link_cmd_t *cmd)
{
    if (br_link_cmd_decode(f, cmd) != BR_OK) {
        if (br_link_msg_len(f->id, BR_LINK_TO_TARGET) >= 0) {
            ++l->dec.cnt.rx_bad_payload;
        } else {
            ++l->dec.cnt.rx_unknown_id;
        }
        return 0;
    }
    if (cmd->kind != BR_LINK_CMD_PARAM_WRITE) {
        return 1;
    }
    /* a write: finite, then the application's range check */
    br_status_t ok = isfinite(cmd->value) ? BR_OK : BR_E_PARAM;
    if (ok == BR_OK && l->cfg.param_check != NULL) {
        ok = l->cfg.param_check(l->cfg.param_ctx, cmd->param, cmd->value);
    }
    if (BR_FAILED(ok)) {
        ++l->dec.cnt.rx_refused;
        (void)br_link_send_param_value(l, cmd->param, cmd->value, ok);
        cmd->kind = BR_LINK_CMD_NONE;
        return 0;
    }
    return 1;
}

/* Decodes received bytes until a request, within what is left of the
 * period's K bytes and its one read (rx_done, rx_have_read). */
static br_status_t rx_decode(br_link_t *l, br_link_cmd_t *cmd)
{
    const size_t k = l->cfg.rx_budget_bytes;
    br_link_frame_t f;
    /* at most k bytes, at most one read, at most one command */
    while (l->rx_done < k) {
        if (l->rx_pos == l->rx_end) {
            if (l->rx_have_read) {
                break;
            }
            l->rx_have_read = 1u;
            const size_t want = k - l->rx_done;
            const size_t got = l->chan.read(l->chan.ctx, l->rx, want);
            l->rx_pos = 0u;
            l->rx_end = 0u;
            if (got > want) {
                return BR_E_INPUT;
            }
            if (got == 0u) {
                break;
            }
            l->rx_end = got;
            l->dec.cnt.rx_bytes += (uint32_t)got;
        }
        ++l->rx_done;
        if (br_link_dec_push(&l->dec, l->rx[l->rx_pos++], &f) && frame_to_cmd(l, &f, cmd)) {
            break;
        }
    }
    return BR_OK;
}

/* the guards of br_link_step and br_link_next; *cmd NONE */
static br_status_t rx_begin(br_link_t *l, br_link_cmd_t *cmd)
{
    if (l == NULL || cmd == NULL) {
        return BR_E_NULL;
    }
    cmd->kind = BR_LINK_CMD_NONE;
    return l->ready ? BR_OK : BR_E_STATE;
}

br_status_t br_link_step(br_link_t *l, br_link_cmd_t *cmd)
{
    const br_status_t st = rx_begin(l, cmd);
    if (st != BR_OK) {
        return st;
    }
    tx_flush(l);
    /* a new period: its K bytes and its one read */
    l->rx_done = 0u;
    l->rx_have_read = 0u;
    return rx_decode(l, cmd);
}

br_status_t br_link_next(br_link_t *l, br_link_cmd_t *cmd)
{
    const br_status_t st = rx_begin(l, cmd);
    return st != BR_OK ? st : rx_decode(l, cmd);
}
