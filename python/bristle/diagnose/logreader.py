# SPDX-License-Identifier: Apache-2.0
"""Reader for measured logs (../shared/spec/measured-log.md): CSV with a
header naming at least t, ref, pos, force.

Tolerated: a UTF-8 byte-order mark, CRLF line ends, extra columns (ignored),
column names in any order and case, spaces around cells, blank lines, and
quoted fields per RFC 4180 (a quoted field may hold commas, doubled quotes
and line ends; "1.5" is the number 1.5).

Numbers are ASCII only, in the form [+-]digits[.digits][e[+-]digits] with a
decimal point: Unicode digits, digit separators, hexadecimal and a decimal
comma ("1,5", which can only reach a cell quoted) are refused, whatever the
locale. A number's magnitude is at most MAX_ABS.

Rejected, with "file:line: problem" (an echoed cell cut to SHOW_CHARS): a
header lacking a column, a row with the wrong number of fields, malformed
quoting, a field longer than csv.field_size_limit() (131072 characters), an
empty or non-numeric cell, NaN or infinity, a number beyond
MAX_ABS, a time that does not increase, a time step that differs from the
first one by more than UNIFORM_TOL of it, fewer than MIN_SAMPLES rows; and,
in read_log, a force or position that never changes (nothing to fit).

The file is read line by line and validated as it streams. read_log counts
the lines first and fills four preallocated float64 arrays (t, ref, pos,
force: 32 bytes a row, nothing else per row is kept); `iter_blocks` yields
fixed-size numpy blocks, so a caller can go through a file of any size in
bounded memory.
"""
import csv
import os
import re
import stat

import numpy as np

COLUMNS = ("t", "ref", "pos", "force")
MIN_SAMPLES = 1000
UNIFORM_TOL = 0.01          # relative deviation of a time step from the first
BLOCK_ROWS = 65536
DEFAULT_MAX_SAMPLES = 2_000_000
MAX_ABS = 1e9               # s, m, N: beyond it a cell is not a measurement
SHOW_CHARS = 40             # an echoed cell is cut to this many characters
COUNT_CHUNK = 1 << 20

NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
DECIMAL_COMMA = re.compile(r"[+-]?[0-9]+,[0-9]+")
NAN_WORDS = {"nan", "+nan", "-nan"}
INF_WORDS = {"inf", "+inf", "-inf", "infinity", "+infinity", "-infinity"}


class LogError(ValueError):
    """A log the diagnosis cannot use; str() is "file:line: problem"."""

    def __init__(self, path, line, problem):
        super().__init__(f"{path}:{line}: {problem}")
        self.path, self.line, self.problem = path, line, problem


def short(s, n=SHOW_CHARS):
    """s cut to n characters with an ellipsis (an echoed cell or value)."""
    return s if len(s) <= n else s[: n - 1] + "…"


class Log:
    """Samples of one log: t, ref, pos, force (float64 arrays) and the period."""

    def __init__(self, path, t, ref, pos, force, dt, n_total):
        self.path, self.t, self.ref, self.pos, self.force = path, t, ref, pos, force
        self.dt = dt
        self.n = len(t)
        self.n_total = n_total  # rows in the file (may exceed n with max_samples)


def open_regular(path, mode="rb", **kw):
    """path opened, when it is a regular file: a device (/dev/zero, a
    terminal), a FIFO, a socket or a folder is refused with LogError before
    it is opened (a FIFO's open or a device's read would block or never
    end), and checked again on the open file."""
    display = os.fspath(path)
    try:
        st = os.stat(path)
    except OSError as e:
        raise LogError(display, 0, f"cannot open: {e.strerror}") from None
    if not stat.S_ISREG(st.st_mode):
        raise LogError(display, 0, f"not a regular file ({_kind(st.st_mode)}); a log, model or machine file is "
                                   "read from a file")
    try:
        f = open(path, mode, **kw)
    except OSError as e:
        raise LogError(display, 0, f"cannot open: {e.strerror}") from None
    if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):
        f.close()
        raise LogError(display, 0, "not a regular file (it changed while being opened)")
    return f


def _kind(mode):
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a file"


def _cell_value(path, lineno, name, cell):
    s = cell.strip()
    if not s:
        raise LogError(path, lineno, f"column '{name}' is empty")
    if NUMBER.fullmatch(s) is None:
        low = s.lower()
        if low in NAN_WORDS:
            raise LogError(path, lineno, f"column '{name}' is NaN")
        if low in INF_WORDS:
            raise LogError(path, lineno, f"column '{name}' is infinite")
        why = " (a decimal comma; the log's decimal mark is '.')" if DECIMAL_COMMA.fullmatch(s) else ""
        raise LogError(path, lineno, f"column '{name}': '{short(s)}' is not a number{why}")
    v = float(s)
    if not abs(v) <= MAX_ABS:
        raise LogError(path, lineno, f"column '{name}': {short(s)} is beyond ±{MAX_ABS:g}")
    return v


