/* SPDX-License-Identifier: Apache-2.0 */
/* The link's frames: CRC-16/CCITT-FALSE, COBS, the encoder and the stream
 * decoder with its checks (bristle/br_link.h, docs/link.md). */
#include "bristle/br_link.h"

#include <string.h>

#include "br_le.h"

uint16_t br_link_crc16(uint16_t crc, const uint8_t *data, size_t n)
{
    if (data == NULL) {
        return crc;
    }
    /* MSB-first CRC, polynomial x^16 + x^12 + x^5 + 1 (0x1021), bit by bit */
    for (size_t i = 0u; i < n; ++i) {
        crc = (uint16_t)(crc ^ (uint16_t)((uint16_t)data[i] << 8));
        for (unsigned b = 0u; b < 8u; ++b) {
            const uint16_t shifted = (uint16_t)(crc << 1);
            crc = (crc & 0x8000u) ? (uint16_t)(shifted ^ 0x1021u) : shifted;
        }
    }
    return crc;
}

br_status_t br_link_encode(uint8_t *buf, size_t cap, uint8_t id, uint16_t seq, const uint8_t *payload,
                           size_t len, size_t *out_len)
{
    if (buf == NULL || out_len == NULL || (payload == NULL && len > 0u)) {
        return BR_E_NULL;
    }
    *out_len = 0u;
    if (len > BR_LINK_PAYLOAD_MAX || cap < len + BR_LINK_BODY_MIN + 1u + (len + BR_LINK_BODY_MIN) / 254u + 2u) {
        return BR_E_PARAM;
    }
    uint8_t body[BR_LINK_BODY_MAX];
    const size_t n = BR_LINK_HEADER_BYTES + len + BR_LINK_CRC_BYTES;
    body[0] = (uint8_t)len;
    body[1] = (uint8_t)BR_LINK_VERSION;
    body[2] = id;
    body[3] = (uint8_t)(seq & 0xFFu);
    body[4] = (uint8_t)(seq >> 8);
    if (len > 0u) {
        memcpy(&body[BR_LINK_HEADER_BYTES], payload, len);
    }
    const uint16_t crc = br_link_crc16(0xFFFFu, body, n - BR_LINK_CRC_BYTES);
    body[n - 2u] = (uint8_t)(crc >> 8);
    body[n - 1u] = (uint8_t)(crc & 0xFFu);

    buf[0] = 0x00u;
    const size_t m = br_link_cobs_encode(body, n, &buf[1], cap - 2u);
    buf[1u + m] = 0x00u;
    *out_len = m + 2u;
    return BR_OK;
}

size_t br_link_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap)
{
    if (in == NULL || out == NULL || cap < n + 1u + n / 254u) {
        return 0u;
    }
    /* COBS: each block is a code byte (1 + its count of non-zero bytes) and
     * those bytes; a zero ends a block, and so does a full block of 254 */
    size_t o = 0u;
    size_t code_at = o++;
    uint8_t code = 1u;
    for (size_t i = 0u; i < n; ++i) {
        if (in[i] != 0u) {
            out[o++] = in[i];
            ++code;
        }
        if (in[i] == 0u || code == 0xFFu) {
            out[code_at] = code;
            code_at = o++;
            code = 1u;
        }
    }
    out[code_at] = code;
    return o;
}

void br_link_dec_init(br_link_dec_t *d)
{
    if (d == NULL) {
        return;
    }
    memset(d, 0, sizeof *d);
}

static void dec_restart(br_link_dec_t *d)
{
    d->n = 0u;
    d->code = 0u;
    d->left = 0u;
    d->overflow = 0u;
}

static void dec_append(br_link_dec_t *d, uint8_t b)
{
    if (d->n >= BR_LINK_BODY_MAX) {
        d->overflow = 1u;
    } else {
        d->body[d->n++] = b;
    }
}

/* The checks of a complete body, in order; 1 and *f when it passes all. */
static int dec_check(br_link_dec_t *d, br_link_frame_t *f)
{
    const uint8_t *b = d->body;
    const size_t n = d->n;
    if (n < BR_LINK_BODY_MIN) {
        ++d->cnt.rx_short;
        return 0;
    }
    /* a body is at most BR_LINK_BODY_MAX bytes (longer ones overflowed), so a
     * length that matches them is at most BR_LINK_PAYLOAD_MAX */
    if (n != BR_LINK_BODY_MIN + (size_t)b[0]) {
        ++d->cnt.rx_bad_len;
        return 0;
    }
    const uint16_t crc = (uint16_t)(((uint16_t)b[n - 2u] << 8) | b[n - 1u]);
    if (br_link_crc16(0xFFFFu, b, n - BR_LINK_CRC_BYTES) != crc) {
        ++d->cnt.rx_bad_crc;
        return 0;
    }
    if (b[1] != BR_LINK_VERSION) {
        ++d->cnt.rx_bad_version;
        return 0;
    }
    const uint16_t seq = (uint16_t)(b[3] | (uint16_t)((uint16_t)b[4] << 8));
    /* a hello of another session than the one in force opens a session: accepted
     * with any seq, the window restarts there (docs/link.md, "The session") */
    const int hello = b[2] == BR_LINK_MSG_HELLO && b[0] == BR_LINK_MSG_HELLO_LEN;
    const uint32_t session = hello ? br_le_get(&b[BR_LINK_HEADER_BYTES + BR_LINK_MSG_HELLO_OFF_SESSION], 4u) : 0u;
    const int opens = hello && (!d->have_session || session != d->session);
    /* new: 1..BR_LINK_SEQ_WINDOW ahead of the last accepted, modulo 2^16 */
    const uint16_t ahead = (uint16_t)(seq - d->last_seq);
    if (!opens && d->have_seq && (ahead == 0u || ahead > BR_LINK_SEQ_WINDOW)) {
        ++d->cnt.rx_replayed;
        return 0;
    }
    if (opens) {
        d->have_session = 1u;
        d->session = session;
    }
    d->have_seq = 1u;
    d->last_seq = seq;
    ++d->cnt.rx_frames;
    f->id = b[2];
    f->seq = seq;
    f->len = b[0];
    memcpy(f->payload, &b[BR_LINK_HEADER_BYTES], b[0]);
    return 1;
}

int br_link_dec_push(br_link_dec_t *d, uint8_t byte, br_link_frame_t *f)
{
    if (d == NULL || f == NULL) {
        return 0;
    }
    if (byte == 0x00u) {
        /* a delimiter ends the frame (two in a row: the gap between two frames) */
        int got = 0;
        if (d->overflow) {
            ++d->cnt.rx_oversized;
        } else if (d->code == 0u) {
            /* nothing since the last delimiter */
        } else if (d->left != 0u) {
            ++d->cnt.rx_bad_cobs;
        } else {
            got = dec_check(d, f);
        }
        dec_restart(d);
        return got;
    }
    if (d->overflow) {
        return 0; /* skipping to the next delimiter */
    }
    if (d->left == 0u) {
        /* a code byte: the zero a previous block below 0xFF stood for, then the block */
        if (d->code != 0u && d->code != 0xFFu) {
            dec_append(d, 0x00u);
        }
        d->code = byte;
        d->left = (uint8_t)(byte - 1u);
    } else {
        dec_append(d, byte);
        --d->left;
    }
    return 0;
}
