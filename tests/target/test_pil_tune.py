# SPDX-License-Identifier: Apache-2.0
"""ctest target_pil_tune (docs/link.md, "Tuning on the target"): the
mechanics of `make pil-tune` on a very short segment (0.1 s of the circle),
the UKF, the smallest search Nelder-Mead runs (its first simplex, 6
evaluations, after the shipped setting's evaluation 0):

1. the parameters reach the target: every evaluation's duty sequence
   (its fingerprint) is the one the host simulator gives with the written
   values in its filter's configuration (br_pil_tune --sim), and the
   evaluations with different variances have different duty sequences;
2. a faulted evaluation is counted as one: the run writes a narrow outlier
   gate before every evaluation (--set outlier_sigma=0.35 and the gate's
   transient term 0: a gate that loses
   lock within 0.1 s for some of these settings and not for others: found
   with --sim; since the machine's UKF carries its external force
   (2026-11-28) it re-acquires as a load what 0.6 used to reject, and 0.6
   stops none, 0.3 all, 0.35 one of the six); each run that stopped is
   printed as a FAULT with no figure, counted in the summary line, and has
   no figure in evals.csv;
3. the best is reported: the smallest objective of the evaluations that ran
   to the end, with its variances.

Fails (never skips) when QEMU or the image is missing.
Usage: test_pil_tune.py --tune BR_PIL_TUNE --image ELF --work DIR"""
import argparse
import csv
import os
import re
import shutil
import subprocess
import sys

SEGMENT_S = "0.1"
MAX_FEV = "6"         # the UKF's five variances: the first simplex
GATE = "outlier_sigma=0.35"
# the gate's transient term off (the thesis gate, eq. G1): the machine's 20.8 counts would accept every step
NO_TERM = "outlier_transient_counts=0"


def run(cmd):
    print("$ " + " ".join(cmd), flush=True)
    r = subprocess.run(cmd, capture_output=True, text=True)
    print(r.stdout + r.stderr)
    return r


def evals(out):
    """the evaluation lines: [(index, fault?, objective, fingerprint)]"""
    rows = []
    for m in re.finditer(r"^eval (\d+)\b.*\n\s+(.*)$", out, re.M):
        line = m.group(2)
        fp = re.search(r"duty ([0-9a-f]{8})", line).group(1)
        obj = float(re.search(r"objective ([0-9.e+-]+)", line).group(1))
        fault = line.startswith(("FAULT", "REFUSED"))
        if fault and "measured" in line:
            sys.exit("FAIL: a faulted evaluation has a figure: " + line)
        rows.append((int(m.group(1)), fault, obj, fp))
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tune", required=True)
    ap.add_argument("--image", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    qemu = os.environ.get("BR_QEMU") or "qemu-system-arm"
    if shutil.which(qemu) is None:
        sys.exit("FAIL: %s not found (make deps installs qemu-system-arm)" % qemu)
    if not os.path.isfile(a.image):
        sys.exit("FAIL: no image at %s (build the cm7-release preset)" % a.image)
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    out_dir = os.path.join(a.work, "out")
    common = ["--max-fev", MAX_FEV, "--duration", SEGMENT_S, "--set", GATE, "--set", NO_TERM]
    t = run([a.tune, "--image", a.image, "--out", out_dir, "--timeout", "120"] + common)
    if t.returncode != 0:
        sys.exit("FAIL: br_pil_tune exit %d" % t.returncode)
    s = run([a.tune, "--sim"] + common)
    if s.returncode != 0:
        sys.exit("FAIL: br_pil_tune --sim exit %d" % s.returncode)
    target, sim = evals(t.stdout), evals(s.stdout)
    if len(target) != int(MAX_FEV) + 1 or [r[0] for r in target] != list(range(int(MAX_FEV) + 1)):
        sys.exit("FAIL: expected evaluations 0..%s, got %s" % (MAX_FEV, [r[0] for r in target]))
    # 1. the same duty sequences as the simulator with the written values, evaluation by evaluation
    if [r[3] for r in target] != [r[3] for r in sim]:
        sys.exit("FAIL: the target's duty sequences are not the simulator's with the written values")
    fps = [r[3] for r in target]
    if len(set(fps)) != len(fps):
        sys.exit("FAIL: different variances gave the same duty sequence: %s" % fps)
    # 2. the faults counted, the runs that went to the end too (the gate makes both happen)
    faults = [r for r in target[1:] if r[1]]
    done = [r for r in target[1:] if not r[1]]
    if not faults or not done:
        sys.exit("FAIL: the gate %s no longer gives both faulted and complete evaluations" % GATE)
    m = re.search(r"^(\d+) evaluations, (\d+) of them faulted or refused", t.stdout, re.M)
    if m is None or int(m.group(1)) != int(MAX_FEV) or int(m.group(2)) != len(faults):
        sys.exit("FAIL: the summary does not count the %d faulted evaluations" % len(faults))
    with open(os.path.join(out_dir, "evals.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    for r, e in zip(rows, target):
        if (r["fault"] != "") != e[1] or (r["meas_contour_rms_m"] == "") != e[1]:
            sys.exit("FAIL: evals.csv row %s disagrees with the printed evaluation" % r["eval"])
    # 3. the best: the smallest objective of the complete evaluations
    best = min(done, key=lambda r: r[2])
    m = re.search(r"^best: objective ([0-9.e+-]+) m \(eval (\d+):", t.stdout, re.M)
    if m is None or int(m.group(2)) != best[0] or abs(float(m.group(1)) - best[2]) > 1e-4 * best[2]:
        sys.exit("FAIL: the best reported is not evaluation %d's objective %.4e" % (best[0], best[2]))
    if not os.path.isfile(os.path.join(out_dir, "summary.md")):
        sys.exit("FAIL: no summary.md")
    print("target_pil_tune: %d evaluations, %d faulted; the duty sequences are the simulator's; best %.4e m (eval %d)"
          % (len(target) - 1, len(faults), best[2], best[0]))


if __name__ == "__main__":
    main()
