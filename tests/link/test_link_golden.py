#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Golden frames, C to Python (docs/link.md): the target's reports the
firmware encodes (br_link_emit, from the values of tests/link/gen_golden.py)
decode with bristle.link to those values, and are byte for byte what
bristle.link encodes from them.

Usage: test_link_golden.py --emit BIN --work DIR"""
import argparse
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import gen_golden  # noqa: E402
from bristle.link import Decoder, encode_frame, messages, pack, unpack  # noqa: E402


def emitted(name, argv=None):
    """The bytes the emitter of --emit BIN writes into DIR/name (--work DIR)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--emit", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args(argv)
    os.makedirs(a.work, exist_ok=True)
    path = os.path.join(a.work, name)
    subprocess.run([a.emit, path], check=True)
    with open(path, "rb") as f:
        return f.read()


def main():
    wire = emitted("reports.bin")
    reports = [c for c in gen_golden.CASES if messages.BY_NAME[c[0]].direction == messages.TO_HOST]
    assert len(reports) == 8, reports
    dec = Decoder()
    frames = dec.feed(wire)
    assert len(frames) == len(reports), (len(frames), dec.counters)
    assert dec.counters["frames"] == len(reports) and sum(dec.counters.values()) == len(reports), dec.counters
    for fr, (name, seq, values) in zip(frames, reports):
        got_name, got = unpack(fr.id, fr.payload)
        assert (got_name, fr.seq, got) == (name, seq, values), (got_name, fr.seq, got, name, seq, values)
    expect = b"".join(encode_frame(messages.BY_NAME[n].id, s, pack(n, **v)) for n, s, v in reports)
    assert wire == expect, (wire.hex(), expect.hex())
    print("C's %d reports (%d bytes) decode in Python to their values; bytes equal" % (len(frames), len(wire)))


if __name__ == "__main__":
    main()
