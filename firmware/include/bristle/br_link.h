/* SPDX-License-Identifier: Apache-2.0 */
/* The link: framed messages over a byte stream (a UART, a pipe), for the
 * host's commands and the target's reports (docs/link.md). Transport-agnostic
 * (a br_byte_chan_t below it), no allocation, bounded work per call: it never
 * blocks the control period.
 *
 * On the wire a frame is 0x00, COBS(body), 0x00 (consistent overhead byte
 * stuffing: no 0x00 inside, so a decoder resynchronises at the next 0x00
 * after any garbage). The body:
 *
 *   length  u8    payload bytes n, 0..BR_LINK_PAYLOAD_MAX
 *   version u8    BR_LINK_VERSION
 *   id      u8    message id (bristle_gen/link/br_link_msgs.h)
 *   seq     u16   little-endian; +1 per frame sent, modulo 2^16
 *   payload n bytes
 *   crc     u16   CRC-16/CCITT-FALSE over every byte before it, most significant first
 *
 * A received frame that is short, oversized, badly stuffed, of the wrong
 * length, of a bad CRC, of another version, or whose seq is not 1..32767
 * ahead of the last accepted one (modulo 2^16: replayed or stale) is dropped
 * and counted (br_link_counters_t); it never reaches the caller. */
#ifndef BR_LINK_H
#define BR_LINK_H

#include <stddef.h>
#include <stdint.h>

#include "bristle/br_refq.h"
#include "bristle/br_status.h"
#include "bristle_gen/link/br_link_msgs.h"

/* body: length, version, id, seq (2); then the payload and the CRC (2) */
#define BR_LINK_HEADER_BYTES 5u
#define BR_LINK_CRC_BYTES 2u
#define BR_LINK_BODY_MIN (BR_LINK_HEADER_BYTES + BR_LINK_CRC_BYTES)
#define BR_LINK_BODY_MAX (BR_LINK_BODY_MIN + BR_LINK_PAYLOAD_MAX)
/* on the wire: COBS adds a code byte and one per 254 data bytes, and two delimiters */
#define BR_LINK_FRAME_MAX (BR_LINK_BODY_MAX + 1u + BR_LINK_BODY_MAX / 254u + 2u)
/* a seq 1..BR_LINK_SEQ_WINDOW ahead of the last accepted one (modulo 2^16) is new */
#define BR_LINK_SEQ_WINDOW 0x7FFFu
/* the bounds of br_link_cfg_t's budgets */
#define BR_LINK_RX_BUDGET_MAX 256u
#define BR_LINK_TX_BUF_BYTES (4u * BR_LINK_FRAME_MAX)

/* A byte channel, br_hal_t's style: a port fills the function pointers and
 * owns ctx. Both calls return at once (never wait for a byte or for room). */
typedef struct {
    void *ctx;
    /* Copies min(n, bytes available) received bytes into buf; returns how many (0: none). */
    size_t (*read)(void *ctx, uint8_t *buf, size_t n);
    /* Takes up to n bytes of buf for sending; returns how many it accepted (0: no room). */
    size_t (*write)(void *ctx, const uint8_t *buf, size_t n);
} br_byte_chan_t;

/* A frame that passed every check. */
typedef struct {
    uint8_t id;
    uint16_t seq;
    uint8_t len; /* payload bytes */
    uint8_t payload[BR_LINK_PAYLOAD_MAX];
} br_link_frame_t;

/* What was received, dropped and sent, since init (each wraps modulo 2^32). */
typedef struct {
    uint32_t rx_bytes;       /* bytes taken from the channel */
    uint32_t rx_frames;      /* frames accepted by the frame checks */
    uint32_t rx_short;       /* fewer than BR_LINK_BODY_MIN bytes */
    uint32_t rx_oversized;   /* more than BR_LINK_BODY_MAX bytes, or a length above BR_LINK_PAYLOAD_MAX */
    uint32_t rx_bad_len;     /* the length byte disagrees with the bytes received */
    uint32_t rx_bad_cobs;    /* the frame ended inside a COBS block */
    uint32_t rx_bad_crc;     /* CRC mismatch */
    uint32_t rx_bad_version; /* another protocol version */
    uint32_t rx_replayed;    /* seq not ahead of the last accepted one */
    uint32_t rx_unknown_id;  /* an id not in the message table, or one the target does not receive */
    uint32_t rx_bad_payload; /* a known id with another payload length */
    uint32_t rx_refused;     /* a param_write refused (non-finite, or by the check hook) */
    uint32_t tx_frames;      /* frames queued by br_link_send */
    uint32_t tx_busy;        /* br_link_send refused: transmit buffer full */
} br_link_counters_t;

