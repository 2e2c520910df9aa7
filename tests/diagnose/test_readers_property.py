# SPDX-License-Identifier: Apache-2.0
"""Property-based tests (hypothesis) of the diagnosis's readers: the log
reader (logreader.read_log), the model-file reader (modelfile.load) and the
machine-file reader (machinefile.load).

  - a random valid log, written in any of the tolerated forms (column order
    and case, extra columns, quoting, spaces, CRLF, BOM, blank lines), reads
    back exactly;
  - a random valid model file reads back exactly;
  - a random mutation of a valid file either reads or raises the reader's
    error whose text is "file:line: problem" with a line inside the file;
    never another exception.

Deterministic (derandomize) and without an example database, so a ctest run
is repeatable and writes nothing into the tree."""
import atexit
import json
import math
import os
import re
import shutil
import tempfile
import unittest

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.configuration import set_hypothesis_home_dir

from bristle.diagnose import causes, closedloop, logreader, machinefile, modelfile, params
from bristle.diagnose.logreader import LogError

SETTINGS = settings(deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.register_profile("bristle", SETTINGS)
settings.load_profile("bristle")
N = logreader.MIN_SAMPLES + 5
TMP = tempfile.mkdtemp(prefix="br_property_")
atexit.register(shutil.rmtree, TMP, True)
set_hypothesis_home_dir(os.path.join(TMP, ".hypothesis"))  # its caches: not in the source tree


def write(name, data):
    p = os.path.join(TMP, name)
    with open(p, "wb") as f:
        f.write(data)
    return p


def assert_clean_error(test, err, path, data):
    """err is "path:line: problem" with 0 <= line <= the file's lines + 1."""
    m = re.match(re.escape(path) + r":(\d+): (.+)", str(err), re.S)
    test.assertIsNotNone(m, str(err))
    test.assertLessEqual(int(m.group(1)), data.count(b"\n") + 1, str(err))
    test.assertLess(len(str(err)), len(path) + 400, "a message echoes too much")


# ---- logs ---------------------------------------------------------------------------
finite = st.floats(min_value=-logreader.MAX_ABS, max_value=logreader.MAX_ABS, allow_nan=False)


@st.composite
def valid_logs(draw):
    dt = draw(st.floats(min_value=1e-4, max_value=1e-2))
    t0 = draw(st.floats(min_value=-100.0, max_value=100.0))
    base = [draw(finite) for _ in range(3)]  # ref, pos, force: a value plus a ramp, never constant
    slope = [draw(st.floats(min_value=1e-6, max_value=1e3)) for _ in range(3)]
    cols = {"t": [t0 + k * dt for k in range(N)]}
    for j, name in enumerate(("ref", "pos", "force")):
        cols[name] = [max(-1e9, min(1e9, base[j] - k * slope[j] if base[j] > 0 else base[j] + k * slope[j]))
                      for k in range(N)]
    order = draw(st.permutations(["t", "ref", "pos", "force", "extra"]))
    form = draw(st.fixed_dictionaries({
        "crlf": st.booleans(), "bom": st.booleans(), "quote": st.booleans(), "space": st.booleans(),
        "upper": st.booleans(), "blank": st.booleans()}))
    return cols, order, form


def render(cols, order, form):
    nl = "\r\n" if form["crlf"] else "\n"
    q = (lambda s: '"' + s + '"') if form["quote"] else (lambda s: s)
    sp = " " if form["space"] else ""  # before a quoted field; after one it is malformed (RFC 4180)
    head = ",".join(q(c.upper() if form["upper"] else c) for c in order)
    lines = [("\ufeff" if form["bom"] else "") + head]
    for k in range(N):
        cells = ['"x, ""y"""' if c == "extra" else q(repr(cols[c][k])) for c in order]
        lines.append(",".join(sp + c + ("" if c.startswith('"') else sp) for c in cells))
        if form["blank"] and k == N // 2:
            lines.append("")
    return (nl.join(lines) + nl).encode("utf-8")


class LogProperty(unittest.TestCase):
    @settings(SETTINGS, max_examples=40)
    @given(valid_logs())
    def test_valid_logs_round_trip(self, case):
        cols, order, form = case
        p = write("valid.csv", render(cols, order, form))
        log = logreader.read_log(p)
        self.assertEqual(log.n, N)
        for name in ("t", "ref", "pos", "force"):
            self.assertEqual(getattr(log, name).tolist(), cols[name], name)

    @settings(SETTINGS, max_examples=150)
    @given(st.data())
    def test_mutated_logs_read_or_fail_cleanly(self, data):
        text = bytearray(render({"t": [k * 1e-3 for k in range(N)], "ref": [1e-4 * k for k in range(N)],
                                 "pos": [1e-4 * k - 1e-7 for k in range(N)], "force": [0.5 * k for k in range(N)]},
                                ["t", "ref", "pos", "force"], dict.fromkeys(("crlf", "bom", "quote", "space",
                                                                             "upper", "blank"), False)))
        pieces = st.sampled_from([b",", b'"', b"\n", b"\r\n", b"", b" ", b"nan", b"-inf", b"1e308", b"\xff",
                                  "١٢".encode(), b"\x00", b"1,5", b"0.0005", b"x" * 200_000, b"t,ref,pos,force"])
        for _ in range(data.draw(st.integers(1, 4))):
            i = data.draw(st.integers(0, len(text)))
            j = data.draw(st.integers(i, min(len(text), i + 40)))
            text[i:j] = data.draw(st.one_of(pieces, st.binary(max_size=8)))
        p = write("mutated.csv", bytes(text))
        try:
            logreader.read_log(p)
        except LogError as e:
            assert_clean_error(self, e, p, bytes(text))


# ---- model and machine files ---------------------------------------------------------
def in_bounds(q):
    lo = 1e-9 if q.lo == params.GT0 else q.lo
    return st.floats(min_value=lo, max_value=q.hi, allow_nan=False, allow_infinity=False)


@st.composite
def valid_models(draw):
    listed = draw(st.lists(st.sampled_from(causes.NAMES), unique=True))
    need = params.NOMINAL + tuple(q for m in causes.of(listed) for q in m.PARAMS)
    p = {q.name: draw(in_bounds(q)) for q in need}
    for names, holds, _ in params.RELATIONS:
        if all(k in p for k in names) and not holds(p):
            p[names[-1]] = 0.0  # 0 satisfies every relation (Fc_N > 0, sigma2_Nspm >= 0)
    nominal = {q.name: draw(in_bounds(q)) for q in params.NOMINAL}
    m = {"format": modelfile.MODEL_FORMAT, "causes": [c for c in causes.NAMES if c in listed],
         "filter": {"order": 4, "fc_hz": draw(st.floats(min_value=1.0, max_value=500.0))},
         "params": p, "nominal_params": nominal}
    if modelfile.PRESLIDING in listed:
        # its element set: 1..8 breakaway displacements in (0, 1e-2] m, shares summing to 1
        d = draw(st.lists(st.floats(min_value=1e-9, max_value=1e-2), min_size=1, max_size=modelfile.ELEMENTS_MAX))
        w = draw(st.lists(st.integers(1, 1000), min_size=len(d), max_size=len(d)))
        m["presliding"] = {"breakaway_m": d, "share": [x / sum(w) for x in w]}
    return m


def mutate(data, text):
    b = bytearray(text.encode())
    pieces = st.sampled_from([b"0", b"-1", b"1e308", b"1e999", b"NaN", b"true", b"null", b'"x"', b"[]", b"{}", b",",
                              b":", b"\n", b'"', b"}", b'"Fc_N"', b'"offset"', b"\xff", b"1" * 500])
    for _ in range(data.draw(st.integers(1, 3))):
        i = data.draw(st.integers(0, len(b)))
        j = data.draw(st.integers(i, min(len(b), i + 12)))
        b[i:j] = data.draw(st.one_of(pieces, st.binary(max_size=6)))
    return bytes(b)


class ModelProperty(unittest.TestCase):
    @settings(SETTINGS, max_examples=150)
    @given(valid_models())
    def test_valid_models_round_trip(self, m):
        p = write("model.json", json.dumps(m, indent=2).encode())
        got = modelfile.load(p)
        self.assertEqual(got["params"], m["params"])
        self.assertEqual(got["nominal_params"], m["nominal_params"])

    @settings(SETTINGS, max_examples=300)
    @given(valid_models(), st.data())
    def test_mutated_models_read_or_fail_cleanly(self, m, data):
        text = mutate(data, json.dumps(m, indent=2))
        p = write("mutated_model.json", text)
        try:
            got = modelfile.load(p)
        except LogError as e:
            assert_clean_error(self, e, p, text)
            return
        for q in causes.MODEL_PARAMS:  # what loads is within the table's bounds
            if q.name in got["params"]:
                self.assertIsNone(q.check(got["params"][q.name]))

    @settings(SETTINGS, max_examples=300)
    @given(st.data())
    def test_mutated_machine_files_read_or_fail_cleanly(self, data):
        with open(os.path.join(machinefile.MACHINES_DIR, "emps.json")) as f:
            text = mutate(data, f.read())
        p = write("mutated_machine.json", text)
        try:
            _, ctrl = machinefile.load(p)
        except LogError as e:
            assert_clean_error(self, e, p, text)
            return
        except closedloop.ControllerError as e:
            self.assertRegex(str(e), "^" + re.escape(p) + r":\d+: ")
            return
        if ctrl is not None:
            for q in closedloop.CONTROLLER:
                self.assertTrue(math.isfinite(ctrl[q.name]) and q.check(ctrl[q.name]) is None)


if __name__ == "__main__":
    unittest.main(verbosity=2)
