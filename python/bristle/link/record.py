# SPDX-License-Identifier: Apache-2.0
"""The recorder's and telemetry's samples on the host (docs/link.md,
"Telemetry" and "The recorder"): a dump's frames into rows, telemetry frames
into rows, and rows into the measured-log CSV the diagnosis reads
(../shared/spec/measured-log.md: t, ref, pos, force).

A row is a dict of the sample's fields (messages.SAMPLE_FIELDS: tick,
counts, ref_counts, ref_frac, duty, F_hat_N, n_outliers, status, fault,
flags), as the firmware packed them."""
import csv
import math
from dataclasses import dataclass

from . import messages

SAMPLE_NAMES = tuple(f.name for f in messages.SAMPLE_FIELDS)
TRIGGER_CAUSES = {0: "none", 1: "fault", 2: "command", 3: "condition"}
STATES = {0: "armed", 1: "collecting", 2: "done"}


class DumpError(ValueError):
    """A dump that cannot be turned into rows: no rec_end, no complete
    capture, a sample missing, or one index with two different samples."""


@dataclass(frozen=True)
class Capture:
    rows: list             # the samples, oldest first
    trigger_index: int     # rows[trigger_index] is the trigger sample
    trigger_tick: int
    cause: str             # TRIGGER_CAUSES' names
    missed_faults: int     # faults that latched while this capture was held


def _messages(frames):
    for fr in frames:
        yield messages.unpack(fr.id, fr.payload)


def dump_rows(frames):
    """The capture of a dump: frames (bristle.link Frame, in arrival order,
    e.g. Decoder.feed's) holding rec_sample frames and the rec_end that closes
    them; other messages are passed over, and a sample sent again (a dump
    asked again from an index) must be the same sample."""
    got, end = {}, None
    for name, v in _messages(frames):
        if name == "rec_sample":
            row = {k: v[k] for k in SAMPLE_NAMES}
            if got.setdefault(v["index"], row) != row:
                raise DumpError("index %d came twice with different samples" % v["index"])
        elif name == "rec_end":
            end = v
    if end is None:
        raise DumpError("no rec_end: the dump is not finished")
    n = end["count"]
    if n == 0:
        raise DumpError("no complete capture on the target (state %s)" % STATES.get(end["state"], end["state"]))
    missing = [i for i in range(n) if i not in got]
    extra = sorted(i for i in got if i >= n)
    if missing or extra:
        raise DumpError("%d of %d samples missing (first %s), %d beyond the capture"
                        % (len(missing), n, missing[:1], len(extra)))
    return Capture([got[i] for i in range(n)], end["trigger_index"], end["trigger_tick"],
                   TRIGGER_CAUSES.get(end["cause"], str(end["cause"])), end["missed_faults"])


def telemetry_rows(frames):
    """The tlm_sample frames' samples, in arrival order (a gap in the ticks is
    a sample the target dropped or the wire lost)."""
    return [v for name, v in _messages(frames) if name == "tlm_sample"]


def machine_scales(machine):
    """What the log's units need from a machine file (machines/*.json, read
    as JSON): the control period (s), metres per encoder count on the load
    (lead / counts_per_rev) and newtons per unit duty on the load
    (torque_per_duty_Nm / L, L = lead / 2 pi)."""
    lead = machine["mechanics"]["lead_m_per_rev"]
    return {"period_s": machine["control"]["period_s"],
            "m_per_count": lead / machine["encoder"]["counts_per_rev"],
            "N_per_duty": machine["amplifier"]["torque_per_duty_Nm"] / (lead / (2.0 * math.pi))}


def write_measured_log(rows, machine, path):
    """rows (oldest first, ticks evenly spaced) as a measured log: t from the
    first row's tick, ref the limited reference, pos the count's centre (as
    the estimator sees it), force the commanded force (duty through the
    amplifier and the screw); then F_hat_N and fault, which the diagnosis
    ignores. DumpError for fewer than two rows or uneven ticks."""
    if len(rows) < 2:
        raise DumpError("a log needs two rows or more")
    step = rows[1]["tick"] - rows[0]["tick"]
    for a, b in zip(rows, rows[1:]):
        if b["tick"] - a["tick"] != step or step <= 0:
            raise DumpError("ticks %d, %d: not evenly spaced (a dropped sample)" % (a["tick"], b["tick"]))
    sc = machine_scales(machine)
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["t", "ref", "pos", "force", "F_hat_N", "fault"])
        for r in rows:
            w.writerow([repr((r["tick"] - rows[0]["tick"]) * sc["period_s"]),
                        repr((r["ref_counts"] + r["ref_frac"]) * sc["m_per_count"]),
                        repr((r["counts"] + 0.5) * sc["m_per_count"]),
                        repr(r["duty"] * sc["N_per_duty"]), repr(r["F_hat_N"]), r["fault"]])
