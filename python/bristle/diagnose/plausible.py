# SPDX-License-Identifier: Apache-2.0
"""Samples no axis could produce (docs/diagnose.md, "Impossible samples").

The machine's limits, from the firmware machine file given with --machine,
else from machines/reference.json (the machine machine.json assumes then):

  force limit   F_max = 2 pi torque_limit_Nm / lead_m_per_rev   (the amplifier's
                torque at its limit, at the load)
  speed limit   v_max = limits.max_speed_mps

A sample is impossible when it is beyond a margin times a limit: a force
|F_k| > MARGIN F_max, or a position that no motion at SPEED_MARGIN v_max can
reach from the last possible sample v, |x_k - x_v| > SPEED_MARGIN v_max
(k - v) dt. MARGIN leaves room for a machine file whose limit is
conservative (the logged force of a saturated axis is the limit plus its
noise). SPEED_MARGIN is wider: max_speed_mps is the speed the axis is used
at, not one it cannot exceed (the reference plant with a few ms of dead time
oscillates to 2.5 times it in the hidden-cause suite); an encoder glitch (a
lost word, a wrap) jumps by millimetres in one period. The position is walked
from the first sample forwards and from the last backwards; the walk that
finds fewer impossible samples is kept (a glitch on the first sample would
otherwise make every later one unreachable).

What is done: an impossible cell is replaced by linear interpolation between
the nearest possible samples of its column, and the report lists the rows
(file line, time, value) and the action. A log with more than MAX_FRACTION of
its rows impossible, or a run of more than MAX_RUN consecutive impossible
samples (a permanent jump of the position, a force column in other units), is
refused: interpolating over it would invent the data.
"""
import math

import numpy as np

from . import logreader

MARGIN = 2.0
SPEED_MARGIN = 10.0
MAX_FRACTION = 0.01
MAX_RUN = 10
LIST_ROWS = 20      # rows the report lists per column (the count is always given)
REFERENCE = "machines/reference.json"


def limits(machine_path=None):
    """(force_N, speed_mps, source) of the machine file (a firmware machine
    file, format 2), else of machines/reference.json."""
    from . import machinejson
    mach = machinejson._loader()
    m = mach.load(machine_path or mach.REFERENCE_MACHINE)
    force = 2.0 * math.pi * m["control"]["torque_limit_Nm"] / m["mechanics"]["lead_m_per_rev"]
    source = m["file"] if machine_path else f"{REFERENCE} (assumed: no machine file given)"
    return force, m["limits"]["max_speed_mps"], source


def _runs(flags):
    """Longest run of True in a boolean array."""
    if not flags.any():
        return 0
    d = np.diff(np.concatenate(([0], flags.view(np.int8), [0])))
    return int((np.flatnonzero(d == -1) - np.flatnonzero(d == 1)).max())


def _walk(x, step):
    """Samples the forward walk finds unreachable: after a step beyond `step`,
    every sample until one is reachable again from the last reachable one.
    Bounded: gives up (returns None) after MAX_RUN + 1 unreachable in a row."""
    bad = np.zeros(len(x), dtype=bool)
    jumps = np.flatnonzero(np.abs(np.diff(x)) > step)
    k_done = 0
    for j in jumps:
        if j < k_done:
            continue
        v, k = j, j + 1
        while k < len(x) and abs(x[k] - x[v]) > step * (k - v):
            bad[k] = True
            k += 1
            if k - v > MAX_RUN + 1:
                return None
        k_done = k
    return bad


def _position_flags(x, step):
    fwd = _walk(x, step)
    bwd = _walk(x[::-1], step)
    bwd = None if bwd is None else bwd[::-1]
    cands = [b for b in (fwd, bwd) if b is not None]
    if not cands:
        return None
    return min(cands, key=lambda b: int(b.sum()))


def _lines(path, idx):
    """File lines of the samples idx (sorted, few): a second streaming pass."""
    want = {int(i): None for i in idx}
    top = max(want) if want else -1
    for k, (lineno, *_row) in enumerate(logreader._rows(path)):
        if k in want:
            want[k] = lineno
        if k >= top:
            break
    return want


def _refuse(lg, what, first_line, detail):
    raise logreader.LogError(lg.path, first_line, f"{what}: {detail}; no axis within the machine's limits produces "
                                                  "this (pass --machine with the axis's own machine file if its "
                                                  "limits are higher)")


def check(lg, machine_path=None):
    """Repairs lg in place (force and pos) and returns the report's
    "impossible_samples" object, or None when every sample is possible.
    Raises LogError when the log is refused."""
    f_max, v_max, source = limits(machine_path)
    f_lim, step = MARGIN * f_max, SPEED_MARGIN * v_max * lg.dt
    force_bad = ~(np.abs(lg.force) <= f_lim)
    pos_bad = _position_flags(lg.pos, step)
    n = lg.n
    if pos_bad is None:
        j = int(np.flatnonzero(np.abs(np.diff(lg.pos)) > step)[0])
        line = _lines(lg.path, [j + 1])[j + 1]
        _refuse(lg, f"the position jumps by {lg.pos[j + 1] - lg.pos[j]:.6g} m in one period and stays away "
                    f"for more than {MAX_RUN} samples", line,
                f"beyond {SPEED_MARGIN:g} x max_speed_mps {v_max:g} m/s ({source})")
    if not force_bad.any() and not pos_bad.any():
        return None
    out = {"limits": {"force_N": f_max, "speed_mps": v_max, "force_margin": MARGIN, "speed_margin": SPEED_MARGIN,
                      "source": source},
           "action": "replaced by linear interpolation between the nearest possible samples of the column"}
    for name, bad, col, unit, limit in (("force", force_bad, lg.force, "N", f"{f_lim:g} N (the amplifier's "
                                         f"{f_max:.4g} N x {MARGIN:g})"),
                                        ("pos", pos_bad, lg.pos, "m", f"a speed of {SPEED_MARGIN:g} x {v_max:g} m/s")):
        idx = np.flatnonzero(bad)
        if len(idx) == 0:
            continue
        shown = idx[:LIST_ROWS]
        lines = _lines(lg.path, shown)
        count, run = len(idx), _runs(bad)
        if count > MAX_FRACTION * n or run > MAX_RUN:
            _refuse(lg, f"column '{name}': {count} of {n} samples beyond {limit} ({source}), "
                        f"the longest run {run} samples", lines[int(idx[0])],
                    f"more than {100 * MAX_FRACTION:g} % of the rows or a run of more than {MAX_RUN}")
        out[name] = {"count": count, "limit": limit,
                     "rows": [{"line": lines[int(i)], "t_s": float(lg.t[i]), "value": float(col[i])}
                              for i in shown]}
        good = np.flatnonzero(~bad)
        col[idx] = np.interp(idx, good, col[good])
    return out


def describe(imp):
    """One line per column for the log and report.md."""
    out = []
    for name in ("force", "pos"):
        if imp and name in imp:
            c = imp[name]
            rows = ", ".join(f"line {r['line']} ({r['value']:.6g})" for r in c["rows"])
            more = f" and {c['count'] - len(c['rows'])} more" if c["count"] > len(c["rows"]) else ""
            out.append(f"{c['count']} impossible sample(s) of column '{name}' (beyond {c['limit']}, "
                       f"{imp['limits']['source']}): {rows}{more}; {imp['action']}")
    return out

