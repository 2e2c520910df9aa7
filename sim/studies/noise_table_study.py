#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Noise-table study for the PF's ROM tables (docs/modules/pf.md): friction
estimation error and contour RMS of the H-inf + PF circle against the table
length, for three indexing schemes, averaged over table seeds.

Usage: noise_table_study.py BUILD_DIR OUT_DIR
Writes OUT_DIR/noise_table_study.json and OUT_DIR/noise_table_study.png and
prints a markdown table. Tables come from firmware/design/gen_noise.py's
generator with seeds SEED, SEED+1, ..."""
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "firmware", "design"))
import gen_noise  # noqa: E402

LENGTHS = [64, 256, 1024, 4096, 16384, 65536]
# extra advance per step: 0 = a plain stream, 1 = stream drifting by one
# sample per step, 40503 = an odd jump of ~0.6 of a 64 Ki table
SKIPS = [0, 1, 40503]
SEEDS = 3


def run(build, table_path, skip):
    out = subprocess.run([os.path.join(build, "sim", "br_pf_study"), "--table", table_path, "--skip", str(skip)],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def main(build, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    res = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in LENGTHS:
            for skip in SKIPS:
                rows = []
                for s in range(SEEDS):
                    path = os.path.join(tmp, "t.bin")
                    gen_noise.table(n, gen_noise.SEED + s).astype("<f4").tofile(path)
                    rows.append(run(build, path, skip))
                key = "%d/%d" % (n, skip)
                res[key] = {k: float(np.mean([r[k] for r in rows])) for k in rows[0]}
                res[key]["contour_rms_max_m"] = max(r["contour_rms_m"] for r in rows)
                print("len %6d skip %5d: F err %.4f N, contour RMS %.3e m (worst seed %.3e), outliers %.0f" % (
                    n, skip, res[key]["fhat_rms_err_N"], res[key]["contour_rms_m"],
                    res[key]["contour_rms_max_m"], res[key]["outliers"]), flush=True)
    with open(os.path.join(out_dir, "noise_table_study.json"), "w") as f:
        json.dump(res, f, indent=1, sort_keys=True)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 4))
    for skip in SKIPS:
        axs[0].semilogx(LENGTHS, [res["%d/%d" % (n, skip)]["fhat_rms_err_N"] for n in LENGTHS], "o-",
                        label="skip %d" % skip)
        axs[1].loglog(LENGTHS, [res["%d/%d" % (n, skip)]["contour_rms_m"] for n in LENGTHS], "o-",
                      label="skip %d" % skip)
    axs[0].set_ylabel("friction estimation RMS error [N]")
    axs[1].set_ylabel("contour RMS [m]")
    for ax in axs:
        ax.set_xlabel("noise table length")
        ax.legend()
    fig.suptitle("H-inf + PF circle, 1500 particles, 1.5 ms; mean over %d table seeds" % SEEDS)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "noise_table_study.png"), dpi=110)
    print("\n| length | skip | F error [N] | contour RMS [m] | worst seed [m] | outliers |\n|---|---|---|---|---|---|")
    for n in LENGTHS:
        for skip in SKIPS:
            r = res["%d/%d" % (n, skip)]
            print("| %d | %d | %.4f | %.3e | %.3e | %.0f |" % (n, skip, r["fhat_rms_err_N"], r["contour_rms_m"],
                                                             r["contour_rms_max_m"], r["outliers"]))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
