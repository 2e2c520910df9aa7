"""Writing the generated JSON files (report.json, model.json): a banner
naming the generator, no timestamp, numbers rounded to 6 significant digits
so that a rerun on the same machine writes the same files."""
import json
import math

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
