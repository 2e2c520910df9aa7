# SPDX-License-Identifier: Apache-2.0
"""What the machine tests (tests/machine/test_*.py) share: the repository's
paths, firmware/design on the import path (the machine loader), and the
check / result pair: one "ok  : ..." or "FAIL: ..." line per check, a count
at the end, exit status 1 on any failure."""
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DESIGN = os.path.join(REPO, "firmware", "design")
sys.path.insert(0, DESIGN)

FAILURES = []


def check(cond, what):
    print("%s: %s" % ("ok  " if cond else "FAIL", what))
    if not cond:
        FAILURES.append(what)


def result():
    """The exit status: 1 when a check failed, after the count."""
    print("%d failure(s)" % len(FAILURES))
    return 1 if FAILURES else 0
