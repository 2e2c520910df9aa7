# SPDX-License-Identifier: Apache-2.0
"""Peak memory of a diagnosis of a long log (docs/diagnose.md, "Memory"):
br_simlog writes an identification log of at least --rows rows, then
`python -m bristle.diagnose diagnose` runs on it in a child process (no
figures); the child's peak resident set size (getrusage, RUSAGE_CHILDREN)
and wall time are printed (br_simlog, the other child, stays
under 10 MB). The diagnosis keeps the first 2 000 000 rows of a log
(logreader.DEFAULT_MAX_SAMPLES). A benchmark, not a test: exit 1 only when the
peak exceeds --limit-mb (the goal, 1 GB for 2 million rows).

Usage: diagnose_memory.py --simlog BIN --work DIR [--rows N] [--limit-mb M]
(`make diagnose-bench`)"""
import argparse
import os
import resource
import subprocess
import sys
import time

ROWS_PER_CYCLE = 9221  # br_simlog's identification cycle at 1 ms (docs/simlog.md)


def logreader_max():
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                    "python"))
    from bristle.diagnose import logreader
    return logreader.DEFAULT_MAX_SAMPLES


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--rows", type=int, default=2_000_000)
    ap.add_argument("--limit-mb", type=float, default=1024.0)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    log = os.path.join(a.work, "long.csv")
    cycles = -(-a.rows // ROWS_PER_CYCLE)
    subprocess.run([a.simlog, "--out", log, "--cycles", str(cycles), "--force-noise", "0.1"], check=True)
    with open(log, "rb") as f:
        rows = sum(chunk.count(b"\n") for chunk in iter(lambda: f.read(1 << 20), b"")) - 1
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = dict(os.environ, PYTHONPATH=os.path.join(repo, "python"), MPLBACKEND="Agg", OPENBLAS_NUM_THREADS="1")
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", log,
                        "--out", os.path.join(a.work, "out"), "--no-plots", "--quiet"],
                       env=env)
    wall = time.monotonic() - t0
    peak_mb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0  # kB on Linux
    if r.returncode != 0:
        print(f"diagnose failed (exit {r.returncode})", file=sys.stderr)
        return 1
    print(f"diagnosis of {min(rows, logreader_max())} rows ({os.path.getsize(log) / 1e6:.0f} MB of CSV): peak RSS {peak_mb:.0f} MB, "
          f"wall {wall:.0f} s (goal: under {a.limit_mb:.0f} MB)")
    return 0 if peak_mb <= a.limit_mb else 1


if __name__ == "__main__":
    sys.exit(main())
