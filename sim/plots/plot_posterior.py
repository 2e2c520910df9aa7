#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The PF's and the UKF's posterior at chosen times (thesis Fig. 8), from the
CSV of `br_mslip_plants --posterior FILE --at T1,T2,..` (br_circle_pftrace.h):
per time one column, rows g_p, z and the friction f_nl; the PF's particles as
a histogram (density), the UKF's Gaussian (its mean and sigma of g_p and z; F_hat
for the friction), and the plant's truth of each run as vertical lines (its
Stribeck level g(v) and its friction force; the Maxwell-slip plant has no
bristle state, so z has no truth). The PF and the UKF each ran their own
closed loop, so each has its own truth.

Usage: plot_posterior.py POSTERIOR.csv OUT.png"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    """One dict per traced run (the UKF's, then the PF's, as br_mslip_plants runs them):
    {"at": {t: {"truth": row, "pf": [rows], "ukf_mean": row, "ukf_sd": row}}}."""
    runs = []  # one dict per traced run, in file order
    cur = None
    for r in csv.DictReader(open(path)):
        t = float(r["t_s"])
        if r["kind"] == "truth":
            if cur is None or t < cur["last_t"]:
                cur = {"at": {}, "last_t": t}
                runs.append(cur)
            cur["last_t"] = t
            cur["at"].setdefault(t, {"truth": r, "pf": []})
            cur["t"] = t
        elif r["kind"] == "pf":
            cur["at"][cur["t"]]["pf"].append(r)
        else:
            cur["at"][cur["t"]][r["kind"]] = r
    return runs


def gauss(ax, mean, sd, color, label):
    if not (sd > 0):
        return
    lo, hi = ax.get_xlim()
    xs = [lo + (hi - lo) * i / 200 for i in range(201)]
    ax.plot(xs, [math.exp(-0.5 * ((x - mean) / sd) ** 2) / (sd * math.sqrt(2 * math.pi)) for x in xs], color=color,
            lw=1.5, label=label)


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    runs = load(argv[1])
    ukf = next(r for r in runs if any("ukf_mean" in v for v in r["at"].values()))
    pf = next(r for r in runs if any(v["pf"] for v in r["at"].values()))
    tp, tu = sorted(pf["at"]), sorted(ukf["at"])
    quantities = [("gp_N", "g_p (N)", 1.0), ("z_m", "z (µm)", 1e6), ("f_N", "friction (N)", 1.0)]
    fig, axes = plt.subplots(len(quantities), len(tp), figsize=(2.3 * len(tp), 6.0), squeeze=False)
    for c, (t, s) in enumerate(zip(tp, tu)):
        P, U = pf["at"][t], ukf["at"][s]
        for r, (key, name, k) in enumerate(quantities):
            ax = axes[r][c]
            vals = [k * float(p[key]) for p in P["pf"]]
            truth_key = {"gp_N": "gp_N", "f_N": "f_N"}.get(key)
            # the axis covers the particles, the UKF's mean +- 3 sigma and the truths
            um = k * float(U["ukf_mean"][key])
            us = k * float(U["ukf_sd"][key]) if U["ukf_sd"][key] else 0.0
            ext = vals + [um - 3 * us, um + 3 * us]
            if truth_key:
                ext += [k * float(P["truth"][truth_key]), k * float(U["truth"][truth_key])]
            pad = 0.05 * (max(ext) - min(ext) or 1.0)
            ax.set_xlim(min(ext) - pad, max(ext) + pad)
            ax.hist(vals, bins=40, density=True, color="tab:blue", alpha=0.6, label="PF particles")
            if key != "f_N":
                gauss(ax, um, us, "tab:orange", "UKF mean ± σ")
            else:
                ax.axvline(float(U["ukf_mean"]["f_N"]), color="tab:orange", lw=1.5, label="UKF F̂")
            if truth_key:
                ax.axvline(k * float(P["truth"][truth_key]), color="tab:blue", ls="--", lw=1.2,
                           label="truth, PF run" + (" (g(v))" if key == "gp_N" else ""))
                ax.axvline(k * float(U["truth"][truth_key]), color="tab:orange", ls="--", lw=1.2,
                           label="truth, UKF run" + (" (g(v))" if key == "gp_N" else ""))
            ax.set_yticks([])
            ax.tick_params(labelsize=7)
            if r == 0:
                ax.set_title(f"t = {t:.3f} s", fontsize=9)
            if c == 0:
                ax.set_ylabel(name, fontsize=9)
    axes[0][0].legend(fontsize=6, loc="upper left")
    axes[2][0].legend(fontsize=6, loc="upper left")
    fig.suptitle("hardware-like plant, x axis around its reversal at t = 2 s: PF particles vs UKF Gaussian", fontsize=10)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=70)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
