# SPDX-License-Identifier: Apache-2.0
"""Writing the outputs of a diagnosis. The generated JSON files (report.json,
model.json, machine.json): a banner naming the generator, no timestamp,
numbers rounded to 6 significant digits so that a rerun on the same machine
writes the same files. Every file of a run is written into a staging folder
inside OUT and moved into OUT only when the whole run has succeeded
(Staging): a run that fails or is killed half-way leaves no partial file in
OUT and keeps the previous run's files."""
import json
import math
import os
import shutil
import tempfile

import numpy as np

GENERATOR = "python/bristle/diagnose (python -m bristle.diagnose); generated, do not edit"


def rounded(x):
    """6 significant digits (JSON-friendly, stable), through dicts and lists."""
    if isinstance(x, dict):
        return {k: rounded(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [rounded(v) for v in x]
    if isinstance(x, (bool, str)) or x is None:
        return x
    if isinstance(x, (int, np.integer)):
        return int(x)
    x = float(x)
    if not math.isfinite(x) or x == 0.0:
        return x if math.isfinite(x) else None
    return float(f"{x:.6g}")


def write_json(path, obj):
    with open(path, "w", encoding="utf-8") as f:
        json.dump(obj, f, indent=2)
        f.write("\n")


class Staging:
    """The outputs of one run: written into `dir` (OUT/.partial-XXXX, made
    here, OUT made if missing) and moved into OUT by commit(), each file by
    one os.replace (a rename in the same folder: a file of OUT is either the
    previous run's or this run's, never a partial one). Leaving the `with`
    block without commit() (an exception) removes the staging folder; a killed
    run leaves only it, hidden, behind."""

    def __init__(self, out):
        os.makedirs(out, exist_ok=True)
        self.out = out
        self.dir = tempfile.mkdtemp(prefix=".partial-", dir=out)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        shutil.rmtree(self.dir, ignore_errors=True)
        return False

    def commit(self):
        for name in sorted(os.listdir(self.dir)):
            os.replace(os.path.join(self.dir, name), os.path.join(self.out, name))
