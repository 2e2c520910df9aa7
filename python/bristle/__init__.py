"""bristle's Python package: the tools that run on a host, not on the target.

bristle.diagnose: the diagnosis of measured logs (docs/diagnose.md).
Run with python/ on PYTHONPATH: `PYTHONPATH=python .venv/bin/python -m bristle.diagnose ...`.
"""