/* The stream decoder (COBS undone byte by byte, the frame checked at its
 * delimiter). Usable alone: br_link_dec_init, then br_link_dec_push. */
typedef struct {
    uint8_t body[BR_LINK_BODY_MAX];
    size_t n;          /* body bytes so far */
    uint8_t code;      /* the current COBS block's code byte; 0 before the first */
    uint8_t left;      /* data bytes left in the current block */
    uint8_t overflow;  /* the body went past BR_LINK_BODY_MAX: dropped at the delimiter */
    uint8_t have_seq;  /* a frame was accepted: last_seq is valid */
    uint16_t last_seq;
    uint8_t have_session; /* a hello was accepted: session is valid */
    uint32_t session;     /* the session in force (the last hello's number) */
    br_link_counters_t cnt;
} br_link_dec_t;

/* Forgets any partial frame and the last sequence number; zeroes the counters (NULL: nothing). */
void br_link_dec_init(br_link_dec_t *d);

/* Takes one byte; 1 when it completes a frame that passes every check
 * (copied to *f), else 0 (a dropped frame is counted in d->cnt; a NULL d or
 * f: 0, the byte ignored). */
int br_link_dec_push(br_link_dec_t *d, uint8_t byte, br_link_frame_t *f);

/* CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, xorout 0;
 * "123456789" gives 0x29B1) of n bytes, continuing from crc (0xFFFF to start);
 * NULL data: crc unchanged. */
uint16_t br_link_crc16(uint16_t crc, const uint8_t *data, size_t n);

/* COBS (Cheshire and Baker 1999) of n bytes into out (cap bytes): no 0x00
 * in the output; returns its length, at most n + 1 + n / 254, or 0 when a
 * pointer is NULL or cap is below that bound (nothing written). */
size_t br_link_cobs_encode(const uint8_t *in, size_t n, uint8_t *out, size_t cap);

/* Writes one frame (delimiters included) into buf (cap bytes; the caller's);
 * *out_len its length, at most BR_LINK_FRAME_MAX. BR_E_NULL, BR_E_PARAM
 * (len > BR_LINK_PAYLOAD_MAX, or cap too small: nothing written, *out_len 0). */
br_status_t br_link_encode(uint8_t *buf, size_t cap, uint8_t id, uint16_t seq, const uint8_t *payload,
                           size_t len, size_t *out_len);

/* A param_write's range check, the application's (the same rules as the
 * machine file's, docs/link.md): BR_OK to accept value for parameter id,
 * negative to refuse it (the answer's status). */
typedef br_status_t (*br_link_param_check_fn)(void *ctx, uint16_t param, float value);

typedef struct {
    size_t rx_budget_bytes; /* K: at most K received bytes handled per br_link_step, 1..BR_LINK_RX_BUDGET_MAX */
    size_t tx_budget_bytes; /* at most this many bytes offered to write per step, 1..BR_LINK_TX_BUF_BYTES */
    br_link_param_check_fn param_check; /* NULL: every finite value is passed on */
    void *param_ctx;
} br_link_cfg_t;

/* A host's request, decoded: what br_link_step hands the application. */
typedef enum {
    BR_LINK_CMD_NONE = 0,
    BR_LINK_CMD_ARM,
    BR_LINK_CMD_DISARM,
    BR_LINK_CMD_FAULT_RESET,
    BR_LINK_CMD_PARAM_READ,
    BR_LINK_CMD_PARAM_WRITE, /* finite and accepted by param_check */
    BR_LINK_CMD_REC_ARM,     /* the recorder's requests (bristle/br_rec.h: br_rec_command) */
    BR_LINK_CMD_REC_TRIGGER,
    BR_LINK_CMD_REC_DUMP,
    BR_LINK_CMD_SETPOINT,    /* ref: a setpoint (kind BR_REFQ_SETPOINT, periods 1) */
    BR_LINK_CMD_SEGMENT,     /* ref: a segment (kind BR_REFQ_SEGMENT) */
    BR_LINK_CMD_HELLO        /* session: a session opened (the window restarted at its seq) */
} br_link_cmd_kind_t;

typedef struct {
    br_link_cmd_kind_t kind;
    uint16_t seq;   /* the frame's sequence number */
    uint16_t param; /* PARAM_READ, PARAM_WRITE */
    uint32_t session; /* HELLO: the host's session number */
    float value;    /* PARAM_WRITE */
    uint16_t first; /* REC_DUMP: the first sample index to send */
    br_refq_item_t ref; /* SETPOINT, SEGMENT: the item as received (br_refq_push checks it) */
} br_link_cmd_t;