def _header(path, lineno, cells):
    names = [c.strip().lower() for c in cells]
    missing = [c for c in COLUMNS if c not in names]
    if missing:
        found = ", ".join(short(n) for n in names[:8] if n) + (", …" if len(names) > 8 else "")
        raise LogError(path, lineno, "header lacks column(s) " + ", ".join(missing) +
                       f" (found: {found or 'nothing'}); expected t,ref,pos,force")
    dup = [c for c in COLUMNS if names.count(c) > 1]
    if dup:
        raise LogError(path, lineno, "header names column(s) twice: " + ", ".join(dup))
    return [names.index(c) for c in COLUMNS], len(names)


class _Lines:
    """The file's lines as text, decoded one by one (invalid UTF-8 names its
    line); `n` is the number of lines read so far."""

    def __init__(self, f, path):
        self.f, self.path, self.n = f, path, 0

    def __iter__(self):
        for raw in self.f:
            self.n += 1
            try:
                line = raw.decode("utf-8")
            except UnicodeDecodeError as e:
                raise LogError(self.path, self.n, f"not UTF-8 text ({e.reason} at byte {e.start})") from None
            if self.n == 1 and line.startswith("\ufeff"):
                line = line[1:]
            yield line


def _rows(path):
    """Yields (line, t, ref, pos, force) of every validated row; raises
    LogError at the first problem, including too few samples at the end."""
    display = os.fspath(path)
    f = open_regular(path)
    idx = ncols = None
    t_prev = dt0 = None
    n = 0
    with f:
        lines = _Lines(f, display)
        reader = csv.reader(lines, skipinitialspace=True, strict=True)
        start = 1
        while True:
            try:
                cells = next(reader)
            except StopIteration:
                break
            except csv.Error as e:
                if "field limit" in str(e):
                    raise LogError(display, start, f"a field longer than {csv.field_size_limit()} characters, "
                                   "not a measurement") from None
                raise LogError(display, start, f"malformed quoting ({e})") from None
            lineno, start = start, lines.n + 1
            if not cells or (len(cells) == 1 and not cells[0].strip()):
                continue
            if idx is None:
                idx, ncols = _header(display, lineno, cells)
                continue
            if len(cells) != ncols:
                raise LogError(display, lineno, f"{len(cells)} fields, the header has {ncols}")
            t, ref, pos, force = (_cell_value(display, lineno, COLUMNS[j], cells[i]) for j, i in enumerate(idx))
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
            n += 1
            yield lineno, t, ref, pos, force
        last = lines.n
    if idx is None:
        raise LogError(display, max(last, 1), "empty file: no header t,ref,pos,force")
    if n < MIN_SAMPLES:
        raise LogError(display, last, f"only {n} samples; at least {MIN_SAMPLES} are needed")


def iter_blocks(path, block_rows=BLOCK_ROWS):
    """Yields (first_line, array of shape (k, 4): t, ref, pos, force) blocks of
    at most block_rows validated rows; raises LogError at the first problem,
    including too few samples at the end of the file. Memory: one block."""
    buf = np.empty((block_rows, 4))
    k = 0
    first_line = None
    for lineno, *row in _rows(path):
        if k == 0:
            first_line = lineno
        buf[k] = row
        k += 1
        if k == block_rows:
            yield first_line, buf.copy()
            k = 0
    if k:
        yield first_line, buf[:k].copy()


def _count_lines(path):
    n = 1  # a last line without its line end
    try:
        with open(path, "rb") as f:
            while chunk := f.read(COUNT_CHUNK):
                n += chunk.count(b"\n")
    except OSError:
        pass  # _rows names the problem
    return n


def _degenerate(path, first, last, name, a):
    if a[0] == a[-1] and np.all(a == a[0]):
        what = "nothing to fit" if name == "force" else "the axis does not move"
        raise LogError(path, first, f"column '{name}' is {a[0]:g} on every row (lines {first} to {last}): {what}")


def read_log(path, max_samples=DEFAULT_MAX_SAMPLES):
    """Validates the whole file (streaming) and keeps its first max_samples
    rows in four preallocated float64 arrays."""
    display = os.fspath(path)
    open_regular(path).close()  # a device or a FIFO: refused before the lines are counted
    cap = max(1, min(_count_lines(path), max_samples))
    cols = [np.empty(cap) for _ in COLUMNS]
    t, ref, pos, force = cols
    n = total = 0
    first = last = 0
    for lineno, *row in _rows(path):
        if n < cap:
            t[n], ref[n], pos[n], force[n] = row
            n += 1
            last = lineno
        first = first or lineno
        total += 1
    t, ref, pos, force = (c[:n] for c in cols)
    _degenerate(display, first, last, "force", force)
    _degenerate(display, first, last, "pos", pos)
    dt = (t[-1] - t[0]) / (n - 1)
    return Log(display, t, ref, pos, force, dt, total)
