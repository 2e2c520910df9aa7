# SPDX-License-Identifier: Apache-2.0
"""position_ripple: a force periodic in the load position (screw lead
error, ball recirculation, motor cogging).

Force model: + A sin(2 pi x / P + phase), as a sin and a cos column
(linear), filtered like the force. P is searched: the highest peaks of the
training residual's periodogram over position (PERIODS periods, from the
distance the axis covers in one filter-cutoff period at its 95th-percentile
speed, shorter ones being filtered away, to a third of the travel), each
refined by a bounded search. Plant, closed loop and estimator
(the firmware's extended model): the same load force."""
import math

import numpy as np
from scipy import optimize

from ..params import GT0, Param

NAME = "position_ripple"
MEANING = "a force periodic in position: screw lead error, ball recirculation, motor cogging"
ACTION = ("Compare the period with the screw lead (lead error), the ball circulation length and the motor's "
          "pole pitch (cogging); inspect the screw at that period, or compensate the ripple as a function of "
          "position.")
OPTION = "--ripple"
PARAMS = (Param("ripple_amp_N", "N", "amplitude A of A sin(2πx/P + φ)", -1e5, 1e5),
          Param("ripple_period_m", "m", "its period P in load position", GT0, 10.0),
          Param("ripple_phase_rad", "rad", "its phase φ at x = 0", -1e3, 1e3))
NL = ("ripple_period_m",)
SWITCHES = ("ripple_amp_N",)   # the period and the phase alone are no ripple
OPTION_OPTIONAL = ("ripple_phase_rad",)   # --ripple A,P: phase 0
HOOK = "force"
MACHINE = {"ripple_amp_N": (0.0, 1.0e5, "ripple force amplitude"),
           "ripple_period_m": (0.0, 10.0, "ripple period in load position", True),
           "ripple_phase_rad": (-2.0 * math.pi, 2.0 * math.pi, "phase at x = 0")}
DETECTION = ("ripple amplitude, period 6 mm", "N", 0.002, lambda s, ref: ["--ripple", f"{s:.6g},0.006,1.0"])
CONTROL_CASE = (["--ripple", "1.0,0.004,0.5"], "1 N ripple, 4 mm period")
PERIODS = 400
PEAKS = 3
PERIODOGRAM_DECIMATE = 4     # the residual is low-passed far below the sampling rate
PERIOD_BLOCK = 64            # periods of the periodogram computed together
BLOCK_ELEMS = 1 << 21        # at most this many (16 MB of float64) in one of its arrays


def robustness_draw(c, sgn):
    """The robustness study's plant parameters of this cause from uniforms c[0..2] and a sign."""
    return {"ripple_amp_N": 0.3 + 1.2 * c[0], "ripple_period_m": 0.002 + 0.006 * c[1],
            "ripple_phase_rad": 2.0 * math.pi * c[2]}


def load_columns(prep, nl):
    P = nl["ripple_period_m"]

    def make():
        th = 2.0 * np.pi * prep.xm / P
        return prep.lp(np.sin(th)), prep.lp(np.cos(th))

    s, c = prep.memo(("ripple", P), make)
    return {"ripple_sin": s, "ripple_cos": c}


