# SPDX-License-Identifier: Apache-2.0
"""Diagnosis of measured logs: what the nominal (thesis) model gets wrong,
which cause of ../shared/spec/measured-log.md explains it, and the gain of
the extended model on a held-out part of the log. docs/diagnose.md."""
import os

# The fits solve many small least-squares problems; BLAS threads only add
# contention (4x slower on a busy 2-core machine). Set before numpy loads.
for _v in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_v, "1")
