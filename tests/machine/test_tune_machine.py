#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`make tune MACHINE=<file>` (docs/tuning.md, "Another machine") with a
small evaluation budget: it writes the tuned headers and tune/machine.json
into the machine's build folder (firmware/design/build_dir.py), nothing into
the source tree; tune/machine.json loads, gives the tuned headers' per-step
values back as float32 on that machine, marks the tuned settings "derived",
and keeps every other value of the given file.

Usage: test_tune_machine.py --machine FILE [--max-fev N]"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import DESIGN, FAILURES, REPO, check, result  # noqa: E402
import machine  # noqa: E402
import tuned_machine  # noqa: E402


def source_state():
    """The source tree's state as git sees it (tracked changes and untracked files)."""
    return subprocess.run(["git", "-C", REPO, "status", "--porcelain", "--untracked-files=all"],
                          capture_output=True, text=True, check=True).stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--machine", required=True)
    ap.add_argument("--max-fev", default="8")
    a = ap.parse_args()
    before = source_state()
    p = subprocess.run(["make", "-C", REPO, "tune", "MACHINE=" + a.machine, "MAX_FEV=" + a.max_fev],
                       capture_output=True, text=True)
    print(p.stdout[-3000:], p.stderr[-3000:])
    check(p.returncode == 0, "make tune MACHINE=%s MAX_FEV=%s: exit 0" % (a.machine, a.max_fev))
    check(source_state() == before, "the source tree is unchanged")
    folder = subprocess.run([sys.executable, os.path.join(DESIGN, "build_dir.py"), "host-release", a.machine],
                            capture_output=True, text=True, check=True).stdout.strip()
    tune = os.path.join(REPO, folder, "tune")  # build_dir.py names it relative to the repository
    out = os.path.join(tune, "machine.json")
    check(os.path.isfile(out) and "make firmware MACHINE=%s" % os.path.join(folder, "tune", "machine.json") in p.stdout,
          "tune/machine.json written in the build folder and the next command printed")
    if FAILURES:
        return 1
    m = machine.load(out)
    given = machine.load(a.machine)
    rpc2 = machine.params(m)["rad_per_count"] ** 2
    for est in ("pf", "ukf"):
        tuned = tuned_machine.read_tuned(os.path.join(tune, "br_%s_tuned.h" % est), est)
        tuned["r_counts2"] /= rpc2
        got = machine.est_per_step(m, est)
        same = all(np.float32(got[k]) == np.float32(v) for k, v in tuned.items())
        check(same, "%s: machine.json gives the tuned per-step values" % est)
        fields = ["estimator.%s.%s" % (est, machine.PER_STEP_FIELD[k]) for k in tuned]
        check(all(machine.provenance(m, f) == "derived" for f in fields), "%s: the tuned settings are derived" % est)
    strip = lambda d: {k: v for k, v in d.items() if k not in ("estimator", "provenance", "source", "file")}
    check(strip(m) == strip(given), "every value outside the estimator section is the given file's")
    return result()


if __name__ == "__main__":
    sys.exit(main())
