# SPDX-License-Identifier: Apache-2.0
"""What a cause's evidence sentence is computed from: the nominal model's
residual over the log (edges left out) and the motion it goes with."""
import numpy as np


class Residual:
    def __init__(self, prep, e):
        w = prep.whole
        self.prep = prep
        self.e = e[w]                 # residual, N
        self.v = prep.v[w]            # interval velocity, m/s
        self.x = prep.xm[w]           # interval position, m
        self.v95 = float(np.percentile(np.abs(self.v), 95))
        self.moving = np.abs(self.v) > 0.2 * self.v95
