"""Figures of a diagnosis (matplotlib, Agg): what report.md lists. A cause's
own figures are in its module (causes/, FIGURES) and use `plt` and `save`
from here."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402



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
    ax.plot(t[w], prep.y[w], color="k", lw=0.8, label="measured (filtered)")
    ax.plot(t[w], diag.nominal.predict(prep)[w], color="tab:red", lw=0.7, label="nominal model")
    if diag.extended.causes:
        ax.plot(t[w], diag.extended.predict(prep)[w], color="tab:blue", lw=0.7, ls="--", label="extended model")
    ax.set_ylabel("force at the load [N]")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("Measured force and the force the models predict from the measured motion")
    ax = axs[1]
    _shade_held_out(ax, prep)
    ax.plot(t[w], (prep.y - diag.nominal.predict(prep))[w], color="tab:red", lw=0.6, label="nominal")
    if diag.extended.causes:
        ax.plot(t[w], diag.extended.residual(prep)[w], color="tab:blue", lw=0.6, label="extended")
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
        ax.plot(x, en, ".", ms=1.0, color="tab:red", alpha=0.5, label="nominal")
        if ee is not None:
            ax.plot(x, ee, ".", ms=1.0, color="tab:blue", alpha=0.5, label="extended")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_xlabel(lab)
        ax.set_ylabel("residual [N]")
        ax.legend(loc="upper right", fontsize=8, markerscale=8)
    axs[0].set_title("Force residual (measured - predicted) against time, velocity and position")
    save(fig, path)


def closed_loop(path, prep, sims):
    t = prep.t
    fig, axs = plt.subplots(3, 1, figsize=(11, 8), sharex=True)
    axs[0].plot(t, prep.ref, color="0.6", lw=0.8, label="reference")
    axs[0].plot(t, prep.pos, color="k", lw=0.8, label="measured")
    for name, col in (("nominal", "tab:red"), ("extended", "tab:blue")):
        if name in sims:
            axs[0].plot(t, sims[name]["q"], color=col, lw=0.6, ls="--", label=f"re-simulated, {name}")
            axs[1].plot(t, 1e6 * (prep.pos - sims[name]["q"]), color=col, lw=0.6, label=name)
            axs[2].plot(t, prep.lp(sims[name]["force"]) - prep.lp(prep.force), color=col, lw=0.6, label=name)
    axs[0].set_ylabel("position [m]")
    axs[1].set_ylabel("measured - simulated [µm]")
    axs[2].set_ylabel("force: simulated - measured [N]")
    axs[2].set_xlabel("t [s]")
    for ax in axs:
        ax.legend(loc="upper right", fontsize=8)
    axs[0].set_title("Closed-loop re-simulation: the log's reference, its controller, the fitted model")
    save(fig, path)
