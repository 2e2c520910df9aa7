# SPDX-License-Identifier: Apache-2.0
"""br_track reads its log by the diagnosis's rules (sim/lib/tool/br_logcsv.h)
and writes every output through br_outfile (docs/tools.md):

- each bad log of the audit (an empty cell, 0.001abc, a hexadecimal float,
  time running backwards, a 1e6 s step, a 1e300 s time, a first step of
  1e6 s, /dev/zero and a FIFO) exits 1 with "file:line: problem", under a
  timeout (it hung on some), before any output: an existing --json and
  trace are left byte for byte and no temporary file remains. The
  host-debug build runs under AddressSanitizer, whose leak check turns a
  leak on the error path into another exit status: the test's exit 1 is
  also the leak check;
- a good log with quoted cells, a byte-order mark, CRLF, spaces, extra
  columns and blank lines tracks as the plain one does;
- --trace writes its files only when every run succeeded;
- br_pf_study refuses a FIFO as --table at once;
- br_bench checks its --json and --record destinations before the run
  (a folder as --record: exit 1, nothing run, an existing --json byte for
  byte; it wrote them with fopen after a run of minutes).

Usage: test_track_bench_io.py --bin DIR --work DIR"""
import argparse
import os
import shutil
import subprocess
import sys
import unittest

ARGS = None
OLD = b"an existing file\n"
ROWS = ["%.6f,%.9e" % (k * 1e-3, 1e-3 * min(k / 500.0, 1.0)) for k in range(1000)]


def track(*a):
    ctrl = () if "--ctrl" in a else ("--ctrl", "hinf_only")
    return subprocess.run([os.path.join(ARGS.bin, "br_track"), *ctrl, *a], capture_output=True, text=True,
                          timeout=120)


