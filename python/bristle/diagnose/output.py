# SPDX-License-Identifier: Apache-2.0
"""Writing the outputs of a diagnosis. The generated JSON files (report.json,
model.json, machine.json): a banner naming the generator, no timestamp,
numbers rounded to 6 significant digits so that a rerun on the same machine
writes the same files. Every file of a run is written into a staging folder
beside OUT, which takes OUT's place by one rename when the whole run has
succeeded (Staging): a run that fails or is killed at any point leaves OUT
all old or all new."""
import ctypes
import errno
import json
import math
import os
import re
import shutil
import tempfile

import numpy as np

AT_FDCWD = -100
RENAME_EXCHANGE = 2
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


def _exchange(a, b):
    """Swaps the folders a and b in one step (Linux renameat2 with
    RENAME_EXCHANGE). OSError, or NotImplementedError where the C library or
    the file system has no such rename."""
    fn = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", None)
    if fn is None:
        raise NotImplementedError("no renameat2")
    fn.argtypes = (ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint)
    if fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE) != 0:
        err = ctypes.get_errno()
        if err in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
            raise NotImplementedError(os.strerror(err))
        raise OSError(err, os.strerror(err), a)


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True  # another user's process
    return True


def check_out(out, names):
    """Problem with OUT as the place of a diagnosis's folder, or None. OUT is
    replaced as a whole, so it must be new, empty, or hold only what a
    diagnosis writes (`names`, and an old run's hidden .partial-* folders),
    and must not hold the current directory; its parent must be writable."""
    p = os.path.realpath(out)
    if os.path.lexists(out) and not os.path.isdir(p):
        return "--out names an existing file, not a directory"
    if os.path.isdir(p):
        cwd = os.path.realpath(os.getcwd())
        if cwd == p or cwd.startswith(p.rstrip(os.sep) + os.sep):
            return "--out holds the current directory; give the diagnosis a folder of its own"
        foreign = sorted(n for n in os.listdir(p) if n not in names and not n.startswith(".partial-"))
        if foreign:
            return ("--out holds files no diagnosis writes (%s); the folder is replaced as a whole: give a new or "
                    "empty folder, or a previous diagnosis's" % ", ".join(foreign[:5] + (["…"] if len(foreign) > 5
                                                                                         else [])))
    parent = os.path.dirname(p)
    while not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        return f"--out cannot be created: {parent} is not a directory"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"--out cannot be written: no permission in {parent}"
    return None


class Staging:
    """OUT committed as a whole: the run's files are written into a sibling
    folder `dir` (<parent>/.<OUT's name>.partial-<pid>-XXXX) and commit() puts
    that folder in OUT's place with one rename: an exchange of the two
    folders (renameat2 RENAME_EXCHANGE) when OUT exists, a plain rename when
    it does not; then the previous folder, now at the staging name, is
    removed. A run killed at any point leaves OUT all old or all new, never a
    mix, nor files of a previous run beside this one's (a run without figures
    leaves none). Leaving the `with` block without commit() removes the
    staging folder. Stale staging folders (their process is gone) of OUT are
    removed when the next run starts.

    Where no exchange exists (another kernel, a file system without it), OUT
    is renamed aside (<parent>/.<name>.old-<pid>-XXXX) and the staging folder
    renamed onto OUT: a kill between the two renames leaves no OUT, and the
    next run puts the old one back before it starts."""

    def __init__(self, out):
        self.out = os.path.realpath(out)
        parent, name = os.path.split(self.out)
        os.makedirs(parent, exist_ok=True)
        self._prefix = os.path.join(parent, "." + name)
        clean_stale(self.out)
        self.dir = tempfile.mkdtemp(prefix=f".{name}.partial-{os.getpid()}-", dir=parent)
        old_mode = os.stat(self.out).st_mode if os.path.isdir(self.out) else None
        os.chmod(self.dir, (old_mode & 0o7777) if old_mode is not None else 0o777 & ~_umask())

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        shutil.rmtree(self.dir, ignore_errors=True)
        return False

    def commit(self):
        if not os.path.isdir(self.out):
            os.rename(self.dir, self.out)
            return
        try:
            _exchange(self.dir, self.out)
        except NotImplementedError:
            aside = tempfile.mkdtemp(prefix=f"{os.path.basename(self._prefix)}.old-{os.getpid()}-",
                                     dir=os.path.dirname(self.out))
            os.rename(self.out, aside)   # a rename onto an empty folder replaces it
            os.rename(self.dir, self.out)
            self.dir = aside
        shutil.rmtree(self.dir, ignore_errors=True)


def _umask():
    m = os.umask(0)
    os.umask(m)
    return m


def clean_stale(out):
    """Removes the staging folders of OUT left by runs that are gone (and an
    old run's .partial-* folders inside OUT); an aside folder of a run killed
    between its two renames is put back as OUT when OUT is missing."""
    out = os.path.realpath(out)
    parent, name = os.path.split(out)
    pat = re.compile(r"\.%s\.(partial|old)-([0-9]+)-[^/]*" % re.escape(name))
    for n in sorted(os.listdir(parent)) if os.path.isdir(parent) else ():
        m = pat.fullmatch(n)
        if not m or _alive(int(m.group(2))):
            continue
        p = os.path.join(parent, n)
        if m.group(1) == "old" and not os.path.lexists(out):
            os.rename(p, out)
        else:
            shutil.rmtree(p, ignore_errors=True)
    if os.path.isdir(out):
        for n in os.listdir(out):
            if n.startswith(".partial-"):
                shutil.rmtree(os.path.join(out, n), ignore_errors=True)
