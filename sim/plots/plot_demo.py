#!/usr/bin/env python3
"""Plots of the X-Y circle demo (thesis Figs. 4 and 5) from DIR/summary.json
and the trace CSVs it names.

Usage: plot_demo.py DIR  -> DIR/fig4_trajectory.png, DIR/fig5_radial_error.png"""
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

LABELS = {"hinf_only": "H-inf only"}
MAGNIFY = 10.0  # radial error magnification in the trajectory plot


def load(d, name):
    s = json.load(open(os.path.join(d, "summary.json")))
    tr = np.genfromtxt(os.path.join(d, s[name]["trace"]), delimiter=",", names=True)
    return s, tr


def main(d):
    s = json.load(open(os.path.join(d, "summary.json")))
    names = [k for k in LABELS if k in s]
    A = s["experiment"]["radius_m"]
    for name in names:
        _, tr = load(d, name)
        ang = np.arctan2(tr["y"], tr["x"])
        # Fig. 4: trajectory vs reference, radial error magnified
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
    # Fig. 5: radial error vs angle, all controllers
    fig, ax = plt.subplots(figsize=(8, 4))
    for name in names:
        _, tr = load(d, name)
        ang = np.degrees(np.mod(np.arctan2(tr["x"], tr["y"]), 2 * np.pi))  # 0 deg at the start, clockwise
        ax.plot(ang, tr["radial_err"] * 1e6, ".", ms=1.5, label=LABELS[name])
    for q in (90, 180, 270):
        ax.axvline(q, color="0.7", lw=0.8)
    ax.set_xlabel("angle along the circle [deg] (quadrant lines = axis reversals)")
    ax.set_ylabel("radial error [um] (+ = outward)")
    ax.set_xlim(0, 360)
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig5_radial_error.png"), dpi=120)
    plt.close(fig)
    print("wrote plots to %s" % d)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
