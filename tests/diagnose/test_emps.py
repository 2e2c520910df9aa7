# SPDX-License-Identifier: Apache-2.0
"""The real EMPS log (../shared/data/emps/emps_estimation.csv, never
committed): the diagnosis must name asymmetric friction, its extended
(LuGre-based) model must beat the nominal on the held-out part and the
published asymmetric model's 3.11 %, and the closed loop is re-simulated
with the EMPS controller. Fails (never skips) when the data is missing.

Usage: test_emps.py --log PATH --out DIR"""
import argparse
import json
import os
import re
import subprocess
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PAPER_SYMMETRIC, PAPER_ASYMMETRIC = 4.08, 3.11
DOC = os.path.join(REPO, "docs", "diagnose.md")
# The held-out relerr must be the one docs/diagnose.md publishes (its EMPS
# table, two decimals): half its last digit (0.005) for the rounding, and as
# much again for the fit's optimiser across BLAS builds (runs here agree to
# 1e-6). A change of the split (e.g. the training slice measured as held out:
# 2.58 %) or of the fit moves it by far more.
DOC_TOL = 0.01


def documented_held_out():
    """(t0, t1) of the EMPS held-out part in docs/diagnose.md."""
    text = open(DOC).read()
    m = re.search(r"Held-out part:\s+t = ([0-9.]+) … ([0-9.]+) s", text[text.index("### EMPS"):])
    if not m:
        raise SystemExit(f"FAIL: {DOC}: the EMPS held-out part (t = … s) is not found")
    return float(m.group(1)), float(m.group(2))


def documented_relerr():
    """(nominal, extended) held-out relerr of the EMPS table in docs/diagnose.md."""
    text = open(DOC).read()
    sec = text[text.index("### EMPS"):]
    nom = re.search(r"^\| nominal: [^|]*\| ([0-9.]+) % \|", sec, re.M)
    ext = re.search(r"^\| \*\*extended: [^|]*\*\* \| \*\*([0-9.]+) %\*\* \|", sec, re.M)
    if not nom or not ext:
        raise SystemExit(f"FAIL: {DOC}: the EMPS table's nominal / extended held-out rows are not found")
    return float(nom.group(1)), float(ext.group(1))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--log", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    if not os.path.isfile(a.log):
        print(f"FAIL: the EMPS log {a.log} is missing. It lives beside the repository in ../shared/data/emps/ "
              "(the public EMPS benchmark, DATA_EMPS.mat, converted; docs/diagnose.md says where to get it).",
              file=sys.stderr)
        return 1
    env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"), MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, "-m", "bristle.diagnose", "diagnose", "--log", a.log, "--out", a.out,
                        "--machine", os.path.join(REPO, "python", "bristle", "diagnose", "machines", "emps.json")], env=env)
    if r.returncode != 0:
        print("FAIL: the diagnosis failed", file=sys.stderr)
        return 1
    with open(os.path.join(a.out, "report.json")) as f:
        rep = json.load(f)
    nom, ext = rep["nominal"]["relerr_percent"], rep["extended"]["relerr_percent"]
    cl = rep["closed_loop"]
    pub = rep["published"]["closed_loop"]
    print(f"EMPS held-out relerr: nominal {nom:.3f} %, extended {ext:.3f} % "
          f"(published, whole run: {PAPER_SYMMETRIC} % symmetric + offset, {PAPER_ASYMMETRIC} % asymmetric)")
    for s in rep["published_structures_refitted"]:
        print(f"  published structure refitted here: {s['name']}: {s['relerr_percent']:.3f} %")
    for name in ("nominal", "extended"):
        c = cl[name]
        print(f"closed loop {name}: position {c['relerr_position_percent']:.4g} %, velocity "
              f"{c['relerr_velocity_percent']:.4g} %, force {c['relerr_force_percent']:.4g} %")
    print(f"closed loop published: position {pub['relerr_position_percent']} %, velocity "
          f"{pub['relerr_velocity_percent']} %, force {pub['relerr_force_percent']} %")
    fails = []
    doc_nom, doc_ext = documented_relerr()
    print(f"documented (docs/diagnose.md): nominal {doc_nom} %, extended {doc_ext} % (tolerance {DOC_TOL})")
    for name, got, want in (("nominal", nom, doc_nom), ("extended", ext, doc_ext)):
        if not abs(got - want) <= DOC_TOL:
            fails.append(f"{name} held-out relerr {got:.4f} % is not the documented {want} % (+-{DOC_TOL})")
    t0, t1 = documented_held_out()
    m = re.search(r"t = ([0-9.]+) \.\. ([0-9.]+) s", rep["method"]["held_out"])
    if not m or abs(float(m.group(1)) - t0) > 0.005 or abs(float(m.group(2)) - t1) > 0.005:
        fails.append(f"the report's held-out part {rep['method']['held_out']!r} is not the documented "
                     f"t = {t0} .. {t1} s")
    if rep["verdict"] != "asymmetric_friction":
        fails.append(f"verdict {rep['verdict']}, expected asymmetric_friction")
    if not ext < nom:
        fails.append(f"extended {ext} % is not below the nominal {nom} %")
    if not ext < PAPER_ASYMMETRIC:
        fails.append(f"extended {ext} % does not beat the published {PAPER_ASYMMETRIC} %")
    f0 = rep["findings"][0]["params"] if rep["findings"] else {}
    if f0 and not f0["Fv_neg_Nspm"] > 1.2 * f0["Fv_pos_Nspm"]:
        fails.append("the viscous friction is not larger in -x, as the paper found")
    if not cl["extended"]["relerr_force_percent"] < cl["nominal"]["relerr_force_percent"]:
        fails.append("the extended model does not re-simulate the force better than the nominal")
    for f in fails:
        print("FAIL: " + f, file=sys.stderr)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
