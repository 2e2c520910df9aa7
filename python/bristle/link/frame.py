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

The decoder drops, and counts, a frame that is short, oversized, badly
stuffed, of the wrong length, of a bad CRC, of another version, or whose
sequence number does not advance (1..32767 ahead of the last accepted one,
modulo 2^16)."""
from dataclasses import dataclass, field

VERSION = 1
PAYLOAD_MAX = 64
HEADER_BYTES = 5            # length, version, id, seq
CRC_BYTES = 2
BODY_MIN = HEADER_BYTES + CRC_BYTES
BODY_MAX = BODY_MIN + PAYLOAD_MAX
ENCODED_MAX = BODY_MAX + 1 + BODY_MAX // 254   # COBS: one code byte per 254 data bytes, and the first
DELIM = 0x00
SEQ_WINDOW = 0x7FFF         # a sequence number 1..SEQ_WINDOW ahead of the last is new


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


def cobs_decode(data):
    """The inverse of cobs_encode; FrameError("bad_cobs") for a 0x00 inside or a block cut short."""
    data = bytes(data)
    out = bytearray()
    i = 0
    while i < len(data):
        code = data[i]
        if code == 0 or i + code > len(data):
            raise FrameError("bad_cobs", "COBS block cut short or a 0x00 inside")
        block = data[i + 1:i + code]
        if DELIM in block:
            raise FrameError("bad_cobs", "0x00 inside a COBS block")
        out += block
        i += code
        if code < 0xFF and i < len(data):
            out.append(0)
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
    """A Frame from one unstuffed body, else FrameError naming the counter (the
    sequence number is the stream decoder's business)."""
    n = len(body)
    if n < BODY_MIN:
        raise FrameError("short", "%d bytes, a frame has at least %d" % (n, BODY_MIN))
    if n > BODY_MAX or body[0] > PAYLOAD_MAX:
        raise FrameError("oversized", "frame above %d bytes or length above %d" % (BODY_MAX, PAYLOAD_MAX))
    if n != BODY_MIN + body[0]:
        raise FrameError("bad_len", "length byte %d for %d payload bytes" % (body[0], n - BODY_MIN))
    if crc16(body[:-2]) != (body[-2] << 8 | body[-1]):
        raise FrameError("bad_crc", "CRC mismatch")
    if body[1] != VERSION:
        raise FrameError("bad_version", "protocol version %d, this side speaks %d" % (body[1], VERSION))
    return Frame(body[2], body[3] | body[4] << 8, bytes(body[HEADER_BYTES:-2]))


def decode_frame(wire):
    """One frame's bytes (with or without the 0x00 delimiters) to a Frame; FrameError otherwise."""
    wire = bytes(wire)
    if wire[:1] == bytes([DELIM]):
        wire = wire[1:]
    if wire[-1:] == bytes([DELIM]):
        wire = wire[:-1]
    if len(wire) > ENCODED_MAX:
        raise FrameError("oversized", "frame above %d bytes" % BODY_MAX)
    return check_body(cobs_decode(wire))


COUNTERS = ("frames", "short", "oversized", "bad_len", "bad_cobs", "bad_crc", "bad_version", "replayed")


@dataclass
class Decoder:
    """The stream decoder: feed() bytes as they come, in any pieces; it
    returns the frames completed, in order, and counts every frame dropped
    (counters: COUNTERS). It never raises on the bytes it is given."""
    counters: dict = field(default_factory=lambda: dict.fromkeys(COUNTERS, 0))
    last_seq: int = -1
    _buf: bytearray = field(default_factory=bytearray)
    _over: bool = False

    def feed(self, data):
        frames = []
        for b in bytes(data):
            if b != DELIM:
                if len(self._buf) >= ENCODED_MAX:
                    self._over = True
                else:
                    self._buf.append(b)
                continue
            buf, over = bytes(self._buf), self._over
            self._buf.clear()
            self._over = False
            if not buf and not over:
                continue  # two delimiters in a row: the gap between two frames
            if over:
                self.counters["oversized"] += 1
                continue
            try:
                f = check_body(cobs_decode(buf))
            except FrameError as e:
                self.counters[e.reason] += 1
                continue
            if self.last_seq >= 0 and not 1 <= ((f.seq - self.last_seq) & 0xFFFF) <= SEQ_WINDOW:
                self.counters["replayed"] += 1
                continue
            self.last_seq = f.seq
            self.counters["frames"] += 1
            frames.append(f)
        return frames