class TrackInput(unittest.TestCase):
    def setUp(self):
        self.w = os.path.join(ARGS.work, self.id().rsplit(".", 1)[-1])
        shutil.rmtree(self.w, ignore_errors=True)
        os.makedirs(self.w)

    def log(self, name, rows, head="t,ref\n", end="\n"):
        p = os.path.join(self.w, name)
        with open(p, "w", newline="") as f:
            f.write(head + end.join(rows) + end)
        return p

    def edited(self, name, k, row):
        rows = list(ROWS)
        rows[k] = row
        return self.log(name, rows)

    def test_bad_logs_refused(self):
        js, tdir = os.path.join(self.w, "t.json"), os.path.join(self.w, "trace")
        os.makedirs(tdir)
        old_trace = os.path.join(tdir, "track_hinf_only.csv")
        for p in (js, old_trace):
            with open(p, "wb") as f:
                f.write(OLD)
        steps = list(ROWS[:10]) + ["%.6f,1e-3" % (1e6 + k * 1e-3) for k in range(10, 1000)]
        first = list(ROWS)
        first[1] = "1000000.0,0"
        fifo = os.path.join(self.w, "fifo")
        os.mkfifo(fifo)
        cases = ((self.edited("empty.csv", 10, "0.010000,"), ":12: column 'ref' is empty"),
                 (self.edited("empty_t.csv", 10, ",0.001"), ":12: column 't' is empty"),
                 (self.edited("abc.csv", 10, "0.010000,0.001abc"), ":12: column 'ref': '0.001abc' is not a number"),
                 (self.edited("hex.csv", 10, "0.010000,0x1p-3"), ":12: column 'ref': '0x1p-3' is not a number"),
                 (self.edited("nan.csv", 10, "0.010000,nan"), ":12: column 'ref': 'nan' is not a number"),
                 (self.edited("back.csv", 10, "0.009000,0"), ":12: time 0.009 s does not increase"),
                 (self.log("step6.csv", steps), ":12: time step 1e+06 s differs from the period 0.001 s"),
                 (self.edited("huge.csv", 10, "1e300,0"), ":12: column 't': 1e300 is beyond"),
                 (self.log("first6.csv", first), ":3: the log lasts more than 3600 s"),
                 (self.edited("fields.csv", 10, "0.010000,0,7"), ":12: 3 fields, the header has 2"),
                 (self.edited("quote.csv", 10, '0.010000,"1,5"'), ":12: malformed quoting"),
                 (self.log("nohead.csv", ROWS, head="time,ref\n"), ":1: header lacks column t"),
                 (self.log("twice.csv", [r + ",0" for r in ROWS], head="t,ref,REF\n"), ":1: header names column ref twice"),
                 (self.log("short.csv", ROWS[:1]), ":2: only 1 rows"),
                 ("/dev/zero", "/dev/zero:0: not a regular file"),
                 (fifo, "fifo:0: not a regular file"))
        for path, fragment in cases:
            with self.subTest(log=os.path.basename(path)):
                r = track("--ref", path, "--json", js, "--trace", tdir)
                self.assertEqual(r.returncode, 1, r.stderr)
                self.assertIn(fragment, r.stderr)
                self.assertEqual(r.stdout, "")
                for p in (js, old_trace):
                    with open(p, "rb") as f:
                        self.assertEqual(f.read(), OLD)
                self.assertEqual(sorted(os.listdir(tdir)), ["track_hinf_only.csv"])
                self.assertEqual([n for n in os.listdir(self.w) if ".tmp-" in n], [])

    def test_tolerated_forms_track_alike(self):
        plain = track("--ref", self.log("plain.csv", ROWS))
        self.assertEqual(plain.returncode, 0, plain.stderr)
        dressed = ['"%s", %s ,7' % tuple(r.split(",")) for r in ROWS]
        dressed.insert(500, "   ")
        p = self.log("dressed.csv", dressed, head='\ufeff"T", Ref ,extra\r\n', end="\r\n")
        r = track("--ref", p)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(r.stdout, plain.stdout)

    def test_traces_only_when_every_run_succeeded(self):
        tdir = os.path.join(self.w, "trace")
        os.makedirs(tdir)
        p = self.log("plain.csv", ROWS)
        # hinf_pf's trace cannot be written (a folder of its name): the run fails after hinf_only's trace was written
        os.makedirs(os.path.join(tdir, "pf_hinf_pf.csv"))
        r = track("--ref", p, "--ctrl", "hinf_only,hinf_pf", "--trace", tdir)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("pf_hinf_pf.csv: is a directory", r.stderr)
        self.assertEqual(os.listdir(tdir), ["pf_hinf_pf.csv"])
        os.rmdir(os.path.join(tdir, "pf_hinf_pf.csv"))
        r = track("--ref", p, "--trace", tdir)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(os.listdir(tdir), ["track_hinf_only.csv"])
        with open(os.path.join(tdir, "track_hinf_only.csv")) as f:
            self.assertEqual(len(f.read().splitlines()), 1 + 1000)


class PfStudyTable(unittest.TestCase):
    def test_fifo_table_refused(self):
        """br_pf_study --table FIFO: refused at once (its open waited for a writer)"""
        w = os.path.join(ARGS.work, "pf_table")
        shutil.rmtree(w, ignore_errors=True)
        os.makedirs(w)
        fifo = os.path.join(w, "fifo")
        os.mkfifo(fifo)
        r = subprocess.run([os.path.join(ARGS.bin, "br_pf_study"), "--table", fifo], capture_output=True, text=True,
                           timeout=60)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn(f"{fifo}: not a regular file", r.stderr)


class BenchOutputs(unittest.TestCase):
    def test_destinations_checked_before_the_run(self):
        w = os.path.join(ARGS.work, "bench")
        shutil.rmtree(w, ignore_errors=True)
        os.makedirs(os.path.join(w, "rec"))
        js = os.path.join(w, "b.json")
        with open(js, "wb") as f:
            f.write(OLD)
        for extra, fragment in ((["--record", os.path.join(w, "rec")], "rec: is a directory"),
                                (["--record", os.path.join(w, "none", "r.csv")], "No such file or directory")):
            r = subprocess.run([os.path.join(ARGS.bin, "br_bench"), "--json", js, "--reps", "1", *extra],
                               capture_output=True, text=True, timeout=600)
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn(fragment, r.stderr)
            self.assertEqual(r.stdout, "")  # nothing ran
            with open(js, "rb") as f:
                self.assertEqual(f.read(), OLD)
            self.assertEqual([n for n in os.listdir(w) if ".tmp-" in n], [])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest)
