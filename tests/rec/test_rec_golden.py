#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Golden frames of the recorder, C to Python (docs/link.md): the scripted
run's bytes the firmware sends (br_rec_emit) decode with bristle.link to the
values of tests/rec/gen_rec_golden.py, byte for byte what bristle.link
encodes from them; the dump becomes the samples as rows, the telemetry the
same rows.

Usage: test_rec_golden.py --emit BIN --work DIR"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "link"))

import gen_rec_golden as g  # noqa: E402
from test_link_golden import emitted  # noqa: E402
from bristle.link import Decoder, dump_rows, telemetry_rows, unpack  # noqa: E402


def main():
    wire = emitted("rec.bin")
    dec = Decoder()
    frames = dec.feed(wire)
    want = g.stream_messages()
    assert dec.counters["frames"] == len(want) == len(frames) and sum(dec.counters.values()) == len(want), \
        dec.counters
    for k, (fr, (name, values)) in enumerate(zip(frames, want)):
        assert fr.seq == (g.SEQ0 + k) & 0xFFFF, (k, fr.seq)
        assert unpack(fr.id, fr.payload) == (name, values), (k, unpack(fr.id, fr.payload), name, values)
    assert wire == g.stream(), (wire.hex(), g.stream().hex())
    cap = dump_rows(frames)
    rows = [dict(s) for s in g.SAMPLES]
    assert cap.rows == rows and telemetry_rows(frames) == rows, (cap.rows, rows)
    assert (cap.trigger_index, cap.trigger_tick, cap.cause, cap.missed_faults) == \
        (g.END["trigger_index"], g.END["trigger_tick"], "fault", 0), cap
    print("C's %d frames (%d bytes) decode in Python to their values; bytes equal; the dump is %d rows"
          % (len(frames), len(wire), len(cap.rows)))


if __name__ == "__main__":
    main()
