# SPDX-License-Identifier: Apache-2.0
"""Unit mistakes a log can show on its face, caught before the fit
(docs/diagnose.md, "Unit checks"): the measured-log format is s, m, N at
the load (../shared/spec/measured-log.md), and three slips are common:

  time in ms      the sample period is about 1000 times the machine's
                  control period (and at least MS_MIN_DT_S)
  positions in mm the travel or the speed is more than SCALE_OFF times the
                  machine's travel_m / max_speed_mps, and a thousandth of
                  them is within FITS times of it
  force in N m    the sliding force (the median |force| while moving) is
                  under NM_MAX_FRACTION of the machine's Coulomb level, and
                  times 2 pi / lead it is within FITS times of it (a motor
                  torque: force = torque 2 pi / lead)

Each is refused with a message naming the likely unit. The machine's
values are the given machine file's, else the reference machine's.
"""
import math

import numpy as np

from .logreader import LogError

SCALE_OFF = 20.0          # a quantity this many times the machine's is not in the stated unit
FITS = 5.0                # ... and converted it must be within this factor of the machine's
MS_MIN_DT_S = 0.05        # a period this long is not a servo log's in seconds
NM_MAX_FRACTION = 0.02    # a sliding force under 2 % of the machine's Coulomb level
SMOOTH = 10               # samples over which the speed is averaged (encoder steps)


def _within(x, ref):
    return ref / FITS <= x <= ref * FITS


def _speed(pos, dt):
    """|speed| averaged over SMOOTH samples."""
    n = min(SMOOTH, len(pos) - 1)
    return np.abs(pos[n:] - pos[:-n]) / (n * dt)


def check(lg, machine):
    """Raises LogError naming the likely unit when the log's scale shows one
    of the three mistakes against the machine file's values."""
    path = lg.path
    period = machine["control"]["period_s"]
    # time in ms: the period 1000 times the machine's
    if lg.dt >= MS_MIN_DT_S and lg.dt >= SCALE_OFF * period and _within(lg.dt / 1000.0, period):
        raise LogError(path, 0, f"the time column looks like milliseconds: the sample period is {lg.dt:g} s where "
                                f"the machine's control period is {period:g} s; write t in seconds")
    travel, vmax = machine["limits"]["travel_m"], machine["limits"]["max_speed_mps"]
    span = float(np.ptp(lg.pos))
    speed = _speed(lg.pos, lg.dt)
    v99 = float(np.percentile(speed, 99))
    if (span > SCALE_OFF * travel or v99 > SCALE_OFF * vmax) and span / 1000.0 <= FITS * travel and \
            v99 / 1000.0 <= FITS * vmax:
        raise LogError(path, 0, f"the positions look like millimetres: the log spans {span:g} m at up to "
                                f"{v99:g} m/s where the machine's travel is {travel:g} m and its top speed "
                                f"{vmax:g} m/s; write ref and pos in metres")
    # force in N m: the sliding force a lead's 2 pi / lead too small
    fc = machine["friction"]["Fc_N"]
    k = 2.0 * math.pi / machine["mechanics"]["lead_m_per_rev"]
    moving = speed > 0.1 * v99 if v99 > 0 else np.zeros(len(speed), bool)
    if moving.sum() >= 100:
        f_slide = float(np.median(np.abs(lg.force[:len(speed)][moving])))
        if f_slide < NM_MAX_FRACTION * fc and _within(f_slide * k, fc):
            raise LogError(path, 0, f"the force looks like a motor torque in N m: the axis slides at {f_slide:.3g} "
                                    f"while the machine's Coulomb friction alone is {fc:g} N (times 2 pi / lead: "
                                    f"{f_slide * k:.3g} N); write the force at the load, torque x 2 pi / lead, in N")
