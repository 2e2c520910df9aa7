#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Python-side fuzzing of bristle.link (docs/link.md), deterministic (fixed
seed, bounded iterations): random byte strings and mutated valid frames
(bit flips, byte insertions, deletions, truncations, splices).

Properties: decode_frame raises nothing but FrameError; every frame it
returns is the canonical encoding of what it returned (so its CRC is right
and no byte of the input was ignored); the stream Decoder never raises,
yields only frames present whole in its input, with advancing sequence
numbers, and counts every non-empty segment exactly once.

Usage: fuzz_link_py.py [--iterations N] [--seed S]"""
import argparse
import os
import random
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from bristle.link import Decoder, FrameError, decode_frame, encode_frame, messages, pack  # noqa: E402
from bristle.link.frame import HELLO, PAYLOAD_MAX, SEQ_WINDOW, VERSION  # noqa: E402


def valid_frame(rng):
    if rng.random() < 0.05:
        # hellos of two sessions only: a session opened again (any seq) and the
        # one in force repeated (the window applies) both occur
        return encode_frame(HELLO.id, rng.randrange(65536), pack("hello", session=rng.randrange(1, 3)))
    if rng.random() < 0.5:
        m = rng.choice(messages.MESSAGES)
        vals = {f.name: bytes(rng.randrange(128) for _ in range(16)) if f.type == "c16" else rng.randrange(128)
                for f in m.fields}
        return encode_frame(m.id, rng.randrange(65536), pack(m.name, **vals))
    return encode_frame(rng.randrange(256), rng.randrange(65536),
                        bytes(rng.randrange(256) for _ in range(rng.randrange(PAYLOAD_MAX + 1))),
                        version=VERSION if rng.random() < 0.8 else rng.randrange(256))


def mutate(rng, b):
    b = bytearray(b)
    for _ in range(rng.randrange(1, 4)):
        op = rng.randrange(5)
        i = rng.randrange(len(b) + 1)
        if op == 0 and b:
            b[i % len(b)] ^= 1 << rng.randrange(8)
        elif op == 1:
            b.insert(i, rng.randrange(256))
        elif op == 2 and b:
            del b[i % len(b)]
        elif op == 3:
            del b[i:]
        else:
            b[i:i] = valid_frame(rng)[1:-1]
    return bytes(b)


def check_one(wire, counts):
    try:
        f = decode_frame(wire)
    except FrameError as e:
        counts[e.reason] = counts.get(e.reason, 0) + 1
        return
    canon = encode_frame(f.id, f.seq, f.payload)
    assert wire.strip(b"\x00") == canon[1:-1], (wire.hex(), canon.hex())
    counts["accepted"] = counts.get("accepted", 0) + 1


def check_stream(stream):
    d = Decoder()
    frames = d.feed(stream)
    last, session = None, None
    for f in frames:
        assert encode_frame(f.id, f.seq, f.payload)[1:] in stream
        # a hello of another session than the one in force opens one: any seq
        opens = f.id == HELLO.id and len(f.payload) == HELLO.size and int.from_bytes(f.payload, "little") != session
        if last is not None and not opens:
            assert 1 <= ((f.seq - last) & 0xFFFF) <= SEQ_WINDOW
        if opens:
            session = int.from_bytes(f.payload, "little")
        last = f.seq
    segments = sum(1 for s in stream.split(b"\x00")[:-1] if s)
    assert sum(d.counters.values()) == segments, (d.counters, segments)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--iterations", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    counts = {}
    for _ in range(a.iterations):
        if rng.random() < 0.3:
            wire = bytes(rng.randrange(256) for _ in range(rng.randrange(90)))
        else:
            wire = mutate(rng, valid_frame(rng))
        check_one(wire, counts)
    for _ in range(a.iterations // 20):
        parts = [valid_frame(rng) if rng.random() < 0.5 else mutate(rng, valid_frame(rng)) for _ in range(8)]
        check_stream(b"".join(parts))
    print("%d inputs, seed %d: %s" % (a.iterations, a.seed, dict(sorted(counts.items()))))


if __name__ == "__main__":
    main()
