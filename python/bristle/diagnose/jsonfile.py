# SPDX-License-Identifier: Apache-2.0
"""Reading a JSON file the diagnosis takes (model.json, a machine file):
LogError "file:line: problem" when it cannot be read or parsed, and the line
of a key for the checks that follow. At most MAX_BYTES: these files are a
few hundred bytes."""
import json
import os

from .logreader import LogError, open_regular, short

MAX_BYTES = 1 << 20  # the C model loader's limit (br_plant_json.c)


def load(path):
    """(the parsed object, its text)."""
    try:
        with open_regular(path, "r", encoding="utf-8-sig") as f:
            if os.fstat(f.fileno()).st_size > MAX_BYTES:
                raise LogError(path, 0, f"larger than {MAX_BYTES >> 20} MiB, not a model or machine file")
            text = f.read(MAX_BYTES + 1)
        return json.loads(text, object_pairs_hook=_unique), text
    except OSError as e:
        raise LogError(path, 0, f"cannot open: {e.strerror}") from None
    except UnicodeDecodeError as e:
        raise LogError(path, 1, f"not UTF-8 text ({e.reason})") from None
    except json.JSONDecodeError as e:
        raise LogError(path, e.lineno, f"not JSON: {e.msg}") from None
    except DuplicateKey as e:
        raise LogError(path, line_of(text, e.args[0]), f"field {describe(e.args[0])} given twice") from None
    except RecursionError:
        raise LogError(path, 1, "not JSON: nested too deeply") from None


def _unique(pairs):
    """A JSON object whose keys are all different (json keeps the last of
    two silently)."""
    keys = [k for k, _ in pairs]
    dup = sorted({k for k in keys if keys.count(k) > 1})
    if dup:
        raise DuplicateKey(dup[0])
    return dict(pairs)


class DuplicateKey(ValueError):
    pass


def line_of(text, key):
    """Line of the first "key" in a JSON text (1 when absent)."""
    i = text.find(f'"{key}"')
    return text.count("\n", 0, i) + 1 if i >= 0 else 1


def describe(v):
    """A value for a message, cut short."""
    return short(json.dumps(v) if isinstance(v, (str, list, dict)) else repr(v))
