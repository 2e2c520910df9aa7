#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""ctest golden_regen: regenerate the golden traces into a scratch directory
and compare them byte for byte with the committed golden/traces. Prints the
first differing line of every differing file; exit status 1 on any difference."""
import argparse
import os
import shutil
import subprocess
import sys


def first_difference(a_path, b_path):
    with open(a_path, "rb") as fa, open(b_path, "rb") as fb:
        a, b = fa.read().split(b"\n"), fb.read().split(b"\n")
    for i, (la, lb) in enumerate(zip(a, b)):
        if la != lb:
            return i + 1, la.decode(errors="replace"), lb.decode(errors="replace")
    n = min(len(a), len(b))
    return n + 1, (a[n].decode() if n < len(a) else "<end of file>"), \
        (b[n].decode() if n < len(b) else "<end of file>")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repo", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    committed = os.path.join(args.repo, "golden", "traces")
    if os.path.isdir(args.out):
        shutil.rmtree(args.out)
    gen = os.path.join(args.repo, "golden", "gen_traces.py")
    r = subprocess.run([sys.executable, gen, "--out", args.out])
    if r.returncode != 0:
        print("golden_regen: %s failed with status %d" % (gen, r.returncode))
        return 1
    new = sorted(f for f in os.listdir(args.out) if f.endswith(".csv"))
    old = sorted(f for f in os.listdir(committed) if f.endswith(".csv"))
    bad = 0
    for f in sorted(set(new) ^ set(old)):
        print("golden_regen: %s exists only in %s" % (f, committed if f in old else args.out))
        bad += 1
    for f in sorted(set(new) & set(old)):
        a, b = os.path.join(committed, f), os.path.join(args.out, f)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            if fa.read() == fb.read():
                print("golden_regen: %s identical" % f)
                continue
        line, la, lb = first_difference(a, b)
        print("golden_regen: %s differs, first at line %d:\n  committed:   %s\n  regenerated: %s"
              % (f, line, la, lb))
        bad += 1
    if bad:
        print("golden_regen: %d trace file(s) differ; if the change is intended, run "
              "`%s golden/gen_traces.py` and commit golden/traces" % (bad, os.path.basename(sys.executable)))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
