# SPDX-License-Identifier: Apache-2.0
"""A trajectory file as the link's reference items (docs/link.md, "The host
tool"): a CSV of time (s) and position (m) turned into timed setpoints, one
per control period, or cubic segments of a number of periods each, in the
target's encoder counts (the machine file's lead and counts_per_rev).

The file: a header naming the columns `t` and a position column (`pos`,
`position` or `ref`: a measured log's reference streams as it is), then rows
of finite numbers, t strictly increasing, at least two rows, at most
MAX_DURATION_S long. Between rows the position is linear in t; its speed (a
central difference) and acceleration must stay within the machine file's
limits (max_speed_mps, max_accel_mps2), else TrajectoryError: the firmware's
reference limiter would clip a faster reference, and the log would not be
the move that was asked for."""
import csv
import math

import numpy as np

POSITION_NAMES = ("pos", "position", "ref")
MAX_DURATION_S = 3600.0   # the host tools' duration bound (docs/tools.md)
FLAG_LAST = 1             # BR_REFQ_FLAG_LAST: the stream's last item
# a reference's speed or acceleration may pass the machine's limit by this
# share: the central differences of a file written at the limit
LIMIT_SLACK = 1.01


class TrajectoryError(ValueError):
    """A trajectory file the tool refuses: the file, the line, the problem."""


def read_trajectory(path):
    """(t, pos) float64 arrays of the file (above)."""
    with open(path, newline="", encoding="utf-8-sig") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise TrajectoryError("%s: empty" % path)
    head = [c.strip().strip('"').lower() for c in rows[0]]
    if "t" not in head or not any(n in head for n in POSITION_NAMES):
        raise TrajectoryError("%s:1: the header must name t and one of %s" % (path, ", ".join(POSITION_NAMES)))
    it = head.index("t")
    ip = head.index(next(n for n in POSITION_NAMES if n in head))
    t, p = [], []
    for ln, r in enumerate(rows[1:], start=2):
        if len(r) != len(head):
            raise TrajectoryError("%s:%d: %d fields, the header has %d" % (path, ln, len(r), len(head)))
        try:
            tv, pv = float(r[it]), float(r[ip])
        except ValueError as e:
            raise TrajectoryError("%s:%d: not a number (%s)" % (path, ln, e)) from e
        if not (math.isfinite(tv) and math.isfinite(pv)):
            raise TrajectoryError("%s:%d: not finite" % (path, ln))
        if t and tv <= t[-1]:
            raise TrajectoryError("%s:%d: t %g not after %g" % (path, ln, tv, t[-1]))
        t.append(tv)
        p.append(pv)
    if len(t) < 2:
        raise TrajectoryError("%s: two rows or more needed" % path)
    if t[-1] - t[0] > MAX_DURATION_S:
        raise TrajectoryError("%s: %g s long, at most %g" % (path, t[-1] - t[0], MAX_DURATION_S))
    return np.array(t) - t[0], np.array(p)


def check_limits(t, p, machine, path="trajectory"):
    """TrajectoryError when the file's speed or acceleration (differences
    between its rows) passes the machine file's limits."""
    lim = machine["limits"]
    v = np.diff(p) / np.diff(t)
    vmax = float(np.max(np.abs(v)))
    if vmax > lim["max_speed_mps"] * LIMIT_SLACK:
        raise TrajectoryError("%s: speed %.4g m/s above the machine's max_speed_mps %g"
                              % (path, vmax, lim["max_speed_mps"]))
    if len(v) > 1:
        a = np.diff(v) / (0.5 * (t[2:] - t[:-2]))
        amax = float(np.max(np.abs(a)))
        if amax > lim["max_accel_mps2"] * LIMIT_SLACK:
            raise TrajectoryError("%s: acceleration %.4g m/s^2 above the machine's max_accel_mps2 %g"
                                  % (path, amax, lim["max_accel_mps2"]))


def counts_per_m(machine):
    return machine["encoder"]["counts_per_rev"] / machine["mechanics"]["lead_m_per_rev"]


def _split(c):
    """a position in counts as (whole, fraction in [0, 1) in float32)"""
    w = math.floor(c)
    f = float(np.float32(c - w))
    if f >= 1.0:  # rounded up to 1 in float32
        w, f = w + 1, 0.0
    return int(w), f


def _at(t, p, tq):
    """position (linear between rows, held outside) and speed (a central
    difference over one period-sized step) at times tq"""
    pos = np.interp(tq, t, p)
    h = 0.5 * float(np.min(np.diff(t)))
    vel = (np.interp(tq + h, t, p) - np.interp(tq - h, t, p)) / (2.0 * h)
    return pos, vel


def setpoints(t, p, machine, period_s, tick0, offset_m=0.0, last=True):
    """One setpoint message per period from tick0 (its fields as a dict, for
    messages.pack("setpoint", ...)) over the file's duration."""
    n = int(math.floor(t[-1] / period_s + 1e-9)) + 1
    tq = np.arange(n) * period_s
    pos, vel = _at(t, p, tq)
    cpm = counts_per_m(machine)
    rad_per_m = 2.0 * math.pi / machine["mechanics"]["lead_m_per_rev"]
    out = []
    for k in range(n):
        w, f = _split((pos[k] + offset_m) * cpm)
        out.append({"tick": tick0 + k, "counts": w, "frac": f, "omega_radps": float(vel[k] * rad_per_m),
                    "flags": FLAG_LAST if (last and k == n - 1) else 0})
    return out


def segments(t, p, machine, period_s, tick0, periods, offset_m=0.0, last=True):
    """Cubic segments of `periods` periods each (the last one shorter) from
    tick0: over each, the cubic through the positions and speeds at its two
    ends (Hermite), p(s) = p0 + v0 s + a s^2 / 2 + j s^3 / 6, s the time into
    it, in counts (the firmware's refq-2)."""
    n = int(math.floor(t[-1] / period_s + 1e-9))
    cpm = counts_per_m(machine)
    out = []
    for k0 in range(0, max(n, 1), periods):
        m = min(periods, n - k0) if n else 1
        T = m * period_s
        (p0, p1), (v0, v1) = _at(t, p, np.array([k0 * period_s, (k0 + m) * period_s]))
        p0, p1 = (p0 + offset_m) * cpm, (p1 + offset_m) * cpm
        v0, v1 = v0 * cpm, v1 * cpm
        # Hermite: a/2 = (3 (p1 - p0) - (2 v0 + v1) T) / T^2, j/6 = (2 (p0 - p1) + (v0 + v1) T) / T^3
        a = 2.0 * (3.0 * (p1 - p0) - (2.0 * v0 + v1) * T) / T ** 2
        j = 6.0 * (2.0 * (p0 - p1) + (v0 + v1) * T) / T ** 3
        w, f = _split(p0)
        out.append({"tick": tick0 + k0, "periods": m, "counts": w, "frac": f, "v_cps": float(v0),
                    "a_cps2": float(a), "j_cps3": float(j), "flags": 0})
    if last:
        out[-1]["flags"] = FLAG_LAST
    return out


def item_end(item):
    """the period after an item's last one"""
    return item["tick"] + item.get("periods", 1)
