# SPDX-License-Identifier: Apache-2.0
"""The link's frames (docs/link.md, "Frame format"), the host's side of
firmware/link/br_link.c.

On the wire a frame is 0x00, COBS(body), 0x00. The body:

    length  u8   payload bytes n, 0..PAYLOAD_MAX
    version u8   VERSION
    id      u8   message id (bristle.link.messages)
    seq     u16  little-endian, advances by 1 per frame sent, modulo 2^16
    payload n bytes
    crc     u16  CRC-16/CCITT-FALSE of every byte before it, most significant byte first

The decoder (the C decoder's twin, byte for byte) drops, and counts, a frame that is short, oversized, badly
stuffed, of the wrong length, of a bad CRC, of another version, or whose
sequence number does not advance (1..32767 ahead of the last accepted one,
modulo 2^16)."""
from dataclasses import dataclass

from .messages import BY_NAME

VERSION = 1
PAYLOAD_MAX = 64
HEADER_BYTES = 5            # length, version, id, seq
CRC_BYTES = 2
BODY_MIN = HEADER_BYTES + CRC_BYTES
BODY_MAX = BODY_MIN + PAYLOAD_MAX
DELIM = 0x00
SEQ_WINDOW = 0x7FFF         # a sequence number 1..SEQ_WINDOW ahead of the last is new
HELLO = BY_NAME["hello"]     # opens a session (Decoder)


class FrameError(ValueError):
    """The documented error of decode_frame and encode_frame: `reason` is the
    counter's name (short, oversized, bad_len, bad_cobs, bad_crc, bad_version)
    or "payload" / "id" / "seq" for a value encode_frame refuses."""

    def __init__(self, reason, text):
        super().__init__(text)
        self.reason = reason


def crc16(data, crc=0xFFFF):
    """CRC-16/CCITT-FALSE: poly 0x1021, init 0xFFFF, not reflected, xorout 0;
    crc16(b"123456789") == 0x29B1."""
    for b in bytes(data):
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) if crc & 0x8000 else (crc << 1)
            crc &= 0xFFFF
    return crc


def cobs_encode(data):
    """Consistent overhead byte stuffing (Cheshire and Baker, 1999): no 0x00 in the output."""
    out = bytearray([0])
    code_at, code = 0, 1
    for b in bytes(data):
        if b:
            out.append(b)
            code += 1
        if not b or code == 0xFF:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
    out[code_at] = code
    return bytes(out)


@dataclass(frozen=True)
class Frame:
    id: int
    seq: int
    payload: bytes


def encode_frame(msg_id, seq, payload, version=VERSION):
    """The bytes on the wire: 0x00, COBS(body), 0x00."""
    payload = bytes(payload)
    if len(payload) > PAYLOAD_MAX:
        raise FrameError("payload", "payload of %d bytes, at most %d" % (len(payload), PAYLOAD_MAX))
    if not 0 <= msg_id <= 0xFF or not 0 <= version <= 0xFF:
        raise FrameError("id", "message id and version are one byte each")
    if not 0 <= seq <= 0xFFFF:
        raise FrameError("seq", "sequence number %r outside 0..65535" % (seq,))
    body = bytes([len(payload), version, msg_id, seq & 0xFF, seq >> 8]) + payload
    c = crc16(body)
    return bytes([DELIM]) + cobs_encode(body + bytes([c >> 8, c & 0xFF])) + bytes([DELIM])


def check_body(body):
    """A Frame from one unstuffed body (at most BODY_MAX bytes: the Decoder
    drops longer ones as oversized, so a length that matches is at most
    PAYLOAD_MAX), else FrameError naming the counter (the sequence number is
    the stream decoder's business)."""
    n = len(body)
    if n < BODY_MIN:
        raise FrameError("short", "%d bytes, a frame has at least %d" % (n, BODY_MIN))
    if n != BODY_MIN + body[0]:
        raise FrameError("bad_len", "length byte %d for %d payload bytes" % (body[0], n - BODY_MIN))
    if crc16(body[:-2]) != (body[-2] << 8 | body[-1]):
        raise FrameError("bad_crc", "CRC mismatch")
    if body[1] != VERSION:
        raise FrameError("bad_version", "protocol version %d, this side speaks %d" % (body[1], VERSION))
    return Frame(body[2], body[3] | body[4] << 8, bytes(body[HEADER_BYTES:-2]))


COUNTERS = ("frames", "short", "oversized", "bad_len", "bad_cobs", "bad_crc", "bad_version", "replayed")


class Decoder:
    """The stream decoder, byte for byte the C decoder's (br_link_dec_push):
    COBS undone as the bytes come, the checks at each closing 0x00. feed()
    takes bytes in any pieces and returns the frames completed, in order;
    every frame dropped is counted in `counters` (COUNTERS) under the same
    reason as in C. It never raises on the bytes it is given."""

    def __init__(self):
        self.counters = dict.fromkeys(COUNTERS, 0)
        self.last_seq = None
        self.session = None  # the session in force (the last hello's number)
        self._body = bytearray()
        self._code = 0
        self._left = 0
        self._over = False

    def _append(self, b):
        if len(self._body) >= BODY_MAX:
            self._over = True
        else:
            self._body.append(b)

    def _end(self):
        """the checks at a delimiter: the Frame, or None (counted)"""
        if self._over:
            self.counters["oversized"] += 1
            return None
        if self._code == 0:
            return None  # two delimiters in a row: the gap between two frames
        if self._left:
            self.counters["bad_cobs"] += 1
            return None
        try:
            f = check_body(bytes(self._body))
        except FrameError as e:
            self.counters[e.reason] += 1
            return None
        # a hello of another session than the one in force opens a session: any
        # seq, the window restarts there (docs/link.md, "The session")
        opens = (f.id == HELLO.id and len(f.payload) == HELLO.size
                 and int.from_bytes(f.payload, "little") != self.session)
        if not opens and self.last_seq is not None and not 1 <= ((f.seq - self.last_seq) & 0xFFFF) <= SEQ_WINDOW:
            self.counters["replayed"] += 1
            return None
        if opens:
            self.session = int.from_bytes(f.payload, "little")
        self.last_seq = f.seq
        self.counters["frames"] += 1
        return f

    def feed(self, data):
        frames = []
        for b in bytes(data):
            if b == DELIM:
                f = self._end()
                if f is not None:
                    frames.append(f)
                self._body.clear()
                self._code = self._left = 0
                self._over = False
            elif self._over:
                continue  # skipping to the next delimiter
            elif self._left == 0:
                # a code byte: the zero a previous block below 0xFF stood for, then the block
                if self._code not in (0, 0xFF):
                    self._append(0)
                self._code, self._left = b, b - 1
            else:
                self._append(b)
                self._left -= 1
        return frames


def decode_frame(wire):
    """One frame's bytes (with or without its 0x00 delimiters) to a Frame,
    through a fresh Decoder (so any sequence number is accepted); FrameError
    naming the counter otherwise ("bad_cobs" also for a 0x00 inside)."""
    wire = bytes(wire)
    if wire[:1] == bytes([DELIM]):
        wire = wire[1:]
    if wire[-1:] == bytes([DELIM]):
        wire = wire[:-1]
    if not wire or DELIM in wire:
        raise FrameError("bad_cobs", "not one frame: empty, or a 0x00 inside")
    d = Decoder()
    frames = d.feed(bytes([DELIM]) + wire + bytes([DELIM]))
    if frames:
        return frames[0]
    reason = next(k for k, v in d.counters.items() if v)
    raise FrameError(reason, "frame dropped: %s" % reason)
