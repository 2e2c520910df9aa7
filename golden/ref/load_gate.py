# SPDX-License-Identifier: Apache-2.0
"""Glitch or load: the rule by which the external-force state of either
filter takes a gated innovation for a load, float64 golden reference written
from docs/modules/est.md, "Glitch or load" (not from br_load_gate.c).

A force change dF after the last update moves theta by g k^2 dF after k
periods (g = L h^2 / (2 J_eff)); a glitch does not grow. State: the held
candidate (nu1, k1) or None, the window counter w, the count of held
candidates.
  period start:           w -= 1 when w > 0
  passed / re-anchored:   candidate dropped
  gated nu, k0 periods after the last measurement, k = k1 + k0 with a
  candidate, else k0; first match:
    |nu / (g k^2)| > 2 max_N        outlier, candidate dropped
    w > 0                           re-acquired over k
    candidate and nu / nu1 >= (k / k1)^2 / 2
                                    re-acquired over k
    else                            held: (nu1, k1) = (nu, k), an outlier
  a re-acquisition drops the candidate and sets w = LIVE_PERIODS.
"""

LIVE_PERIODS = 3   # w after a re-acquisition (rule b holds at the next two periods)
GROWTH_SHARE = 0.5  # the share of a force's growth (k / k1)^2 the next innovation must reach


class LoadGate:
    def __init__(self):
        self.cand = None    # (nu1, k1): the held candidate
        self.w = 0
        self.n_held = 0

    def tick(self):
        """The start of a period (a step or a predict-only period)."""
        if self.w > 0:
            self.w -= 1

    def passed(self):
        """A measurement inside the gate, or a re-anchoring."""
        self.cand = None

    def gated(self, nu, k0, g, max_N):
        """A gated innovation nu (rad, measurement - prediction) k0 periods
        after the last measurement: the periods k over which a force change
        explains it, to re-acquire, or 0 (an outlier: held when a force
        within 2 max_N explains it)."""
        k = k0 + (self.cand[1] if self.cand is not None else 0)
        # no force change within twice the bound explains nu over k periods
        if abs(nu / (g * k * k)) > 2.0 * max_N:
            self.cand = None
            return 0
        # a load re-acquired in the last two periods: changing, at once
        if self.w > 0:
            return self._reacquire(k)
        # the candidate confirmed: nu grew by at least half a force's (k / k1)^2
        if self.cand is not None:
            nu1, k1 = self.cand
            if nu / nu1 >= GROWTH_SHARE * (k / k1) ** 2:
                return self._reacquire(k)
        self.cand = (nu, k)
        self.n_held += 1
        return 0

    def _reacquire(self, k):
        self.cand = None
        self.w = LIVE_PERIODS
        return k

    def columns(self):
        """The state for a trace row: nu1 (0: none), k1, w."""
        return [0.0, 0, self.w] if self.cand is None else [self.cand[0], self.cand[1], self.w]
