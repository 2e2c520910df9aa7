#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bristle.link.record (docs/link.md, "The recorder"): a dump's frames into
rows and each refusal, telemetry rows, and the measured-log CSV in the units
of a machine file (machines/reference.json), checked against the spec's
definitions (../shared/spec/measured-log.md)."""
import csv
import json
import math
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")

from bristle.link import Decoder, DumpError, dump_rows, encode_frame, messages, pack, telemetry_rows  # noqa: E402
from bristle.link.record import SAMPLE_NAMES, write_measured_log  # noqa: E402


def sample(t):
    return dict(tick=t, counts=1000 + 3 * t, ref_counts=1000 + 3 * t, ref_frac=0.25, duty=0.5 - t / 64.0,
                F_hat_N=1.5, n_outliers=0, status=0, fault=0, flags=0)


def frames(msgs):
    wire = b"".join(encode_frame(messages.BY_NAME[n].id, k, pack(n, **v)) for k, (n, v) in enumerate(msgs))
    return Decoder().feed(wire)


def end(count, trigger_index=0, state=2):
    return ("rec_end", dict(count=count, trigger_index=trigger_index, trigger_tick=7, cause=2, state=state,
                            missed_faults=0))


def chunk(i, t=None):
    return ("rec_sample", dict(index=i, **sample(i if t is None else t)))


def refused(msgs, words):
    try:
        dump_rows(frames(msgs))
    except DumpError as e:
        assert all(w in str(e) for w in words), (str(e), words)
        return
    raise AssertionError("accepted: %r" % (msgs,))


def test_dump_rows():
    # out of order, one sample sent again (a dump asked again from an index), a telemetry frame between
    msgs = [chunk(2), chunk(0), ("tlm_sample", sample(9)), chunk(1), chunk(2), end(3, 1)]
    cap = dump_rows(frames(msgs))
    assert cap.rows == [sample(0), sample(1), sample(2)] and cap.trigger_index == 1 and cap.cause == "command"
    assert telemetry_rows(frames(msgs)) == [sample(9)]
    assert SAMPLE_NAMES == tuple(sample(0))


def test_dump_refusals():
    refused([chunk(0), chunk(1)], ["no rec_end"])
    refused([end(0, state=0)], ["no complete capture", "armed"])
    refused([chunk(0), chunk(2), end(3)], ["1 of 3 samples missing", "[1]"])
    refused([chunk(0), chunk(1), chunk(5), end(2)], ["1 beyond"])
    refused([chunk(0), chunk(0, t=4), end(1)], ["index 0 came twice"])


def test_measured_log():
    with open(os.path.join(ROOT, "machines", "reference.json"), encoding="utf-8") as f:
        m = json.load(f)
    rows = [sample(t) for t in range(10, 20)]
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "log.csv")
        write_measured_log(rows, m, path)
        with open(path, newline="", encoding="utf-8") as f:
            got = list(csv.DictReader(f))
        # the spec's columns first; the units from the machine file: metres on the
        # load per count (lead / counts per revolution), force = torque / L
        assert list(got[0])[:4] == ["t", "ref", "pos", "force"]
        lead, cpr = m["mechanics"]["lead_m_per_rev"], m["encoder"]["counts_per_rev"]
        L = lead / (2 * math.pi)
        for r, g in zip(rows, got):
            assert math.isclose(float(g["t"]), (r["tick"] - 10) * m["control"]["period_s"], abs_tol=1e-15)
            assert math.isclose(float(g["pos"]), (r["counts"] + 0.5) * lead / cpr, rel_tol=1e-15)
            assert math.isclose(float(g["ref"]), (r["ref_counts"] + 0.25) * lead / cpr, rel_tol=1e-15)
            assert math.isclose(float(g["force"]), r["duty"] * m["amplifier"]["torque_per_duty_Nm"] / L,
                                rel_tol=1e-15)
        for bad, words in (([rows[0]], "two rows"), (rows[:3] + rows[4:], "not evenly spaced"),
                           ([rows[1], rows[0]], "not evenly spaced")):
            try:
                write_measured_log(bad, m, path)
            except DumpError as e:
                assert words in str(e), (str(e), words)
            else:
                raise AssertionError("accepted %d rows" % len(bad))


if __name__ == "__main__":
    for name, fn in sorted(globals().items()):
        if name.startswith("test_") and callable(fn):
            fn()
            print("ok", name)
    sys.exit(0)
