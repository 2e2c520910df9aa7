# SPDX-License-Identifier: Apache-2.0
"""The frame of the ctest scripts that run a release tool into a work folder
(test_tune_refusal.py, test_tune_guard_outliers.py, test_bench_numpy.py):
the command line (the tool's path and --work), a fresh work folder, and the
report of the checks that failed."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import work_args  # noqa: E402


def start(tool_flag):
    """(the tool's path, the work folder, now empty) from --<tool_flag> BIN --work DIR"""
    a = work_args.parse(tool_flag)
    return getattr(a, tool_flag), a.work


def finish(fails):
    """prints each failed check; the exit status: 1 if any failed"""
    for msg in fails:
        print("FAIL: " + msg, file=sys.stderr)
    return 1 if fails else 0
