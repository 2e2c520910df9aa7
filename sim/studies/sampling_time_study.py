#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Sampling-time study (thesis section 3.3, Fig. 2): runs br_dt_study with the
thesis's particle count (1000 dt[ms]) and with a CPU budget, writes
OUT/sampling_time.json and OUT/fig2_sampling_time.png, prints markdown tables.

Usage: sampling_time_study.py BUILD_DIR OUT_DIR [--cost-ns C] [--budget F]
The budget variant gives the PF the fraction F of one host core (default 0.25)
at C ns per particle-step (default: the host figure of `make bench`, 156 ns)."""
import argparse
import json
import os
import subprocess

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def run(build, extra):
    exe = os.path.join(build, "sim", "br_dt_study")
    out = subprocess.run([exe, "--seeds", "4"] + extra, check=True, capture_output=True, text=True).stdout
    return [json.loads(line) for line in out.splitlines() if line.strip()]


def table(title, rows):
    print("\n%s\n\n| dt [ms] | particles | RMS error [N] | discretisation/model (bias) [N] | Monte-Carlo [N] | outlier steps |" % title)
    print("|---|---|---|---|---|---|")
    for r in rows:
        print("| %.1f | %d | %.4f | %.4f | %.4f | %d |" % (r["dt_s"] * 1e3, r["particles"], r["rms_err_N"], r["bias_N"],
                                                      r["mc_N"], r["outliers"]))
    best = min(rows, key=lambda r: r["rms_err_N"])
    print("\noptimum: %.1f ms (%.4f N)" % (best["dt_s"] * 1e3, best["rms_err_N"]))
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build")
    ap.add_argument("out")
    ap.add_argument("--cost-ns", type=float, default=156.0)
    ap.add_argument("--budget", type=float, default=0.25)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    thesis = run(a.build, ["--m-per-ms", "1000"])
    budget = run(a.build, ["--budget", str(a.budget), "--cost-ns", str(a.cost_ns)])
    with open(os.path.join(a.out, "sampling_time.json"), "w") as f:
        json.dump({"thesis_particles": thesis, "cpu_budget": budget, "budget": a.budget, "cost_ns": a.cost_ns},
                  f, indent=1)
    table("Particles = 1000 dt[ms] (thesis)", thesis)
    table("Particles = %g of a core / %g ns per particle-step" % (a.budget, a.cost_ns), budget)
    fig, axs = plt.subplots(1, 2, figsize=(11, 4), sharey=True)
    for ax, rows, title in ((axs[0], thesis, "m = 1000 dt[ms] (thesis)"),
                            (axs[1], budget, "m = %g core / %g ns" % (a.budget, a.cost_ns))):
        dt = [r["dt_s"] * 1e3 for r in rows]
        ax.semilogy(dt, [r["rms_err_N"] for r in rows], "ko-", label="total")
        ax.semilogy(dt, [r["bias_N"] for r in rows], "s--", label="discretisation / model (bias)")
        ax.semilogy(dt, [r["mc_N"] for r in rows], "^--", label="Monte-Carlo (spread)")
        ax.axvline(1.5, color="0.7", lw=0.8)
        ax.set_xlabel("sampling period dt [ms]")
        ax.set_title(title)
        ax.legend(fontsize=8)
    axs[0].set_ylabel("friction estimation RMS error [N]")
    fig.suptitle("PF offline on a logged H-inf-only circle (grey: the thesis's optimum, 1.5 ms)")
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "fig2_sampling_time.png"), dpi=120)


if __name__ == "__main__":
    main()
