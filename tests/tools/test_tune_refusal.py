# SPDX-License-Identifier: Apache-2.0
"""br_tune_est refuses a tuning that no guard plant lets pass (docs/tuning.md,
"Guard plants"; sim/apps/br_tune_est.c, guard_penalty): with a guard plant
that no PF holds lock on (5 N of force noise per period; the thesis
filter, --pf-load 0: with the machine's shared external force the PF holds
even 10 N), every point the
search visits is penalised, and the tuner must write nothing rather than its
least-bad point: exit 1, the existing header and log byte for byte, no
temporary file left. Run with a release build of the tuner (a sanitised one
takes minutes for the dozen closed-loop circles).

Usage: test_tune_refusal.py --tuner BIN --work DIR"""
import os
import subprocess
import sys

import tool_check

OLD = b"an existing file\n"


def main():
    tuner, work = tool_check.start("tuner")
    header, log = os.path.join(work, "tuned.h"), os.path.join(work, "tune.csv")
    for p in (header, log):
        with open(p, "wb") as f:
            f.write(OLD)
    r = subprocess.run([tuner, "--est", "pf", "--out", header, "--log", log, "--max-fev", "6",
                        "--guard-noise", "5", "--pf-load", "0"], capture_output=True, text=True, timeout=900)
    fails = []
    if r.returncode != 1:
        fails.append(f"exit {r.returncode}, expected 1")
    for w in ("no variances found that pass the guard plants", "nothing written"):
        if w not in r.stderr:
            fails.append(f"stderr lacks {w!r}")
    if "tuning pf" not in r.stdout:
        fails.append("the search did not run")
    for p in (header, log):
        with open(p, "rb") as f:
            if f.read() != OLD:
                fails.append(f"{p} was changed")
    if sorted(os.listdir(work)) != ["tune.csv", "tuned.h"]:
        fails.append(f"files left: {sorted(os.listdir(work))}")
    print(r.stdout + r.stderr)
    return tool_check.finish(fails)


if __name__ == "__main__":
    sys.exit(main())
