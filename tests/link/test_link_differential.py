#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Differential fuzzing of the two decoders (docs/link.md): one long stream
(fixed seed) of random bytes, valid frames, mutated frames and long runs,
decoded by the firmware's decoder (br_link_decode) and by bristle.link's
Decoder: the same frames, in the same order, and the same counters.

Usage: test_link_differential.py --decode BIN --work DIR [--pieces N] [--seed S]"""
import argparse
import os
import random
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from bristle.link import Decoder  # noqa: E402
from fuzz_link_py import mutate, valid_frame  # noqa: E402


def stream(rng, pieces):
    out = bytearray()
    for _ in range(pieces):
        r = rng.random()
        if r < 0.4:
            out += valid_frame(rng)
        elif r < 0.8:
            out += mutate(rng, valid_frame(rng))
        elif r < 0.9:
            out += bytes(rng.randrange(256) for _ in range(rng.randrange(40)))
        else:
            out += bytes([rng.choice((1, 0xFF, rng.randrange(1, 256)))]) * rng.randrange(60, 300)
    return bytes(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--decode", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--pieces", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    data = stream(random.Random(a.seed), a.pieces)
    path = os.path.join(a.work, "stream.bin")
    with open(path, "wb") as f:
        f.write(data)
    c_lines = subprocess.run([a.decode, path], check=True, capture_output=True, text=True).stdout.splitlines()
    d = Decoder()
    py_lines = ["frame %d %d %s" % (f.id, f.seq, f.payload.hex()) for f in d.feed(data)]
    py_lines += ["%s %d" % kv for kv in d.counters.items()]
    if c_lines != py_lines:
        diff = next(i for i, (x, y) in enumerate(zip(c_lines + [""], py_lines + [""])) if x != y)
        raise SystemExit("the decoders differ at line %d: C %r, Python %r" % (diff, c_lines[diff:diff + 1],
                                                                               py_lines[diff:diff + 1]))
    print("%d bytes, %d pieces, seed %d: the same %d frames and counters %s"
          % (len(data), a.pieces, a.seed, d.counters["frames"], d.counters))


if __name__ == "__main__":
    main()
