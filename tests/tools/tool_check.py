# SPDX-License-Identifier: Apache-2.0
"""The frame of the ctest scripts that run a release tool into a work folder
(test_tune_refusal.py, test_tune_guard_outliers.py, test_bench_numpy.py):
the command line (the tool's path and --work), a fresh work folder, and the
report of the checks that failed."""
import argparse
import os
import shutil
import sys


def start(tool_flag):
    """(the tool's path, the work folder, now empty) from --<tool_flag> BIN --work DIR"""
    ap = argparse.ArgumentParser()
    ap.add_argument("--" + tool_flag, required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    return getattr(a, tool_flag), a.work


def finish(fails):
    """prints each failed check; the exit status: 1 if any failed"""
    for msg in fails:
        print("FAIL: " + msg, file=sys.stderr)
    return 1 if fails else 0
