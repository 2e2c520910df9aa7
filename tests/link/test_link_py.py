#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bristle.link's frames and messages (docs/link.md): the CRC's check value,
COBS, each reason a frame is refused (decode_frame's FrameError, the stream
Decoder's counters), the sequence window, resynchronisation after garbage,
and the message table's packing and its refusals."""
import os
import random
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from bristle.link import Decoder, FrameError, MessageError, crc16, decode_frame, encode_frame, messages, pack, unpack  # noqa: E402
from bristle.link.frame import BODY_MAX, PAYLOAD_MAX, VERSION, cobs_encode  # noqa: E402


def wire_of(body, fix_crc=True):
    body = bytearray(body)
    if fix_crc:
        c = crc16(body[:-2])
        body[-2:] = bytes([c >> 8, c & 0xFF])
    return b"\x00" + cobs_encode(bytes(body)) + b"\x00"


def raises(reason, fn, *args):
    try:
        fn(*args)
    except FrameError as e:
        assert e.reason == reason, (e.reason, reason)
        return
    raise AssertionError("no FrameError(%s)" % reason)


def test_crc_and_cobs():
    assert crc16(b"123456789") == 0x29B1  # CRC-16/CCITT-FALSE's check value
    rng = random.Random(1)
    for n in list(range(0, 300)) + [508, 509, 510]:
        d = bytes(rng.choice((0, 0, rng.randrange(256))) for _ in range(n))
        e = cobs_encode(d)
        assert 0 not in e and len(e) <= n + 1 + n // 254
    # every payload length and many zero patterns through the decoder
    for n in range(PAYLOAD_MAX + 1):
        p = bytes(rng.choice((0, rng.randrange(256))) for _ in range(n))
        assert decode_frame(encode_frame(0x21, n, p)).payload == p


def test_roundtrip_every_message():
    rng = random.Random(2)
    for m in messages.MESSAGES:
        vals = {}
        for f in m.fields:
            vals[f.name] = {"u8": rng.randrange(256), "i8": rng.randrange(-128, 128), "u16": rng.randrange(65536),
                            "u32": rng.randrange(1 << 32), "i32": rng.randrange(-(1 << 31), 1 << 31),
                            "f32": struct.unpack("<f", struct.pack("<f", rng.uniform(-1e3, 1e3)))[0],
                            "c16": bytes(rng.randrange(256) for _ in range(16))}[f.type]
        seq = rng.randrange(65536)
        fr = decode_frame(encode_frame(m.id, seq, pack(m.name, **vals)))
        assert (fr.id, fr.seq) == (m.id, seq) and unpack(fr.id, fr.payload) == (m.name, vals)


def test_each_refusal():
    hdr = [0, VERSION, 0x10, 1, 0]
    raises("short", decode_frame, wire_of(bytes(6)))
    raises("oversized", decode_frame, wire_of(bytes([PAYLOAD_MAX + 1] + hdr[1:]) + bytes(PAYLOAD_MAX + 3)))
    raises("oversized", decode_frame, b"\x00" + b"\x01" * (BODY_MAX + 3) + b"\x00")
    raises("bad_len", decode_frame, wire_of(bytes([1] + hdr[1:]) + b"\x07\x07\x00\x00"))
    c = crc16(bytes(hdr))
    raises("bad_crc", decode_frame, wire_of(bytes(hdr + [c >> 8, (c & 0xFF) ^ 1]), fix_crc=False))
    assert decode_frame(wire_of(bytes(hdr + [c >> 8, c & 0xFF]), fix_crc=False)).id == 0x10
    raises("bad_version", decode_frame, wire_of(bytes([0, VERSION + 1, 0x10, 1, 0, 0, 0])))
    raises("bad_cobs", decode_frame, b"\x00\x05\x01\x01\x00")
    raises("payload", encode_frame, 1, 0, bytes(PAYLOAD_MAX + 1))
    raises("seq", encode_frame, 1, 65536, b"")


def test_decoder_counts_and_window():
    d = Decoder()
    stream = (wire_of(bytes(6)) + wire_of(bytes([0, VERSION + 1, 0x10, 1, 0, 0, 0])) + b"\x00\x05\x01\x00"
              + bytes(range(1, 200)) + b"\x00")  # short, version, cobs, oversized garbage
    seqs = [0xFFFE, 0xFFFE, 0xFFFD, 0xFFFF, 0x0000, 0x8000, 0x7FFF, 0x7FFF]
    fresh = [1, 0, 0, 1, 1, 0, 1, 0]
    got = d.feed(stream)
    assert got == []
    for s, f in zip(seqs, fresh):
        assert len(d.feed(encode_frame(0x10, s, b""))) == f
    c = d.counters
    assert (c["short"], c["bad_version"], c["bad_cobs"], c["oversized"]) == (1, 1, 1, 1), c
    assert (c["replayed"], c["frames"]) == (4, 4), c


def test_resync_and_pieces():
    rng = random.Random(3)
    junk = bytes(rng.randrange(1, 256) for _ in range(500))
    f1, f2 = encode_frame(0x11, 5, b""), encode_frame(0x20, 6, pack("param_read", param=9))
    stream = junk + f1 + junk[:7] + f2
    d = Decoder()
    out = []
    i = 0
    while i < len(stream):  # in random pieces
        k = rng.randrange(1, 40)
        out += d.feed(stream[i:i + k])
        i += k
    assert [(f.id, f.seq) for f in out] == [(0x11, 5), (0x20, 6)]


def test_messages_refused():
    for args in ((0x7E, b""), (0x10, b"\x01"), (0x21, bytes(5))):
        try:
            unpack(*args)
        except MessageError:
            continue
        raise AssertionError(args)
    try:
        pack("param_write", param=1)
    except MessageError:
        pass
    else:
        raise AssertionError("a missing field passed")
    dup = messages.MESSAGES + (messages.Message("again", 0x10, messages.TO_HOST, (), ""),)
    try:
        messages.check_table(dup)
    except ValueError:
        pass
    else:
        raise AssertionError("a repeated id passed")
    messages.check_table()


if __name__ == "__main__":
    for name, fn in sorted(globals().items()):
        if name.startswith("test_") and callable(fn):
            fn()
            print("ok", name)
