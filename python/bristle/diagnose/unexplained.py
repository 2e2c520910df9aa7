# SPDX-License-Identifier: Apache-2.0
"""What a residual above the noise floor goes with (docs/diagnose.md, "The
noise floor and unexplained").

For each signal of the motion (SIGNALS: time, position, velocity,
acceleration, direction, time since the last reversal) the residual's
variance that the signal explains over the log (edges left out):

  share = 1 - ||e - m(s)||^2 / ||e||^2

with m(s) the residual's mean per bin of s: BINS bins at the quantiles of
s (position, velocity, acceleration, time since a reversal), the three
states of the direction (moving in -x, at rest, moving in +x), and for time
a quadratic trend (a slow change of the machine over the run). A signal the
residual goes with explains at least GOES_WITH_MIN of it. The bins are few
against the log's length (a noise-only residual gets shares under 1 %).
"""
import numpy as np

BINS = 16
GOES_WITH_MIN = 0.10
REST_FRAC = 0.02      # |v| below this share of the 95th-percentile speed: at rest
SIGNALS = ("time", "position", "velocity", "acceleration", "direction", "reversal")
UNITS = {"time": "s", "position": "m", "velocity": "m/s", "acceleration": "m/s²", "direction": "",
         "reversal": "s since the last reversal"}


def motion_signals(prep):
    """The signals over the intervals of the log (edges left out)."""
    w = prep.whole
    v = prep.v[w]
    v95 = float(np.percentile(np.abs(v), 95))
    moving = np.abs(v) > REST_FRAC * v95
    direction = np.where(moving, np.sign(v), 0.0)
    # time since the last change of the direction of motion (rests ignored)
    t = prep.t[:-1][w]
    idx = np.flatnonzero(direction)
    marks = np.zeros(len(t), dtype=bool)
    marks[0] = True
    if len(idx):
        s = direction[idx]
        marks[idx[1:][s[1:] != s[:-1]]] = True
    last_idx = np.maximum.accumulate(np.where(marks, np.arange(len(t)), 0))
    rev_t = t - t[last_idx]
    return {"time": t, "position": prep.xm[w], "velocity": v, "acceleration": prep.a[w], "direction": direction,
            "reversal": rev_t}


JOINT = ("time", "position")   # taken jointly with the direction


def bin_means(e, s, name, direction):
    """m(s): the residual's mean per bin (see the module's doc)."""
    if name == "time":
        u = (s - s.mean()) / max(float(np.ptp(s)), 1e-12)
        base = np.column_stack([np.ones_like(u), u, u * u])
        X = np.column_stack([base, base * direction[:, None]])
        c, *_ = np.linalg.lstsq(X, e, rcond=None)
        return X @ c, None
    if name == "direction":
        keys = s
    else:
        edges = np.unique(np.quantile(s, np.linspace(0, 1, BINS + 1)[1:-1]))
        keys = np.searchsorted(edges, s)
        if name in JOINT:
            keys = keys * 3 + (direction + 1).astype(int)
    uniq, inv = np.unique(keys, return_inverse=True)
    sums = np.bincount(inv, weights=e)
    cnt = np.bincount(inv)
    means = sums / np.maximum(cnt, 1)
    return means[inv], (inv, means, cnt)


def goes_with(prep, e_full):
    """{signal: share} for the residual e_full (over all intervals)."""
    sig = motion_signals(prep)
    e = e_full[prep.whole]
    ee = float(e @ e)
    out = {}
    for name in SIGNALS:
        m, _ = bin_means(e, sig[name], name, sig["direction"])
        r = e - m
        out[name] = max(0.0, 1.0 - float(r @ r) / ee) if ee > 0 else 0.0
    return out


def describe(prep, fit, floor, relerr_percent):
    """(see below)"""
    out = _describe(prep, fit, floor, relerr_percent)
    if fit.causes:
        out["evidence"] += (" The findings explain only part of the force: one of them may stand in for part of "
                            "a force no cause names; check it on the machine before acting on it.")
    return out


def _describe(prep, fit, floor, relerr_percent):
    """The report's `unexplained` object: residual_percent, goes_with (the
    signals explaining at least GOES_WITH_MIN, strongest first), shares and
    an evidence sentence."""
    shares = goes_with(prep, fit.residual(prep))
    gw = [k for k, v in sorted(shares.items(), key=lambda kv: -kv[1]) if v >= GOES_WITH_MIN]
    ratio = relerr_percent / floor.percent if floor.percent > 0 else float("inf")
    if gw:
        what = ", ".join(f"{k} ({100 * shares[k]:.0f} % of it)" for k in gw)
        ev = (f"The held-out residual, {relerr_percent:.3g} %, is {ratio:.3g} times the log's noise floor "
              f"({floor.percent:.3g} %); it goes with {what} (unexplained.png): structure that neither the nominal model nor the findings describe.")
    else:
        ev = (f"The held-out residual, {relerr_percent:.3g} %, is {ratio:.3g} times the log's noise floor "
              f"({floor.percent:.3g} %), but no single signal of the motion explains {100 * GOES_WITH_MIN:.0f} % "
              f"of it (unexplained.png): look at the force signal chain (noise that is not white, disturbances "
              f"in time).")
    return {"residual_percent": relerr_percent, "goes_with": gw, "shares": shares, "evidence": ev}


def figure(path, prep, diag):
    """The residual the best model leaves against each signal, with its
    mean per bin and the share it explains."""
    from . import plots

    sig = motion_signals(prep)
    e = diag.extended.residual(prep)[prep.whole]
    shares = goes_with(prep, diag.extended.residual(prep))
    fig, axs = plots.plt.subplots(2, 3, figsize=(13, 7))
    for ax, name in zip(axs.ravel(), SIGNALS):
        s = sig[name]
        ax.plot(*plots.dots(s, e), ".", ms=0.8, color="0.55", alpha=0.4, rasterized=True)
        m, _ = bin_means(e, s, name, sig["direction"])
        d = sig["direction"]
        if name in JOINT or name == "direction":
            for dv, col, lab, ls in ((1.0, "tab:red", "fit, moving in +x", "-"), (-1.0, "tab:blue", "fit, moving in -x", "-"),
                                     (0.0, "tab:green", "fit, at rest", "none")):
                sel = np.flatnonzero(d == dv)
                if len(sel):
                    o = plots.dots(sel[np.argsort(s[sel], kind="stable")])[0]
                    ax.plot(s[o], m[o], color=col, lw=1.2, ls=ls, marker="o" if ls == "none" else None, ms=3,
                            label=lab)
        else:
            o = plots.dots(np.argsort(s, kind="stable"))[0]
            ax.plot(s[o], m[o], color="tab:red", lw=1.2, label="mean per bin")
        ax.axhline(0, color="k", lw=0.5)
        flag = "  ← goes with" if shares[name] >= GOES_WITH_MIN else ""
        ax.set_title(f"{name}: {100 * shares[name]:.1f} % of the residual{flag}", fontsize=9)
        ax.set_xlabel(f"{name} [{UNITS[name]}]" if UNITS[name] else "direction (-1, rest, +1)")
        ax.set_ylabel("residual [N]")
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle("What the extended model's residual goes with (whole log, edges left out)")
    plots.save(fig, path)
