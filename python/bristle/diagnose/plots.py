# SPDX-License-Identifier: Apache-2.0
"""Figures of a diagnosis (matplotlib, Agg): what report.md lists. A cause's
own figures are in its module (causes/, FIGURES) and use `plt` and `save`
from here."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

# A series is drawn with at most this many points: a figure is about 1200
# pixels wide, and 2 million points drawn as they are took the diagnosis of a
# 5-million-row log to 1.75 GB (docs/diagnose.md, "Memory"). A log of EMPS's
# length (25 000 samples) is drawn whole.
MAX_POINTS = 100_000


def envelope(x, y):
    """(x, y) of a line for the plot: as they are when short, else the
    minimum and maximum of y in each of MAX_POINTS / 2 consecutive buckets, in
    their order (a spike stays visible)."""
    n = len(y)
    if n <= MAX_POINTS:
        return x, y
    k = -(-n // (MAX_POINTS // 2))
    m = n // k
    blocks = np.asarray(y[: m * k]).reshape(m, k)
    base = np.arange(m) * k
    lo, hi = base + blocks.argmin(axis=1), base + blocks.argmax(axis=1)
    idx = np.concatenate((np.sort(np.stack((lo, hi), axis=1), axis=1).ravel(), np.arange(m * k, n)))
    return np.asarray(x)[idx], np.asarray(y)[idx]


def dots(*arrays):
    """Every arrays' same samples for a dot plot: all when short, else every
    k-th, at most MAX_POINTS."""
    k = max(1, -(-len(arrays[0]) // MAX_POINTS))
    return tuple(a[::k] for a in arrays)


def save(fig, path):
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _shade_held_out(ax, prep):
    ax.axvspan(prep.t[prep.split], prep.t[prep.hi], color="0.92", zorder=0, label="held out")


def force_fit(path, prep, diag):
    w = prep.whole
    t = prep.t[:-1]
    fig, axs = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    ax = axs[0]
    _shade_held_out(ax, prep)
    ax.plot(*envelope(t[w], prep.y[w]), color="k", lw=0.8, label="measured (filtered)")
    ax.plot(*envelope(t[w], diag.nominal.predict(prep)[w]), color="tab:red", lw=0.7, label="nominal model")
    if diag.extended.causes:
        ax.plot(*envelope(t[w], diag.extended.predict(prep)[w]), color="tab:blue", lw=0.7, ls="--",
                label="extended model")
    ax.set_ylabel("force at the load [N]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("Measured force and the force the models predict from the measured motion")
    ax = axs[1]
    _shade_held_out(ax, prep)
    ax.plot(*envelope(t[w], (prep.y - diag.nominal.predict(prep))[w]), color="tab:red", lw=0.6, label="nominal")
    if diag.extended.causes:
        ax.plot(*envelope(t[w], diag.extended.residual(prep)[w]), color="tab:blue", lw=0.6, label="extended")
    ax.set_ylabel("residual [N]")
    ax.set_xlabel("t [s]")
    ax.legend(loc="upper right", fontsize=8)
    save(fig, path)


def residuals(path, prep, diag):
    w = prep.whole
    t = prep.t[:-1][w]
    en = diag.nominal.residual(prep)[w]
    ee = diag.extended.residual(prep)[w] if diag.extended.causes else None
    fig, axs = plt.subplots(3, 1, figsize=(11, 9))
    for ax, x, lab in ((axs[0], t, "t [s]"), (axs[1], prep.v[w], "velocity [m/s]"), (axs[2], prep.xm[w], "position [m]")):
        ax.plot(*dots(x, en), ".", ms=1.0, color="tab:red", alpha=0.5, label="nominal")
        if ee is not None:
            ax.plot(*dots(x, ee), ".", ms=1.0, color="tab:blue", alpha=0.5, label="extended")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel(lab)
        ax.set_ylabel("residual [N]")
        ax.legend(loc="upper right", fontsize=8, markerscale=8)
    axs[0].set_title("Force residual (measured - predicted) against time, velocity and position")
    save(fig, path)


def closed_loop(path, prep, sims):
    """The closed-loop re-simulation a person can read: the following error
    (reference - position) measured and re-simulated, in µm; the force
    measured and re-simulated (both filtered); and their difference."""
    t = prep.t
    fig, axs = plt.subplots(3, 1, figsize=(11, 8.5), sharex=True)
    axs[0].plot(*envelope(t, 1e6 * (prep.ref - prep.pos)), color="k", lw=0.8, label="measured")
    axs[1].plot(*envelope(t, prep.lp(prep.force)), color="k", lw=0.8, label="measured")
    for name, col in (("nominal", "tab:red"), ("extended", "tab:blue")):
        if name in sims:
            axs[0].plot(*envelope(t, 1e6 * (prep.ref - sims[name]["q"])), color=col, lw=0.7, ls="--",
                        label=f"re-simulated, {name}")
            fs = prep.lp(sims[name]["force"])
            axs[1].plot(*envelope(t, fs), color=col, lw=0.7, ls="--", label=f"re-simulated, {name}")
            axs[2].plot(*envelope(t, fs - prep.lp(prep.force)), color=col, lw=0.6, label=name)
    axs[0].set_ylabel("following error\nreference - position [µm]")
    axs[1].set_ylabel("force at the load [N]")
    axs[2].set_ylabel("force: re-simulated\n- measured [N]")
    axs[2].set_xlabel("t [s]")
    for ax in axs:
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(alpha=0.3)
    axs[0].set_title("Closed-loop re-simulation: the log's reference through its controller, the fitted model as the plant")
    save(fig, path)


def _steady_friction(p, v):
    """The steady-state friction of model.json's parameters p at velocity v
    (the LuGre's sliding force g(v) sgn v + viscous, each direction's)."""
    import numpy as np

    Fc, Fs, vs = p["Fc_N"], p["Fs_N"], p["vs_mps"]
    c = (Fc + p.get("dFc_neg_N", 0.0)) / Fc
    s2n = p["sigma2_Nspm"] + p.get("dsigma2_neg_Nspm", 0.0)
    g = Fc + (Fs - Fc) * np.exp(-np.abs(v) / vs)
    return np.where(v >= 0, g + p["sigma2_Nspm"] * v, -c * g + s2n * v)


def friction_map(path, prep, diag):
    """Friction against velocity, by direction: the measured force minus
    the extended model's inertia and load terms (what is left is friction),
    its mean per velocity bin, and the nominal and extended models' steady
    friction curves."""
    import numpy as np

    from . import causes as causes_
    from . import model as model_

    ext = diag.extended
    w = prep.whole
    loads = np.zeros(prep.n)
    for hook in causes_.hooks(causes_.of(ext.causes), "load_columns"):
        for k, col in hook(prep, ext.nl).items():
            loads += ext.coef.get(k, 0.0) * col
    fr = (model_.target(prep, ext.causes, ext.nl) - ext.coef["Meff"] * prep.a - loads)[w]
    v = prep.v[w]
    v95 = float(np.percentile(np.abs(v), 95))
    mv = np.abs(v) > 0.02 * v95
    fig, ax = plt.subplots(figsize=(10, 6))
    for sgn, col, lab in ((1, "tab:red", "moving in +x"), (-1, "tab:blue", "moving in -x")):
        sel = mv & (np.sign(v) == sgn)
        vd, fd = dots(v[sel][::3], fr[sel][::3])
        ax.plot(1e3 * vd, fd, ".", ms=1.0, color=col, alpha=0.25, rasterized=True)
        if sel.sum() > 40:
            edges = np.quantile(v[sel], np.linspace(0, 1, 31))
            k = np.clip(np.searchsorted(edges, v[sel]) - 1, 0, 29)
            cnt = np.bincount(k, minlength=30)
            ok = cnt > 0
            vm = np.bincount(k, weights=v[sel], minlength=30)[ok] / cnt[ok]
            fm = np.bincount(k, weights=fr[sel], minlength=30)[ok] / cnt[ok]
            ax.plot(1e3 * vm, fm, "o", ms=4, color=col, label=f"measured, mean per bin ({lab})")
    vg = np.linspace(-1.05 * np.max(np.abs(v)), 1.05 * np.max(np.abs(v)), 801)
    vg = vg[vg != 0]
    for f, name, ls in ((diag.nominal, "nominal", ":"), (ext, "extended", "-")):
        pr = f.params()
        for part in (vg < 0, vg > 0):
            ax.plot(1e3 * vg[part], _steady_friction(pr, vg[part]), color="k", ls=ls, lw=1.2,
                    label=f"{name} model, steady friction" if part[0] else None)
    ax.axhline(0, color="0.5", lw=0.5)
    ax.axvline(0, color="0.5", lw=0.5)
    ax.set_xlabel("velocity [mm/s]")
    ax.set_ylabel("friction force [N] (measured force - inertia - load terms)")
    ax.set_title("Friction map: force against velocity by direction, with the fitted curves")
    ax.legend(fontsize=8, loc="upper left", markerscale=2)
    save(fig, path)
