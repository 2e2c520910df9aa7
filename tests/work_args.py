# SPDX-License-Identifier: Apache-2.0
"""The command line the Python tests under ctest share: each required
--NAME VALUE the test names, and --work DIR, the test's own folder, emptied
first (or only made, when the test keeps what an earlier run left). A test
in a subfolder imports it after putting tests/ on its path:

    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    import work_args
    a = work_args.parse("bin")       # a.bin, a.work"""
import argparse
import os
import shutil


def parse(*required, fresh=True, argv=None):
    """the parsed options (--NAME for each of required, and --work); the work folder emptied when fresh, else made"""
    ap = argparse.ArgumentParser()
    for name in required:
        ap.add_argument("--" + name, required=True)
    ap.add_argument("--work", required=True)
    a = ap.parse_args(argv)
    if fresh:
        shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work, exist_ok=not fresh)
    return a
