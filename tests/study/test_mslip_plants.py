# SPDX-License-Identifier: Apache-2.0
"""The drawn Maxwell-slip plants study (docs/presliding-plants.md), small:
3 plants (166-168 of seed 1: the PF without its shared external force, --pf-load 0, stops on 167)
on 2 processes and again on 1. Checks that the summary is the same
for any split, that every count is the per-plant runs' own, that a faulted
run is listed with its time and cause and has no figure, and that the page
writer exits 1 on a fault it was not told to expect (docs/tools.md).

Usage: test_mslip_plants.py --bin BUILD/sim --work DIR"""
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import work_args  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
STUDY = os.path.join(ROOT, "sim", "studies", "mslip_plants.py")
N = 3
# plants FIRST .. FIRST + N - 1: the PF stops on plant STOP of seed 1 (docs/presliding-plants.md's table; 103
# ran to the end since the PF's delay identification has its steady phase)
STOP = 167
FIRST = STOP - 1


def study(a, out, jobs, *extra):
    # the PF without its shared external force (the machine file's since 2026-11-28), which stops on STOP
    return subprocess.run([sys.executable, STUDY, "--bin", a.bin, "--out", out, "--n", str(N), "--first", str(FIRST),
                           "--jobs", str(jobs), "--pf-load", "0"]
                          + list(extra), capture_output=True, text=True)


def main():
    a = work_args.parse("bin")
    fails = []

    def check(cond, what):
        if not cond:
            fails.append(what)

    page = os.path.join(a.work, "page.md")
    with open(page, "w", encoding="utf-8") as f:
        f.write("# hand-written head\n\nkept\n")
    r2 = study(a, os.path.join(a.work, "j2"), 2, "--md", page, "--command", "test")
    r1 = study(a, os.path.join(a.work, "j1"), 1)
    check(r1.returncode == 0, "without --md the study exits 0: %s" % r1.stderr)
    s1 = json.load(open(os.path.join(a.work, "j1", "summary.json")))
    s2 = json.load(open(os.path.join(a.work, "j2", "summary.json")))
    check(s1 == s2, "the summary depends on --jobs")
    plants = [json.load(open(os.path.join(a.work, "j1", "plants", "plant_%04d.json" % j)))["plants"][0]
              for j in range(FIRST, FIRST + N)]
    check([p["plant"] for p in plants] == list(range(FIRST, FIRST + N)), "plant indices")
    n_faults = 0
    text = open(page, encoding="utf-8").read()
    check(text.startswith("# hand-written head\n\nkept\n"), "the page's hand-written head was not kept")
    for c, v in s1["controllers"].items():
        runs = [p["runs"][c] for p in plants]
        faulted = [(p["plant"], p["runs"][c]) for p in plants if p["runs"][c]["faulted"]]
        n_faults += len(faulted)
        check(v["faulted"] == len(faulted) and v["ran"] == N - len(faulted), "%s: counts" % c)
        for j, run_ in faulted:
            check(run_["contour_rms_m"] is None, "%s plant %d: a faulted run has a figure" % (c, j))
            check("%d: %.3f s (%s)" % (j, run_["fault_t_s"], run_["fault_cause"]) in text,
                  "%s plant %d: the fault is not listed with time and cause" % (c, j))
        ok = sorted(x["contour_rms_m"] for x in runs if not x["faulted"])
        if ok:
            check(abs(v["max_m"] - ok[-1]) <= 1e-15, "%s: max" % c)
    check(n_faults > 0, "plants %d-%d of seed 1 are expected to hold a stop (docs/presliding-plants.md)"
          % (FIRST, FIRST + N - 1))
    check(r2.returncode == (1 if n_faults else 0), "a fault not expected must fail the page writer: rc %d"
          % r2.returncode)
    # --first outside its range: refused before any plant runs
    r4 = subprocess.run([sys.executable, STUDY, "--bin", a.bin, "--out", os.path.join(a.work, "j4"), "--n", "1",
                         "--first", "-1"], capture_output=True, text=True)
    check(r4.returncode == 2 and "--first" in r4.stderr and not os.path.exists(os.path.join(a.work, "j4")),
          "--first -1: refused (exit 2) with nothing written: rc %d %s" % (r4.returncode, r4.stderr))
    # --pf-load outside br_mslip_plants's bound (0 .. 1e9, nan included): refused before any plant runs
    for bad in ("-1", "2e9", "nan"):
        r5 = subprocess.run([sys.executable, STUDY, "--bin", a.bin, "--out", os.path.join(a.work, "j5"), "--n", "1",
                             "--pf-load", bad], capture_output=True, text=True)
        check(r5.returncode == 2 and "--pf-load" in r5.stderr and not os.path.exists(os.path.join(a.work, "j5")),
              "--pf-load %s: refused (exit 2) with nothing written: rc %d %s" % (bad, r5.returncode, r5.stderr))
    # --pf-load reaches the PF and only the PF: plant STOP with the PF's shared external force
    r6 = subprocess.run([sys.executable, STUDY, "--bin", a.bin, "--out", os.path.join(a.work, "j6"), "--n", "1",
                         "--first", str(STOP), "--jobs", "1", "--pf-load", "1e4"], capture_output=True, text=True)
    check(r6.returncode == 0, "--pf-load 1e4: %s" % r6.stderr)
    if r6.returncode == 0:
        p6 = json.load(open(os.path.join(a.work, "j6", "plants", "plant_%04d.json" % STOP)))["plants"][0]
        p0 = plants[STOP - FIRST]
        check(all(p6["runs"][c] == p0["runs"][c] for c in p0["runs"] if c != "hinf_pf"),
              "--pf-load changed a run other than the PF's")
        check(p6["runs"]["hinf_pf"] != p0["runs"]["hinf_pf"], "--pf-load did not reach the PF's run")
    r3 = study(a, os.path.join(a.work, "j3"), 2, "--md", page, "--command", "test", "--expect-faults")
    check(r3.returncode == 0, "--expect-faults: %s" % r3.stderr)
    for f in fails:
        print("FAIL:", f)
    print("%d checks failed" % len(fails) if fails else "ok")
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
