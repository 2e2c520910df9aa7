# SPDX-License-Identifier: Apache-2.0
"""The figures README.md cites, each checked against what produces it, at
the precision the README prints (docs/measurements.md, "How the README's
figures are checked"):

- the demo's tables (hardware-like plant, the LuGre plant) and the realistic
  plant's figures in the prose: a fresh `br_demo_circle --out DIR`'s
  summary.json (contour RMS, thesis figure, period), the PF's particle count
  from machines/reference.json;
- the ISO 230-4 circular deviations G: sim/plots/iso230_4.py on that run;
- the robustness medians and lost counts: docs/robustness-results.md, which
  sim/studies/robustness.py writes (`make robustness N=200`);
- the fleet's ratios and run counts: docs/fleet.md's generated part, which
  sim/studies/fleet.py --md writes (`make fleet N=200`);
- the drawn Maxwell-slip plants' stops and medians: docs/presliding-plants.md's
  generated part, which sim/studies/mslip_plants.py --md writes
  (`make mslip-plants N=200`).

A README figure that disagrees fails the test; so does a README whose
sentences or tables the parser no longer finds. Then every checked figure
is changed by one in its last printed digit, one at a time, in a copy of
the README: each such copy must fail (the test shows it can).

Usage: test_readme_figures.py --demo BR_DEMO_CIRCLE --work DIR [--root DIR]"""
import argparse
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NUM = r"(\d+(?:\.\d+)?(?:e[+-]?\d+)?)"

# README row label -> the demo summary's controller key
DEMO_ROWS = {
    "H-inf only": "hinf_only",
    "H-inf + UKF": "hinf_ukf",
    "H-inf + PF": "hinf_pf",
    "compensation with the true friction": "hinf_true",
    "H-inf + static feedforward": "hinf_ff",
}
UNIT = {"m": 1.0, "µm": 1e-6, "nm": 1e-9, "ms": 1e-3}


def as_printed(printed, value):
    """value written the way `printed` is (same notation, same digits)"""
    if "e" in printed:
        mant = printed.split("e")[0]
        sig = len(mant.replace(".", "").lstrip("0"))
        return "%.*e" % (sig - 1, value)
    if "." in printed:
        return "%.*f" % (len(printed.split(".")[1]), value)
    return "%d" % round(value)


class Checks:
    """collects (README span, printed text, value from the source, what) and
    the problems: a figure that differs, a sentence or table not found"""

    def __init__(self, text):
        self.text = text
        self.figures = []
        self.problems = []

    def figure(self, m, group, value, what, scale=1.0):
        printed = m.group(group)
        want = as_printed(printed, value / scale)
        self.figures.append((m.span(group), printed, what))
        if float(want) != float(printed):
            self.problems.append("%s: README %s, source %s" % (what, printed, want))

    def find(self, pattern, what, start=0, end=None):
        m = re.compile(pattern, re.S | re.M).search(self.text, start, len(self.text) if end is None else end)
        if m is None:
            self.problems.append("not found in README.md: %s (/%s/)" % (what, pattern))
        return m


def section(c, title):
    m = c.find(r"^## " + re.escape(title) + r"\n", "section " + title)
    if m is None:
        return 0, 0
    nxt = re.compile(r"^## ", re.M).search(c.text, m.end())
    return m.end(), nxt.start() if nxt else len(c.text)


def check_demo_tables(c, summary, n_particles):
    start, end = section(c, "What `make demo` shows")
    row = re.compile(r"^\| (?P<label>[^|(]+?)(?: \((?P<ms>" + NUM[1:-1] + r") ms(?:, (?P<np>\d+) particles)?\))?"
                     r" \| (?P<rms>" + NUM[1:-1]
                     + r") m \| (?:(?P<thesis>" + NUM[1:-1] + r") m|—) \|$", re.M)
    tables = list(re.compile(r"^\| controller \| contour RMS \|.*?\n(?=\n)", re.M | re.S).finditer(c.text, start, end))
    seen = set()
    for t in tables:
        before = c.text[max(start, t.start() - 600):t.start()]
        plant = ("hardware_like" if "hardware-like plant" in before
                 else "reference" if "model's own world" in before else None)
        if plant is None:
            c.problems.append("README.md: a demo table at %d whose plant the text before it does not name" % t.start())
            continue
        seen.add(plant)
        rows = list(row.finditer(c.text, t.start(), t.end()))
        if len(rows) != t.group(0).count("\n") - 2:
            c.problems.append("README.md: %s table: a row the parser does not read" % plant)
        ctl = summary if plant == "reference" else summary[plant]
        for r in rows:
            key = DEMO_ROWS.get(r.group("label").strip())
            if key is None:
                c.problems.append("README.md: %s table: unknown row %r" % (plant, r.group("label")))
                continue
            o = ctl[key]
            if o.get("faulted"):
                c.problems.append("%s %s: the demo run faulted; not a figure" % (plant, key))
            what = "%s %s" % (plant, key)
            c.figure(r, "rms", o["contour_rms_m"], what + " contour RMS [m]")
            if r.group("thesis") is None:
                if o["thesis_contour_rms_m"] is not None:
                    c.problems.append("%s: README —, the summary has a thesis figure" % what)
            else:
                c.figure(r, "thesis", o["thesis_contour_rms_m"], what + " thesis RMS [m]")
            if r.group("ms"):
                c.figure(r, "ms", o["dt_s"], what + " period [ms]", UNIT["ms"])
            if r.group("np"):
                c.figure(r, "np", n_particles, what + " particles (machines/reference.json)")
    for plant in ("hardware_like", "reference"):
        if plant not in seen:
            c.problems.append("README.md: the %s demo table not found" % plant)


