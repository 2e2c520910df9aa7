#!/usr/bin/env python3
"""Plots of the X-Y circle demo (thesis Figs. 4-8) from DIR/summary.json and
the traces it names.

Usage: plot_demo.py DIR
  fig4_trajectory_<ctrl>.png  trajectory vs reference, radial error magnified (Fig. 4)
  fig5_radial_error.png       radial error vs angle, every controller (Fig. 5)
  fig6_friction.png           estimated friction (PF, UKF) and the true one, x axis (Fig. 6)
  fig7_gp.png                 the PF's mean g_p over time, both axes (Fig. 7)
  fig8_gp_hist.png            g_p particle histograms before, during and after
                              its largest transition (Fig. 8)"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

LABELS = {"hinf_only": "H-inf only", "hinf_ukf": "H-inf + UKF", "hinf_pf": "H-inf + PF",
          "hinf_true": "true friction (limit)"}
MAGNIFY = 10.0  # radial error magnification in the trajectory plot


def load_trace(d, s, name):
    return np.genfromtxt(os.path.join(d, s[name]["trace"]), delimiter=",", names=True)


def fig4(d, s, name, tr):
    A = s["experiment"]["radius_m"]
    ang = np.arctan2(tr["y"], tr["x"])
    r = A + MAGNIFY * tr["radial_err"]
    fig, ax = plt.subplots(figsize=(6, 6))
    ax.plot(tr["x_ref"] * 1e6, tr["y_ref"] * 1e6, "k--", lw=1, label="reference")
    ax.plot(r * np.cos(ang) * 1e6, r * np.sin(ang) * 1e6, "C0", lw=1,
            label="%s (radial error x%g)" % (LABELS[name], MAGNIFY))
    ax.set_aspect("equal")
    ax.set_xlabel("x [um]")
    ax.set_ylabel("y [um]")
    ax.set_title("X-Y circle, %s: contour RMS %.2e m" % (LABELS[name], s[name]["contour_rms_m"]))
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig4_trajectory_%s.png" % name), dpi=120)
    plt.close(fig)


def fig5(d, traces):
    fig, ax = plt.subplots(figsize=(8, 4))
    for name, tr in traces.items():
        ang = np.degrees(np.mod(np.arctan2(tr["x"], tr["y"]), 2 * np.pi))  # 0 deg at the start, clockwise
        ax.plot(ang, tr["radial_err"] * 1e6, ".", ms=1.5, label=LABELS[name])
    for q in (90, 180, 270):
        ax.axvline(q, color="0.7", lw=0.8)
    ax.set_xlabel("angle along the circle [deg] (quadrant lines = axis reversals)")
    ax.set_ylabel("radial error [um] (+ = outward)")
    ax.set_xlim(0, 360)
    ax.legend(markerscale=6)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig5_radial_error.png"), dpi=120)
    plt.close(fig)


def fig6(d, traces):
    est = [n for n in ("hinf_pf", "hinf_ukf") if n in traces]
    if not est:
        return
    fig, ax = plt.subplots(figsize=(9, 4))
    for n in est:
        tr = traces[n]
        ax.plot(tr["t"], tr["fhat_x"], lw=0.8, label="%s estimate" % LABELS[n])
    tr = traces[est[0]]
    ax.plot(tr["t"], tr["fnl_x"], "k", lw=0.8, label="true (run with %s)" % LABELS[est[0]])
    ax.set_xlabel("t [s]")
    ax.set_ylabel("friction f_nl, x axis [N]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig6_friction.png"), dpi=120)
    plt.close(fig)


def gp_transition(tr, axis):
    """Time of the largest drop of the mean g_p over 60 ms."""
    g = tr["gp_%s" % axis]
    t = tr["t"]
    lag = max(1, int(round(0.06 / (t[1] - t[0]))))
    drop = g[:-lag] - g[lag:]
    k = int(np.argmax(drop))
    return t[k + lag // 2], drop[k]


def fig7_8(d, traces):
    if "hinf_pf" not in traces:
        return
    tr = traces["hinf_pf"]
    fig, ax = plt.subplots(figsize=(9, 4))
    ax.plot(tr["t"], tr["gp_x"], lw=0.8, label="x axis")
    ax.plot(tr["t"], tr["gp_y"], lw=0.8, label="y axis")
    ax.set_xlabel("t [s]")
    ax.set_ylabel("PF mean g_p [N]")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig7_gp.png"), dpi=120)
    plt.close(fig)
    hist_path = os.path.join(d, "gp_hist_hinf_pf.csv")
    if not os.path.exists(hist_path):
        return
    h = np.loadtxt(hist_path, delimiter=",", comments="#")
    with open(hist_path) as f:
        width = float(f.readline().split(" bins of ")[1].split(" N")[0])
    axis = max((0, 1), key=lambda a: gp_transition(tr, "xy"[a])[1])
    tc, drop = gp_transition(tr, "xy"[axis])
    dt = tr["t"][1] - tr["t"][0]
    times = [tc - 0.03, tc, tc + 0.03]
    fig, axs = plt.subplots(1, 3, figsize=(11, 3.5), sharey=True)
    edges = np.arange(h.shape[1] - 2) * width
    for ax, tq in zip(axs, times):
        rows = h[(h[:, 1] == axis) & (np.abs(h[:, 0] - tq) < dt / 2)]
        if len(rows):
            ax.bar(edges, rows[0, 2:], width=width, align="edge")
        ax.set_title("t = %.3f s" % tq)
        ax.set_xlabel("g_p [N]")
    axs[0].set_ylabel("particles (%s axis)" % "xy"[axis])
    fig.suptitle("PF g_p histogram around its largest transition (mean drop %.1f N in 60 ms)" % drop)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig8_gp_hist.png"), dpi=120)
    plt.close(fig)


def main(d):
    s = json.load(open(os.path.join(d, "summary.json")))
    traces = {n: load_trace(d, s, n) for n in LABELS if n in s}
    for name, tr in traces.items():
        fig4(d, s, name, tr)
    fig5(d, traces)
    fig6(d, traces)
    fig7_8(d, traces)
    print("wrote plots to %s" % d)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
