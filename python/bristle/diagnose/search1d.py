# SPDX-License-Identifier: Apache-2.0
"""The one-parameter search the cause modules with one nonlinear parameter
share (causes/position_gradient.py, friction_drift.py, actuator_delay.py;
docs/diagnose.md, "Causes"): the fit's sum of squares on a grid, then a
bounded scalar search between the best grid point's two neighbours."""
import numpy as np
from scipy import optimize


def grid_then_bounded(sse, grid, xatol):
    """The x that minimises sse(x): the best point of grid (ascending), then
    scipy's bounded search over the interval its neighbours span, to xatol;
    the grid point itself where that interval is empty (a one-point grid)."""
    vals = [sse(x) for x in grid]
    i = int(np.argmin(vals))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if b <= a:
        return float(grid[i])
    r = optimize.minimize_scalar(sse, bounds=(a, b), method="bounded", options={"xatol": xatol})
    return float(r.x)