typedef struct {
    br_link_cfg_t cfg;
    br_byte_chan_t chan;
    br_link_dec_t dec;
    uint8_t rx[BR_LINK_RX_BUDGET_MAX]; /* read from the channel, not yet decoded */
    size_t rx_pos, rx_end;
    size_t rx_done;                    /* bytes decoded in this period (since br_link_step) */
    uint8_t rx_have_read;              /* this period's one read was made */
    uint8_t tx[BR_LINK_TX_BUF_BYTES];  /* queued frames, not yet taken by the channel */
    size_t tx_len;
    uint16_t tx_seq;                   /* the next frame's sequence number */
    int ready;
} br_link_t;

/* The target's reports (payload layouts: bristle_gen/link/br_link_msgs.h). */
typedef struct {
    uint32_t tick;       /* control period index of the report */
    uint32_t fault_tick; /* period at which the fault latched (0 without one) */
    uint8_t armed;       /* 1 armed, 0 disarmed */
    uint8_t fault;       /* br_app_fault_t, 0 none */
} br_link_status_t;

/* The reference queue's report (ref_status). */
typedef struct {
    uint32_t tick;      /* control period index of the report */
    uint8_t queued;     /* items queued */
    uint8_t free;       /* free places */
    uint8_t state;      /* br_refq_state_t */
    uint32_t dropped;   /* br_refq_counters_t */
    uint32_t late;
    uint32_t underruns;
} br_link_ref_status_t;

/* Validates cfg (budgets in range) and chan (both functions set). BR_OK, BR_E_NULL or BR_E_PARAM. */
br_status_t br_link_init(br_link_t *l, const br_link_cfg_t *cfg, const br_byte_chan_t *chan);

/* One call per control period: offers the channel at most tx_budget_bytes of
 * the queued frames (one write), then decodes at most rx_budget_bytes received
 * bytes (at most one read), stopping at the first command. *cmd is that
 * command, or kind BR_LINK_CMD_NONE. A refused param_write queues its
 * param_value answer (status BR_E_PARAM or the hook's) and is not returned.
 * BR_E_NULL, BR_E_STATE (not initialised), BR_E_INPUT (the channel claimed
 * more bytes than asked: they are discarded). */
br_status_t br_link_step(br_link_t *l, br_link_cmd_t *cmd);

/* The period's next request, after br_link_step returned one: decoding goes
 * on within what is left of the same period's rx_budget_bytes and its one
 * read (none when the step made it), nothing is written; *cmd as
 * br_link_step's (kind NONE when the budget ends first: the bytes of a frame
 * begun stay decoded, the rest waits for the next period). So a period
 * handles at most rx_budget_bytes and one read however many calls it makes.
 * BR_E_NULL, BR_E_STATE, BR_E_INPUT (br_link_step's). */
br_status_t br_link_next(br_link_t *l, br_link_cmd_t *cmd);

/* Queues one frame of message id with the next sequence number.
 * BR_E_NULL, BR_E_STATE, BR_E_PARAM (len above BR_LINK_PAYLOAD_MAX),
 * BR_E_BUSY (no room in the transmit buffer: counted, nothing queued). */
br_status_t br_link_send(br_link_t *l, uint8_t id, const uint8_t *payload, size_t len);

/* Queue one report each (br_link_send's statuses). */
br_status_t br_link_send_status(br_link_t *l, const br_link_status_t *s);
br_status_t br_link_send_fault(br_link_t *l, uint8_t cause, uint32_t tick);
/* st: the read's or write's status, sent as an i8 (BR_OK, or the refusal) */
br_status_t br_link_send_param_value(br_link_t *l, uint16_t param, float value, br_status_t st);
br_status_t br_link_send_ref_status(br_link_t *l, const br_link_ref_status_t *s);
/* hello's answer: the session number, BR_LINK_VERSION, fw_version and the
 * machine's name (its first 16 bytes, NUL-padded; NULL: empty) */
br_status_t br_link_send_hello_reply(br_link_t *l, uint32_t session, uint32_t fw_version, const char *machine);

/* The payload length of message id sent in direction (BR_LINK_TO_HOST or
 * BR_LINK_TO_TARGET), from the table; -1 when there is no such message. */
int br_link_msg_len(uint8_t id, unsigned direction);

/* A frame as a host's request: BR_OK and *cmd; BR_E_INPUT for an id the
 * target does not receive (unknown, or a report's) or a payload of another
 * length than the table's (*cmd kind NONE). BR_E_NULL. The range check of a
 * param_write is br_link_step's. */
br_status_t br_link_cmd_decode(const br_link_frame_t *f, br_link_cmd_t *cmd);

#endif
