#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Thesis Fig. 1: contour RMS against the Nelder-Mead iteration, from the
progress logs written by br_tune_est --log.

Usage: plot_tuning.py OUT.png LOG.csv[:LABEL] [LOG.csv[:LABEL] ...]"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main(out, logs):
    fig, ax = plt.subplots(figsize=(7, 4))
    for spec in logs:
        path, _, label = spec.partition(":")
        d = np.genfromtxt(path, delimiter=",", names=True)
        ax.semilogy(d["iter"], d["contour_rms_m"], "o-", ms=3, label=label or path)
    ax.set_xlabel("Nelder-Mead iteration")
    ax.set_ylabel("best contour RMS [m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print("wrote %s" % out)


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2:])
