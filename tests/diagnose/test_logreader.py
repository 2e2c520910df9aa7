# SPDX-License-Identifier: Apache-2.0
"""Log reader (python/bristle/diagnose/logreader.py): what real files contain is
accepted, every problem is rejected with "file:line: problem", and a large
file streams in bounded memory. One test per guard."""
import os
import tempfile
import tracemalloc
import unittest

import numpy as np

from bristle.diagnose import logreader
from bristle.diagnose.logreader import LogError

N = logreader.MIN_SAMPLES + 20


def rows(n=N, dt=1e-3, extra=False):
    out = []
    for k in range(n):
        r = f"{k * dt:.6f},{1e-4 * k:.6e},{1e-4 * k - 1e-7:.6e},{0.5 * k:.6e}"
        out.append(r + (",7,x" if extra else ""))
    return out


class ReaderTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def write(self, text, name="log.csv", binary=False):
        p = os.path.join(self.dir.name, name)
        with open(p, "wb") as f:
            f.write(text if binary else text.encode("utf-8"))
        return p

    def expect_error(self, lines, line_no, fragment, binary=None):
        if binary is not None:
            p = self.write(binary, binary=True)
        else:
            p = self.write("\n".join(lines) + "\n")
        with self.assertRaises(LogError) as cm:
            logreader.read_log(p)
        msg = str(cm.exception)
        self.assertTrue(msg.startswith(f"{p}:{line_no}: "), msg)
        self.assertIn(fragment, msg)
        return msg

    # what real files contain
    def test_plain(self):
        log = logreader.read_log(self.write("t,ref,pos,force\n" + "\n".join(rows()) + "\n"))
        self.assertEqual(log.n, N)
        self.assertAlmostEqual(log.dt, 1e-3, places=12)
        self.assertAlmostEqual(log.force[10], 5.0)
        self.assertAlmostEqual(log.pos[10], 1e-3 - 1e-7)

    def test_bom_crlf_extra_columns_order_case_spaces(self):
        body = "\r\n".join(f"{r.split(',')[3]}, {r.split(',')[0]} ,{r.split(',')[2]},7,{r.split(',')[1]}"
                           for r in rows())
        text = "\ufeff\"Force\", T ,pos,temperature,REF\r\n" + body + "\r\n\r\n"
        log = logreader.read_log(self.write(text))
        self.assertEqual(log.n, N)
        self.assertAlmostEqual(log.t[3], 3e-3)
        self.assertAlmostEqual(log.ref[3], 3e-4)
        self.assertAlmostEqual(log.force[3], 1.5)

    def test_extra_columns_after(self):
        log = logreader.read_log(self.write("t,ref,pos,force,a,b\n" + "\n".join(rows(extra=True)) + "\n"))
        self.assertEqual(log.n, N)

    def test_no_trailing_newline_and_blank_lines(self):
        r = rows()
        text = "t,ref,pos,force\n\n" + "\n".join(r[:5]) + "\n   \n" + "\n".join(r[5:])
        self.assertEqual(logreader.read_log(self.write(text)).n, N)

    def test_quoted_fields_per_rfc4180(self):
        """Quoted numbers, and an extra column holding a comma, a doubled quote
        and a line end: parsed; the lines after it keep their numbers."""
        r = rows()
        r[0] = '"0.000000","0.0e+00",' + r[0].split(",", 2)[2] + ',"a, ""quoted""\nnote"'
        r[1:] = [x + ",plain" for x in r[1:]]
        r[5] = r[5].replace("0.005000", "0.004000")  # an error on data row 6: line 8 (row 1 spans two lines)
        text = "t,ref,pos,force,note\n" + "\n".join(r) + "\n"
        with self.assertRaises(LogError) as cm:
            logreader.read_log(self.write(text))
        self.assertIn(":8: time 0.004 s does not increase", str(cm.exception))
        r[5] = r[5].replace("0.004000", "0.005000")
        log = logreader.read_log(self.write("t,ref,pos,force,note\n" + "\n".join(r) + "\n"))
        self.assertEqual(log.n, N)
        self.assertEqual((log.t[0], log.ref[0]), (0.0, 0.0))

    def test_malformed_quoting(self):
        r = rows()
        r[3] = '"0.003000"x' + r[3][len("0.003000"):]
        self.expect_error(["t,ref,pos,force"] + r, 5, "malformed quoting")

    def test_max_samples_keeps_the_first(self):
        p = self.write("t,ref,pos,force\n" + "\n".join(rows(N + 500)) + "\n")
        log = logreader.read_log(p, max_samples=N)
        self.assertEqual((log.n, log.n_total), (N, N + 500))

    # what it rejects, naming the line
    def test_missing_column(self):
        msg = self.expect_error(["t,ref,force"] + rows(), 1, "header lacks column(s) pos")
        self.assertIn("expected t,ref,pos,force", msg)

    def test_header_is_data(self):
        self.expect_error(rows(), 1, "header lacks column(s) t, ref, pos, force")

    def test_duplicate_column(self):
        self.expect_error(["t,ref,pos,force,pos"] + [r + ",1" for r in rows()], 1, "names column(s) twice: pos")

    def test_short_row(self):
        r = rows()
        r[7] = "0.007000,1e-4,2e-4"
        self.expect_error(["t,ref,pos,force"] + r, 9, "3 fields, the header has 4")

    def test_non_numeric(self):
        r = rows()
        r[40] = r[40].rsplit(",", 1)[0] + ",12.5N"
        self.expect_error(["t,ref,pos,force"] + r, 42, "column 'force': '12.5N' is not a number")

    def test_digit_separator_is_not_a_number(self):
        r = rows()
        r[2] = r[2].rsplit(",", 1)[0] + ",1_000"
        self.expect_error(["t,ref,pos,force"] + r, 4, "'1_000' is not a number")

    def test_unicode_digits_are_not_numbers(self):
        for cell in ("١٢٫٥", "１２", "²", "0x10", "1e5j", "1_000", "0.5e"):
            r = rows()
            r[20] = r[20].rsplit(",", 1)[0] + "," + cell
            self.expect_error(["t,ref,pos,force"] + r, 22, "is not a number")

    def test_decimal_comma_is_refused(self):
        r = rows()
        r[8] = r[8].rsplit(",", 1)[0] + ',"12,5"'
        self.expect_error(["t,ref,pos,force"] + r, 10, "'12,5' is not a number (a decimal comma")

    def test_huge_cell(self):
        r = rows()
        r[30] = r[30].rsplit(",", 1)[0] + ",1e308"
        self.expect_error(["t,ref,pos,force"] + r, 32, "column 'force': 1e308 is beyond ±1e+09")

    def test_a_long_cell_is_echoed_short(self):
        r = rows()
        r[9] = r[9].rsplit(",", 1)[0] + "," + "7" * 1000 + "x" * 100_000
        msg = self.expect_error(["t,ref,pos,force"] + r, 11, "is not a number")
        self.assertLess(len(msg), len(self.dir.name) + 200, msg)
        self.assertIn("7" * (logreader.SHOW_CHARS - 1) + "…'", msg)
        r[9] = r[9].rsplit(",", 1)[0] + "," + "7" * 10_000_000  # 10 MB in one field
        msg = self.expect_error(["t,ref,pos,force"] + r, 11, "a field longer than 131072 characters")
        self.assertLess(len(msg), len(self.dir.name) + 200, msg)

    def test_all_zero_force(self):
        r = [x.rsplit(",", 1)[0] + ",0" for x in rows()]
        self.expect_error(["t,ref,pos,force"] + r, 2, f"column 'force' is 0 on every row (lines 2 to {N + 1}): "
                          "nothing to fit")

    def test_constant_position(self):
        r = [",".join(x.split(",")[:2] + ["0.25", x.split(",")[3]]) for x in rows()]
        self.expect_error(["", "t,ref,pos,force"] + r, 3, "column 'pos' is 0.25 on every row (lines 3 to "
                          f"{N + 2}): the axis does not move")

    def test_empty_cell(self):
        r = rows()
        parts = r[11].split(",")
        parts[2] = " "
        r[11] = ",".join(parts)
        self.expect_error(["t,ref,pos,force"] + r, 13, "column 'pos' is empty")

    def test_nan(self):
        r = rows()
        parts = r[100].split(",")
        parts[2] = "nan"
        r[100] = ",".join(parts)
        self.expect_error(["t,ref,pos,force"] + r, 102, "column 'pos' is NaN")

    def test_infinite(self):
        r = rows()
        parts = r[5].split(",")
        parts[1] = "-inf"
        r[5] = ",".join(parts)
        self.expect_error(["t,ref,pos,force"] + r, 7, "column 'ref' is infinite")

    def test_time_not_increasing(self):
        r = rows()
        r[500] = r[499]
        self.expect_error(["t,ref,pos,force"] + r, 502, "does not increase")

    def test_time_going_back(self):
        r = rows()
        r[4] = "0.002500" + r[4][len("0.004000"):]  # after 0.003 s
        self.expect_error(["t,ref,pos,force"] + r, 6, "time 0.0025 s does not increase (previous 0.003 s)")

    def test_non_uniform_time(self):
        r = rows()
        del r[300]  # a missing sample: one step of 2 ms, reaching line 302
        self.expect_error(["t,ref,pos,force"] + r, 302, "non-uniform sampling")

    def test_jitter_within_tolerance_is_accepted(self):
        r = rows()
        jittered = []
        for k, line in enumerate(r):
            parts = line.split(",")
            parts[0] = f"{k * 1e-3 + (2e-6 if k % 2 else 0.0):.7f}"  # +-0.2 % of the period
            jittered.append(",".join(parts))
        self.assertEqual(logreader.read_log(self.write("t,ref,pos,force\n" + "\n".join(jittered))).n, N)

    def test_too_few_samples(self):
        n = logreader.MIN_SAMPLES - 1
        self.expect_error(["t,ref,pos,force"] + rows(n), n + 1,
                          f"only {n} samples; at least {logreader.MIN_SAMPLES} are needed")

    def test_empty_file(self):
        self.expect_error([""], 1, "empty file")

    def test_not_utf8(self):
        data = ("t,ref,pos,force\n" + "\n".join(rows(20)) + "\n").encode() + b"\xff\xfe,1,2,3\n"
        self.expect_error(None, 22, "not UTF-8", binary=data)

    def test_missing_file(self):
        with self.assertRaises(LogError) as cm:
            logreader.read_log(os.path.join(self.dir.name, "absent.csv"))
        self.assertIn("absent.csv:0: cannot open", str(cm.exception))

    # bounded memory
    def test_read_log_keeps_four_float64_per_row(self):
        """read_log fills preallocated arrays: its peak allocation is the
        samples (32 bytes a row) and little more, not lists of strings or
        copies of blocks."""
        p = os.path.join(self.dir.name, "big.csv")
        n = 100_000
        k = np.arange(n)
        with open(p, "w") as f:
            f.write("t,ref,pos,force\n")
            np.savetxt(f, np.column_stack([k * 1e-3, 1e-7 * k, 1e-7 * k, np.sin(k * 1e-3)]),
                       fmt=["%.6f", "%.9e", "%.9e", "%.8e"], delimiter=",")
        tracemalloc.start()
        log = logreader.read_log(p)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        self.assertEqual(log.n, n)
        self.assertLess(peak, 1.05 * 32 * n + 1_500_000, f"peak {peak} bytes")  # the old reader: 3x the samples

    def test_streams_in_bounded_memory(self):
        """iter_blocks holds one block: its peak allocation does not grow with
        the file (100000 rows, 5 MB of text), while keeping the samples would
        take 3.2 MB."""
        p = os.path.join(self.dir.name, "big.csv")
        n = 100_000
        k = np.arange(n)
        data = np.column_stack([k * 1e-3, 1e-7 * k, 1e-7 * k, np.sin(k * 1e-3)])
        with open(p, "w") as f:
            f.write("t,ref,pos,force\n")
            np.savetxt(f, data, fmt=["%.6f", "%.9e", "%.9e", "%.8e"], delimiter=",")
        for block_rows in (4096,):
            tracemalloc.start()
            total = 0
            for _, blk in logreader.iter_blocks(p, block_rows=block_rows):
                total += len(blk)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            self.assertEqual(total, n)
            # two blocks (buffer + the copy handed out) plus line buffers
            self.assertLess(peak, 2 * block_rows * 4 * 8 + 1_000_000, f"peak {peak} bytes")


if __name__ == "__main__":
    unittest.main(verbosity=2)
