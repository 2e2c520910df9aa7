# SPDX-License-Identifier: Apache-2.0
"""bristle's Python package: the tools that run on a host, not on the target.

bristle.diagnose: the diagnosis of measured logs (docs/diagnose.md), the
console command `bristle-diagnose` once installed (docs/python-package.md);
from the source tree: `PYTHONPATH=python .venv/bin/python -m bristle.diagnose ...`.
"""
import os as _os


def _version():
    """The project's one version: VERSION at the repository root when run
    from the source tree, else the installed distribution's (pyproject.toml
    takes it from the same file)."""
    src = _os.path.join(_os.path.dirname(_os.path.abspath(__file__)), "..", "..", "VERSION")
    if _os.path.isfile(src):
        with open(src, encoding="utf-8") as f:
            return f.read().strip()
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("bristle")
    except PackageNotFoundError:
        return "unknown"


__version__ = _version()