def position_periodogram(e, x, periods):
    """Amplitude of the best sin/cos fit of e at each period over position x,
    PERIOD_BLOCK periods at a time, fewer for a long x: a block's arrays
    stay under BLOCK_ELEMS elements (a log's length in memory, not 64 of them)."""
    amps = np.empty(len(periods))
    step = max(1, min(PERIOD_BLOCK, BLOCK_ELEMS // max(len(x), 1)))
    for i in range(0, len(periods), step):
        P = np.asarray(periods[i:i + step])[:, None]
        th = 2.0 * np.pi * x[None, :] / P
        s, c = np.sin(th), np.cos(th)
        ss, cc, sc = (s * s).sum(1), (c * c).sum(1), (s * c).sum(1)
        es, ec = s @ e, c @ e
        det = ss * cc - sc * sc
        a = (cc * es - sc * ec) / det
        b = (ss * ec - sc * es) / det
        amps[i:i + step] = np.hypot(a, b)
    return amps


def period_range(prep):
    """The periods the search covers (see the module's doc)."""
    sl = prep.whole
    v95 = float(np.percentile(np.abs(prep.v[sl]), 95))
    travel = float(np.ptp(prep.xm[sl]))
    return max(v95 / prep.fc_hz, 1e-5), travel / 3.0


def search(prep, base, fit_with):
    """None when the log's travel is too short for the range."""
    pmin, pmax = period_range(prep)
    if not pmax > 1.5 * pmin:
        return None
    periods = np.geomspace(pmin, pmax, PERIODS)
    tr = np.arange(prep.n)[prep.train][::PERIODOGRAM_DECIMATE]  # a slice, or the intervals' indices
    amps = position_periodogram(base.residual(prep)[tr], prep.xm[tr], periods)
    g = periods[1] / periods[0]
    best = None
    for i in np.argsort(amps)[::-1][:PEAKS]:
        P0 = periods[i]

        def sse(lp):
            return fit_with({"ripple_period_m": math.exp(lp)}).train_sse

        r = optimize.minimize_scalar(sse, bounds=(math.log(P0 / g ** 2), math.log(P0 * g ** 2)), method="bounded",
                                     options={"xatol": 1e-5})
        if best is None or r.fun < best[1]:
            best = (math.exp(r.x), r.fun)
    return {"ripple_period_m": best[0]}


def params(coef, nl, p):
    a_s, a_c = coef["ripple_sin"], coef["ripple_cos"]
    return {"ripple_amp_N": math.hypot(a_s, a_c), "ripple_period_m": nl["ripple_period_m"],
            "ripple_phase_rad": math.atan2(a_c, a_s)}


def from_params(p):
    A, ph = p["ripple_amp_N"], p["ripple_phase_rad"]
    return {"ripple_sin": A * math.cos(ph), "ripple_cos": A * math.sin(ph)}, {"ripple_period_m": p["ripple_period_m"]}


def report_params(p):
    return {"period_m": p["ripple_period_m"], "amplitude_N": p["ripple_amp_N"], "phase_rad": p["ripple_phase_rad"]}


def evidence(r, p):
    return (f"The residual spectrum over position peaks at a period of {1e3 * p['period_m']:.3g} mm "
            f"(amplitude {p['amplitude_N']:.2g} N, residual spectrum plot), in both directions of motion "
            f"(residual vs position).")


def closed_loop(p, plant):
    A, P, ph = p["ripple_amp_N"], p["ripple_period_m"], p["ripple_phase_rad"]
    two_pi, sin = 2.0 * math.pi, math.sin
    plant.loads.append(lambda x: A * sin(two_pi * x / P + ph))


def residual_spectrum(path, prep, diag):
    """The nominal and extended residuals' amplitude against the period in position."""
    from .. import plots

    pmin, pmax = period_range(prep)
    pmin = max(pmin / 2, 1e-6)
    w = slice(prep.lo, prep.hi, PERIODOGRAM_DECIMATE)
    periods = np.geomspace(pmin, max(pmax, 2 * pmin), 500)
    fig, ax = plots.plt.subplots(figsize=(10, 4.5))
    ax.semilogx(1e3 * periods, position_periodogram(diag.nominal.residual(prep)[w], prep.xm[w], periods),
                color="tab:red", lw=0.8, label="nominal residual")
    if diag.extended.causes:
        ax.semilogx(1e3 * periods, position_periodogram(diag.extended.residual(prep)[w], prep.xm[w], periods),
                    color="tab:blue", lw=0.8, label="extended residual")
    ax.set_xlabel("period in position [mm]")
    ax.set_ylabel("amplitude [N]")
    ax.set_title("Residual spectrum over position (least-squares sine fit at each period)")
    ax.legend(fontsize=8)
    plots.save(fig, path)


FIGURES = (("residual_spectrum.png", "residual spectrum over position", residual_spectrum),)
