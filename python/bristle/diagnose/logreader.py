"""Reader for measured logs (../shared/spec/measured-log.md): CSV with a
header naming at least t, ref, pos, force.

Tolerated: a UTF-8 byte-order mark, CRLF line ends, extra columns (ignored),
column names in any order and case, surrounding spaces or quotes, blank lines.

Rejected, with "file:line: problem": a header lacking a column, a row with the
wrong number of fields, an empty or non-numeric cell, NaN or infinity, a time
that does not increase, a time step that differs from the first one by more
than UNIFORM_TOL of it, fewer than MIN_SAMPLES rows.

The file is read line by line and validated as it streams; `iter_blocks`
yields fixed-size numpy blocks, so a caller can go through a file of any size
in bounded memory. `read_log` keeps the samples (four float64 per row, at most
`max_samples` of them) for the diagnosis.
"""
import math
import os

import numpy as np

COLUMNS = ("t", "ref", "pos", "force")
MIN_SAMPLES = 1000
UNIFORM_TOL = 0.01          # relative deviation of a time step from the first
BLOCK_ROWS = 65536
DEFAULT_MAX_SAMPLES = 2_000_000


class LogError(ValueError):
    """A log the diagnosis cannot use; str() is "file:line: problem"."""

    def __init__(self, path, line, problem):
        super().__init__(f"{path}:{line}: {problem}")
        self.path, self.line, self.problem = path, line, problem


class Log:
    """Samples of one log: t, ref, pos, force (float64 arrays) and the period."""

    def __init__(self, path, t, ref, pos, force, dt, n_total):
        self.path, self.t, self.ref, self.pos, self.force = path, t, ref, pos, force
        self.dt = dt
        self.n = len(t)
        self.n_total = n_total  # rows in the file (may exceed n with max_samples)


def _cell_value(path, lineno, name, cell):
    s = cell.strip().strip('"').strip()
    if not s:
        raise LogError(path, lineno, f"column '{name}' is empty")
    try:
        v = float(s)
    except ValueError:
        raise LogError(path, lineno, f"column '{name}': '{s}' is not a number") from None
    if "_" in s:  # float() accepts digit separators; a log does not
        raise LogError(path, lineno, f"column '{name}': '{s}' is not a number")
    if math.isnan(v):
        raise LogError(path, lineno, f"column '{name}' is NaN")
    if math.isinf(v):
        raise LogError(path, lineno, f"column '{name}' is infinite")
    return v


def _header(path, lineno, line):
    names = [c.strip().strip('"').strip().lower() for c in line.split(",")]
    missing = [c for c in COLUMNS if c not in names]
    if missing:
        raise LogError(path, lineno, "header lacks column(s) " + ", ".join(missing) +
                       f" (found: {', '.join(n for n in names if n) or 'nothing'}); "
                       "expected t,ref,pos,force")
    dup = [c for c in COLUMNS if names.count(c) > 1]
    if dup:
        raise LogError(path, lineno, "header names column(s) twice: " + ", ".join(dup))
    return [names.index(c) for c in COLUMNS], len(names)


def iter_blocks(path, block_rows=BLOCK_ROWS):
    """Yields (first_line, array of shape (k, 4): t, ref, pos, force) blocks of
    at most block_rows validated rows; raises LogError at the first problem,
    including too few samples at the end of the file. Memory: one block."""
    display = os.fspath(path)
    buf = np.empty((block_rows, 4))
    k = 0
    n = 0
    idx = ncols = None
    t_prev = dt0 = None
    lineno = 0
    first_line = None
    try:
        f = open(path, "rb")
    except OSError as e:
        raise LogError(display, 0, f"cannot open: {e.strerror}") from None
    with f:
        for lineno, raw in enumerate(f, start=1):
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError as e:
                raise LogError(display, lineno, f"not UTF-8 text ({e.reason} at byte {e.start})") from None
            if lineno == 1 and line.startswith("\ufeff"):
                line = line[1:]
            line = line.rstrip("\r\n")
            if not line.strip():
                continue
            if idx is None:
                idx, ncols = _header(display, lineno, line)
                continue
            cells = line.split(",")
            if len(cells) != ncols:
                raise LogError(display, lineno, f"{len(cells)} fields, the header has {ncols}")
            row = [_cell_value(display, lineno, COLUMNS[j], cells[i]) for j, i in enumerate(idx)]
            t = row[0]
            if t_prev is not None:
                step = t - t_prev
                if not step > 0.0:
                    raise LogError(display, lineno, f"time {t!r} s does not increase (previous {t_prev!r} s)")
                if dt0 is None:
                    dt0 = step
                elif abs(step - dt0) > UNIFORM_TOL * dt0:
                    raise LogError(display, lineno,
                                   f"time step {step:.6g} s differs from the period {dt0:.6g} s "
                                   f"by more than {100 * UNIFORM_TOL:g} % (non-uniform sampling)")
            t_prev = t
            if k == 0:
                first_line = lineno
            buf[k] = row
            k += 1
            n += 1
            if k == block_rows:
                yield first_line, buf.copy()
                k = 0
    if idx is None:
        raise LogError(display, lineno, "empty file: no header t,ref,pos,force")
    if n < MIN_SAMPLES:
        raise LogError(display, lineno,
                       f"only {n} samples; at least {MIN_SAMPLES} are needed")
    if k:
        yield first_line, buf[:k].copy()


def read_log(path, max_samples=DEFAULT_MAX_SAMPLES, block_rows=BLOCK_ROWS):
    """Validates the whole file (streaming) and keeps its first max_samples rows."""
    parts = []
    kept = 0
    total = 0
    for _, blk in iter_blocks(path, block_rows):
        total += len(blk)
        if kept < max_samples:
            take = blk[: max_samples - kept]
            parts.append(take)
            kept += len(take)
    a = np.concatenate(parts) if len(parts) > 1 else parts[0]
    t = a[:, 0]
    dt = (t[-1] - t[0]) / (len(t) - 1)
    return Log(os.fspath(path), t.copy(), a[:, 1].copy(), a[:, 2].copy(), a[:, 3].copy(), dt, total)