def check_realistic_prose(c, summary):
    ws = r"\s+"
    pat = ("realistic" + ws + "plant.*?the" + ws + "demo's" + ws + "second" + ws + "table" + ws + "gives" + ws
           + "H-inf" + ws + "only" + ws + NUM + ws + r"m," + ws + r"\+" + ws + "UKF" + ws + NUM + ws + r"m," + ws
           + r"\+" + ws + "PF" + ws + NUM + ws + r"m," + ws + r"\+" + ws + "static" + ws + "friction" + ws
           + "feedforward" + ws + NUM + ws + "m")
    m = c.find(pat, "the realistic plant's figures")
    if m:
        for g, key in enumerate(("hinf_only", "hinf_ukf", "hinf_pf", "hinf_ff"), 1):
            c.figure(m, g, summary["realistic"][key]["contour_rms_m"], "realistic %s contour RMS [m]" % key)


def check_iso_g(c, summary):
    m = c.find(r"circular\s+deviation\s+G\s+\(" + NUM + r"\s+(µm|nm)\s+H-inf\s+only,\s+" + NUM
               + r"\s+(µm|nm)\s+with\s+the\s+UKF\)", "the ISO 230-4 G figures")
    if m:
        for g, key in ((1, "hinf_only"), (3, "hinf_ukf")):
            c.figure(m, g, summary[key]["iso230_4"]["circular_deviation_m"], "G %s" % key, UNIT[m.group(g + 1)])


def table_rows(page, first_cell_re, heading=None):
    """{first cell: [cells]} of the markdown table rows of page (after heading)"""
    text = open(page, encoding="utf-8").read()
    if heading is not None:
        i = text.find(heading)
        if i < 0:
            raise SystemExit("%s: %r not found" % (page, heading))
        j = text.find("\n#", i + len(heading))
        text = text[i:j if j > 0 else len(text)]
    rows = {}
    for line in text.splitlines():
        cells = [x.strip() for x in line.strip().strip("|").split("|")]
        if line.startswith("|") and re.fullmatch(first_cell_re, cells[0]) and cells[0] not in rows:
            rows[cells[0]] = cells
    return rows


def metres(cell):
    return float(cell.split()[0])


def check_robustness(c, root):
    rows = table_rows(os.path.join(root, "docs", "robustness-results.md"), r"hinf_\w+")
    m = c.find(r"The\s+UKF\s+is\s+ahead\s+in\s+the\s+median\s+\(" + NUM + r"\s+against\s+" + NUM + r"\s+m\)",
               "the robustness medians")
    if m:
        c.figure(m, 1, metres(rows["hinf_ukf"][2]), "robustness hinf_ukf median [m]")
        c.figure(m, 2, metres(rows["hinf_pf"][2]), "robustness hinf_pf median [m]")
    if c.find(r"neither\s+estimator\s+loses\s+lock\s+on\s+any\s+plant", "the robustness lost count") is not None:
        for k in ("hinf_ukf", "hinf_pf"):
            if rows[k][5] != "0":
                c.problems.append("robustness %s: README says no lost plant, robustness-results.md %s" % (k, rows[k][5]))


