# SPDX-License-Identifier: Apache-2.0
"""`python -m bristle.diagnose`: the same command line as `bristle-diagnose`
(bristle/diagnose/cli.py; docs/diagnose.md)."""
import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main(prog="python -m bristle.diagnose"))
