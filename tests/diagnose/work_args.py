# SPDX-License-Identifier: Apache-2.0
"""The command line of the diagnosis tests that write logs with br_simlog:
--simlog BIN --work DIR (emptied first), the rest for unittest; and, for
the script-style tests, the same two options and a log writer."""
import argparse
import os
import shutil
import subprocess
import sys
import unittest


def main(module):
    """Parses the arguments into module.ARGS, empties the work folder and runs
    the module's tests."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    module.ARGS, rest = ap.parse_known_args()
    shutil.rmtree(module.ARGS.work, ignore_errors=True)
    os.makedirs(module.ARGS.work)
    unittest.main(module=module, argv=[sys.argv[0]] + rest)


def simlog_script(*defaults):
    """--simlog BIN --work DIR of a script-style test (DIR created): (args,
    simlog(name, *flags) -> the path of WORK/name.csv that br_simlog wrote
    with defaults + flags)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--simlog", required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)

    def simlog(name, *flags):
        p = os.path.join(a.work, name + ".csv")
        subprocess.run([a.simlog, "--out", p] + [str(f) for f in defaults + flags], check=True)
        return p

    return a, simlog