def check_fleet(c, root):
    page = os.path.join(root, "docs", "fleet.md")
    every = table_rows(page, r"hinf_\w+", "### All trajectories")
    thesis = table_rows(page, r"hinf_\w+", "### thesis_circle")
    circle = table_rows(page, r"hinf_\w+", "### circle\n")
    m = c.find(r"\(thesis\s+circle\s+PF\s+" + NUM + r",\s+UKF\s+" + NUM + r",\s+other\s+circles\s+PF\s+" + NUM
               + r",\s+UKF\s+" + NUM + r"\)", "the fleet's circle ratios")
    if m:
        c.figure(m, 1, float(thesis["hinf_pf"][6]), "fleet thesis_circle hinf_pf ratio")
        c.figure(m, 2, float(thesis["hinf_ukf"][6]), "fleet thesis_circle hinf_ukf ratio")
        c.figure(m, 3, float(circle["hinf_pf"][6]), "fleet circle hinf_pf ratio")
        c.figure(m, 4, float(circle["hinf_ukf"][6]), "fleet circle hinf_ukf ratio")
    m = c.find(r"over\s+all\s+" + NUM + r"\s+runs\s+each\s+the\s+PF\s+went\s+to\s+the\s+end\s+in\s+" + NUM
               + r"\s+and\s+the\s+UKF\s+in\s+" + NUM, "the fleet's run counts")
    if m:
        c.figure(m, 1, int(every["hinf_pf"][1]), "fleet runs hinf_pf")
        c.figure(m, 1, int(every["hinf_ukf"][1]), "fleet runs hinf_ukf")
        c.figure(m, 2, int(every["hinf_pf"][2]), "fleet went to the end hinf_pf")
        c.figure(m, 3, int(every["hinf_ukf"][2]), "fleet went to the end hinf_ukf")


def check_mslip_plants(c, root):
    page = os.path.join(root, "docs", "presliding-plants.md")
    rows = table_rows(page, r"H-inf only|\+ UKF|\+ PF", "<!-- mslip-plants:begin -->")
    m = c.find(r"the\s+UKF\s+on\s+" + NUM + r"\s+and\s+the\s+PF\s+on\s+" + NUM + r",.*?their\s+medians\s+are\s+"
               + NUM + r"\s+m\s+\(UKF\)\s+and\s+" + NUM + r"\s+m\s+\(PF\)\s+against\s+" + NUM
               + r"\s+m\s+for\s+H-inf\s+only", "the drawn Maxwell-slip plants' figures")
    if m:
        c.figure(m, 1, int(rows["+ UKF"][2]), "mslip plants hinf_ukf faulted")
        c.figure(m, 2, int(rows["+ PF"][2]), "mslip plants hinf_pf faulted")
        c.figure(m, 3, float(rows["+ UKF"][4]), "mslip plants hinf_ukf median")
        c.figure(m, 4, float(rows["+ PF"][4]), "mslip plants hinf_pf median")
        c.figure(m, 5, float(rows["H-inf only"][4]), "mslip plants hinf_only median")


def check(text, summary, root, n_particles):
    c = Checks(text)
    check_demo_tables(c, summary, n_particles)
    check_realistic_prose(c, summary)
    check_iso_g(c, summary)
    check_robustness(c, root)
    check_fleet(c, root)
    check_mslip_plants(c, root)
    return c


def off_by_one(printed):
    """printed with its last digit changed by one (9 -> 8, else +1)"""
    mant, _, exp = printed.partition("e")
    d = mant[-1]
    mant = mant[:-1] + ("8" if d == "9" else str(int(d) + 1))
    return mant + ("e" + exp if exp else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--demo", required=True, help="the br_demo_circle binary (host-release)")
    ap.add_argument("--work", required=True)
    ap.add_argument("--root", default=ROOT)
    a = ap.parse_args()
    out = os.path.join(a.work, "demo")
    os.makedirs(out, exist_ok=True)
    subprocess.run([a.demo, "--out", out], check=True, stdout=subprocess.DEVNULL)
    subprocess.run([sys.executable, os.path.join(a.root, "sim", "plots", "iso230_4.py"), out],
                   check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "summary.json"), encoding="utf-8") as f:
        summary = json.load(f)
    with open(os.path.join(a.root, "machines", "reference.json"), encoding="utf-8") as f:
        n_particles = json.load(f)["estimator"]["pf"]["n_particles"]
    with open(os.path.join(a.root, "README.md"), encoding="utf-8") as f:
        text = f.read()

    c = check(text, summary, a.root, n_particles)
    print("%d README figures checked" % len(c.figures))
    if c.problems:
        print("README.md disagrees with its sources:\n  " + "\n  ".join(c.problems))
        return 1
    if len(c.figures) < 20:
        print("only %d figures found: the parser missed some" % len(c.figures))
        return 1
    # every checked figure, changed in its last digit, must fail the check
    missed = []
    spans = {}
    for span, printed, what in c.figures:
        spans.setdefault(span, (printed, what))
    for (s, e), (printed, what) in sorted(spans.items()):
        wrong = text[:s] + off_by_one(printed) + text[e:]
        if not check(wrong, summary, a.root, n_particles).problems:
            missed.append("%s (%s -> %s)" % (what, printed, off_by_one(printed)))
    if missed:
        print("a wrong README figure would pass:\n  " + "\n  ".join(missed))
        return 1
    print("each of them changed by one in its last digit fails the check")
    return 0


if __name__ == "__main__":
    sys.exit(main())
