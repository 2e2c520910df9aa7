#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Plots of the X-Y circle demo (thesis Figs. 4-8) from DIR/summary.json and
the traces it names.

Usage: plot_demo.py DIR
  fig4_trajectory_<ctrl>.png  trajectory vs reference, radial error magnified, and the
                              radial error at the controller's own scale (Fig. 4)
  fig5_radial_error.png       radial error vs angle, every controller; a second panel
                              with the compensated ones only (Fig. 5)
  fig6_friction.png           estimated friction (PF, UKF) and the true one, x axis, and
                              the estimation error (Fig. 6)
  fig7_gp.png                 the PF's mean g_p over time, both axes (Fig. 7)
  fig8_gp_hist.png            g_p particle histograms 30 ms before, at and after the
                              largest g_p transition at a reversal after start-up (Fig. 8)
  iso230_4_polar.png          the circular test as a ballbar report draws it: per
                              controller the nominal circle and the radial deviation
                              about the least-squares centre, magnified (the scale
                              printed), with G and the reversal spikes (iso230_4.py);
                              with --dir both the counter-clockwise path overlaid
The realistic plant's traces (summary.json "realistic", prefix real_) give the
same figures with the prefix real_."""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import iso230_4  # noqa: E402  (beside this script)

LABELS = {"hinf_only": "H-inf only", "hinf_ukf": "H-inf + UKF", "hinf_pf": "H-inf + PF",
          "hinf_true": "true friction (limit)", "hinf_ff": "H-inf + feedforward",
          "hinf_qec": "H-inf + reversal pulse (QEC)"}
COMPENSATED = ("hinf_ukf", "hinf_pf", "hinf_true")  # errors in nm: their own panel
STARTUP_S = 1.0   # Fig. 8 looks for its transition after the start-up
REVERSAL_WIN_S = 0.5  # ... within this of an axis reversal
MAGNIFY = 10.0  # radial error magnification in the trajectory plot
# the PF's g_p clamp (machines/reference.json, estimator.pf.gp_min_Fc / gp_max_Fs, in N)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "firmware", "design"))
import machine  # noqa: E402
_pf = machine.est_per_step(machine.load_or_exit(machine.REFERENCE_MACHINE), "pf")
GP_CLAMPS_N = (_pf["gp_min_N"], _pf["gp_max_N"])


def load_trace(d, s, name):
    return np.genfromtxt(os.path.join(d, s[name]["trace"]), delimiter=",", names=True)


def circle_angle(tr):
    return np.degrees(np.mod(np.arctan2(tr["x"], tr["y"]), 2 * np.pi))  # 0 deg at the start, clockwise


def fig4(d, s, name, tr, pre="", A=1e-4):
    ang = np.arctan2(tr["y"], tr["x"])
    r = A + MAGNIFY * tr["radial_err"]
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 5.2), gridspec_kw={"width_ratios": [1, 1.15]})
    ax.plot(tr["x_ref"] * 1e6, tr["y_ref"] * 1e6, "k--", lw=1, label="reference")
    ax.plot(r * np.cos(ang) * 1e6, r * np.sin(ang) * 1e6, "C0", lw=1,
            label="%s (radial error x%g)" % (LABELS[name], MAGNIFY))
    ax.set_aspect("equal")
    ax.set_xlabel("x [um]")
    ax.set_ylabel("y [um]")
    ax.set_title("%s: contour RMS %.2e m" % (LABELS[name], s[name]["contour_rms_m"]), fontsize=10)
    ax.legend(loc="lower right", fontsize=8)
    # the radial error at its own scale: visible for the compensated controllers too
    nm = name in COMPENSATED
    ax2.plot(circle_angle(tr), tr["radial_err"] * (1e9 if nm else 1e6), ".", ms=1.2, color="C0")
    for q in (90, 180, 270):
        ax2.axvline(q, color="0.7", lw=0.8)
    ax2.set_xlim(0, 360)
    ax2.set_xlabel("angle along the circle [deg]")
    ax2.set_ylabel("radial error [%s] (+ = outward)" % ("nm" if nm else "um"))
    ax2.set_title("radial error at its own scale", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "%sfig4_trajectory_%s.png" % (pre, name)), dpi=120)
    plt.close(fig)


def fig5(d, traces, pre=""):
    comp = [n for n in COMPENSATED if n in traces]
    fig, axs = plt.subplots(2 if comp else 1, 1, figsize=(8, 7 if comp else 4), squeeze=False)
    for name, tr in traces.items():
        axs[0, 0].plot(circle_angle(tr), tr["radial_err"] * 1e6, ".", ms=1.5, label=LABELS[name])
    axs[0, 0].set_ylabel("radial error [um] (+ = outward)")
    if comp:
        for name in comp:
            axs[1, 0].plot(circle_angle(traces[name]), traces[name]["radial_err"] * 1e9, ".", ms=1.5,
                           color="C%d" % list(traces).index(name), label=LABELS[name])
        axs[1, 0].set_ylabel("radial error [nm]: compensated only")
    for ax in axs[:, 0]:
        for q in (90, 180, 270):
            ax.axvline(q, color="0.7", lw=0.8)
        ax.set_xlim(0, 360)
        ax.legend(markerscale=6, fontsize=8)
    axs[-1, 0].set_xlabel("angle along the circle [deg] (quadrant lines = axis reversals)")
    fig.tight_layout()
    fig.savefig(os.path.join(d, "%sfig5_radial_error.png" % pre), dpi=120)
    plt.close(fig)


def fig6(d, traces, pre=""):
    est = [n for n in ("hinf_pf", "hinf_ukf") if n in traces]
    if not est:
        return
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True, gridspec_kw={"height_ratios": [1.4, 1]})
    for n in est:
        tr = traces[n]
        ax.plot(tr["t"], tr["fhat_x"], lw=0.8, label="%s estimate" % LABELS[n])
        # each run's own error: the plant's true f_nl of that run
        ax2.plot(tr["t"], tr["fhat_x"] - tr["fnl_x"], lw=0.6,
                 label="%s: F^ - f_nl (RMS %.3f N)" % (LABELS[n], np.sqrt(np.mean((tr["fhat_x"] - tr["fnl_x"]) ** 2))))
    tr = traces[est[0]]
    ax.plot(tr["t"], tr["fnl_x"], "k", lw=0.8, label="true (run with %s)" % LABELS[est[0]])
    ax.set_ylabel("friction f_nl, x axis [N]")
    ax.legend(fontsize=8)
    ax2.set_xlabel("t [s]")
    ax2.set_ylabel("estimation error, x [N]")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "%sfig6_friction.png" % pre), dpi=120)
    plt.close(fig)


def gp_transition(tr, axis, period_s=8.0):
    """The largest change of the mean g_p over 60 ms within REVERSAL_WIN_S of a
    reversal of that axis after STARTUP_S: (time, change). x = A sin reverses at
    T/4 + k T/2, y = A cos at k T/2."""
    g = tr["gp_%s" % axis]
    t = tr["t"]
    lag = max(1, int(round(0.06 / (t[1] - t[0]))))
    ch = np.abs(g[lag:] - g[:-lag])
    tm = t[:-lag] + 0.5 * lag * (t[1] - t[0])
    first = period_s / 4 if axis == "x" else 0.0
    revs = np.arange(first, t[-1] + 1e-9, period_s / 2)
    if len(revs) == 0 or len(tm) == 0:
        return (tm[0] if len(tm) else t[0]), 0.0  # a run shorter than its first reversal
    ok = (tm > STARTUP_S) & (np.min(np.abs(tm[:, None] - revs[None, :]), axis=1) < REVERSAL_WIN_S)
    if not ok.any():
        return tm[0], 0.0
    k = int(np.argmax(np.where(ok, ch, -1.0)))
    return tm[k], float(ch[k])


def fig7_8(d, traces, pre=""):
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
    fig.savefig(os.path.join(d, "%sfig7_gp.png" % pre), dpi=120)
    plt.close(fig)
    hist_path = os.path.join(d, "gp_hist_%shinf_pf.csv" % pre)
    if not os.path.exists(hist_path):
        return
    h = np.loadtxt(hist_path, delimiter=",", comments="#")
    with open(hist_path) as f:
        width = float(f.readline().split(" bins of ")[1].split(" N")[0])
    axis = max((0, 1), key=lambda a: gp_transition(tr, "xy"[a])[1])
    tc, drop = gp_transition(tr, "xy"[axis])
    dt = tr["t"][1] - tr["t"][0]
    times = [tc - 0.03, tc, tc + 0.03]
    fig, axs = plt.subplots(1, 3, figsize=(11, 3.7), sharey=True)
    edges = np.arange(h.shape[1] - 2) * width
    for ax, tq in zip(axs, times):
        rows = h[(h[:, 1] == axis) & (np.abs(h[:, 0] - tq) < dt / 2)]
        if len(rows):
            b = rows[0, 2:]
            ax.bar(edges, b, width=width, align="edge")
            # the bins that hold the g_p clamp (docs/demo.md, "Fig. 8"): drawn apart
            for lim in GP_CLAMPS_N:
                j = int(lim / width)
                if 0 <= j < len(b) and b[j] > 0:
                    ax.bar(edges[j], b[j], width=width, align="edge", color="0.6")
                    ax.annotate("clamp %.1f N: %.0f %%" % (lim, 100 * b[j] / b.sum()), (edges[j], b[j]),
                                fontsize=7, ha="center", va="bottom")
        ax.set_title("t = %.3f s" % tq)
        ax.set_xlabel("g_p [N]")
    axs[0].set_ylabel("particles (%s axis)" % "xy"[axis])
    fig.suptitle("PF g_p histogram at the largest g_p transition at a reversal after start-up "
                 "(mean g_p changes %.1f N in 60 ms; grey: particles held at the clamp)" % drop, fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "%sfig8_gp_hist.png" % pre), dpi=120)
    plt.close(fig)


def _nice(x):
    """1, 2 or 5 times a power of ten, >= x"""
    e = 10.0 ** np.floor(np.log10(x))
    return next(m * e for m in (1, 2, 5, 10) if m * e >= x)


def polar(d, sec, pre="", A=1e-4):
    """iso230_4_polar.png: one polar panel per controller, as a ballbar report:
    the nominal circle (radius 1 on the plot) and 1 + deviation / scale at the
    actual polar angle about the least-squares centre, the rings labelled in
    deviation; the counter-clockwise run overlaid when there is one."""
    names = [n for n in LABELS if n in sec]
    if not names:
        return
    ccw = sec.get("ccw") or {}
    ncol = min(3, len(names))
    nrow = (len(names) + ncol - 1) // ncol
    fig = plt.figure(figsize=(4.6 * ncol, 4.9 * nrow))
    for i, n in enumerate(names):
        ax = fig.add_subplot(nrow, ncol, i + 1, projection="polar")
        runs = [("main", sec[n])] + ([("ccw", ccw[n])] if n in ccw else [])
        paths = []
        for tag, obj in runs:
            tr = load_trace(d, {"t": obj}, "t")
            a, b, R = iso230_4.lsq_circle(tr["x"], tr["y"])
            dev = iso230_4.deviation(tr["x"], tr["y"], (a, b), R)
            phi = np.arctan2(tr["y"] - b, tr["x"] - a)
            paths.append((tag, phi, dev, iso230_4.analyse_trace(tr)))
        big = max(np.abs(p[2]).max() for p in paths)
        step = _nice(big / 3.0)  # a ring every step of deviation
        unit, f = ("nm", 1e9) if step < 1e-6 else ("um", 1e6)
        per = step / 0.1  # deviation per unit of plot radius: a ring every 0.1 of the nominal radius
        th = np.linspace(0, 2 * np.pi, 721)
        ax.plot(th, np.ones_like(th), "k--", lw=0.8)
        for k, (tag, phi, dev, fig_) in enumerate(paths):
            lab = {"main": "cw" if len(paths) == 1 or tag == "main" else "ccw", "ccw": "ccw"}[tag]
            if len(paths) == 1:
                lab = None
            ax.plot(phi, 1.0 + dev / per, lw=0.8, color="C%d" % (3 if tag == "ccw" else 0), label=lab)
            for sp in fig_["reversal_spikes"]:
                ang = np.radians(sp["peak_angle_deg"])
                ax.plot([ang], [1.0 + (sp["height_m"] + sp["local_mean_m"]) / per], "v" if sp["height_m"] < 0 else "^",
                        ms=4, color="C%d" % (3 if tag == "ccw" else 0))
        ticks = np.arange(-4, 5)
        ax.set_rticks(1.0 + 0.1 * ticks)
        ax.set_yticklabels(["%+g" % (k * step * f) if k % 2 == 0 and k else "0" if k == 0 else "" for k in ticks],
                           fontsize=6)
        ax.set_rlim(0.45, 1.55)
        ax.set_rlabel_position(100)
        ax.tick_params(axis="x", labelsize=7)
        fig0 = paths[0][3]
        sub = "G %.3g %s" % (fig0["circular_deviation_m"] * f, unit)
        bi = (sec[n].get("iso230_4") or {}).get("bidirectional")
        if bi:
            sub += ", H %.3g %s" % (bi["circular_hysteresis_m"] * f, unit)
        ax.set_title("%s\n%s; rings %g %s apart\n(x%.3g against the radius)" %
                     (LABELS[n], sub, step * f, unit, 0.1 * A / step), fontsize=8)
        if len(paths) > 1:
            ax.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.15, -0.1))
    fig.suptitle("circular test (ISO 230-4): radial deviation about the least-squares centre, magnified; "
                 "dashed: the nominal circle; markers: reversal spikes", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "%siso230_4_polar.png" % pre), dpi=120)
    plt.close(fig)


def main(d):
    s = json.load(open(os.path.join(d, "summary.json")))
    A = s["experiment"]["radius_m"]
    for pre, sec in (("", s), ("real_", s.get("realistic"))):
        if not sec:
            continue
        traces = {n: load_trace(d, sec, n) for n in LABELS if n in sec}
        for name, tr in traces.items():
            fig4(d, sec, name, tr, pre, A)
        fig5(d, traces, pre)
        fig6(d, traces, pre)
        fig7_8(d, traces, pre)
        polar(d, sec, pre, A)
    print("wrote plots to %s" % d)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
