# SPDX-License-Identifier: Apache-2.0
"""The command line of the diagnosis tests that write logs with br_simlog:
--simlog BIN --work DIR (emptied first), the rest for unittest."""
import argparse
import os
import shutil
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
