# SPDX-License-Identifier: Apache-2.0
"""From a log to the quantities the force model is fitted on.

Filter: a 4th-order Butterworth low-pass at FC_HZ (FC_MAX_FRAC of Nyquist at
most), run forward and backward (zero phase), applied to the measured
position and, identically, to the measured force ("parallel filtering": both
sides of the fit see the same filter; relerr is computed on the filtered force).

Each sample interval k (t_k .. t_k+1) is one equation: the force logged at
t_k is held over it (zero-order hold, what a digital controller does), so

  y_k  = filtered force at t_k
  v_k  = (xf_k+1 - xf_k) / dt                 mean velocity over the interval
  a_k  = (w_k+1 - w_k) / dt,  w_k = (xf_k+1 - xf_k-1) / (2 dt)
                                              mean acceleration over the interval
  xm_k = (xf_k + xf_k+1) / 2                  position of the interval

with xf the filtered position. The first and last EDGE_S seconds (at least
EDGE_MIN samples) are left out of every fit and error (filter transients).

Held-out split: the fit uses the first TRAIN_FRAC of the remaining
intervals; every relerr the report gives is measured on the rest, the last
(1 - TRAIN_FRAC) of the log in time.
"""
import numpy as np
from scipy import signal

from .params import GT0, Param

FC_HZ = 50.0
FC_PARAM = Param("fc_hz", "Hz", "the low-pass cutoff (--fc, model.json's filter)", GT0, 1e6)
FC_MAX_FRAC = 0.4
ORDER = 4
EDGE_S = 0.15
EDGE_MIN = 50
TRAIN_FRAC = 0.7
MEMO_MAX = 64
MEMO_BYTES = 128 << 20      # the memo's arrays at most (a long log: a few entries)


class Prepared:
    """Interval quantities of one log, the filter, and the train/held-out split."""

    def __init__(self, log, fc_hz=FC_HZ, train_frac=TRAIN_FRAC):
        self.path = log.path
        self.dt = log.dt
        self.fc_hz = min(fc_hz, FC_MAX_FRAC * 0.5 / log.dt)
        self._b, self._a = signal.butter(ORDER, self.fc_hz / (0.5 / log.dt))
        self.t = log.t
        self.ref = log.ref
        self.pos = log.pos
        self.force = log.force
        self.xf = self.lp(log.pos)
        dt = log.dt
        w = np.gradient(self.xf, dt)
        self.v = np.diff(self.xf) / dt
        self.a = np.diff(w) / dt
        self.xm = 0.5 * (self.xf[1:] + self.xf[:-1])
        self.dx = np.diff(log.pos)  # the measured path: the bristle state depends on it
        self.y = self.lp(log.force)[:-1]
        self.n = len(self.v)  # intervals
        edge = max(EDGE_MIN, int(round(EDGE_S / dt)))
        if self.n < 4 * edge + 100:
            raise ValueError(f"{log.path}: {log.n} samples are too few for the diagnosis "
                             f"(at least {4 * edge + 101} needed)")
        self.lo, self.hi = edge, self.n - edge
        self.split = self.lo + int(train_frac * (self.hi - self.lo))
        self.train = slice(self.lo, self.split)
        self.test = slice(self.split, self.hi)
        self.whole = slice(self.lo, self.hi)
        self.train_frac = train_frac
        self._memo = {}
        self._memo_bytes = 0

    def lp(self, x):
        """The zero-phase low-pass applied to every signal."""
        return signal.filtfilt(self._b, self._a, x)

    def memo(self, key, make):
        """Per-log memo of column blocks (the searches reuse them many times):
        make() once per key; a bounded store (MEMO_MAX entries, MEMO_BYTES of
        arrays), cleared when full. Only a cache: the results are the same
        whatever it holds."""
        if key not in self._memo:
            value = make()
            size = _nbytes(value)
            if len(self._memo) > MEMO_MAX or self._memo_bytes + size > MEMO_BYTES:
                self._memo.clear()
                self._memo_bytes = 0
            self._memo[key] = value
            self._memo_bytes += size
        return self._memo[key]

    def forget(self, key):
        self._memo_bytes -= _nbytes(self._memo.pop(key, None))

    def held_out_description(self):
        t0, t1 = self.t[self.split], self.t[self.hi]
        return (f"the last {100 * (1 - self.train_frac):.0f} % of the log in time, "
                f"t = {t0:.3f} .. {t1:.3f} s ({self.hi - self.split} samples); the fit used "
                f"t = {self.t[self.lo]:.3f} .. {t0:.3f} s")


def _nbytes(v):
    """Bytes of the arrays in a memo entry (an array, or a dict or tuple of them)."""
    if isinstance(v, np.ndarray):
        return v.nbytes
    if isinstance(v, dict):
        return sum(_nbytes(x) for x in v.values())
    if isinstance(v, (tuple, list)):
        return sum(_nbytes(x) for x in v)
    return 0


def relerr(y, e):
    """100 ||e|| / ||y|| in percent."""
    ny = float(np.linalg.norm(y))
    return 100.0 * float(np.linalg.norm(e)) / ny if ny > 0 else float("inf")
