# SPDX-License-Identifier: Apache-2.0
"""The mutation check (docs/mutants.md): plants one defined bug at a time in a
scratch copy of the tree and asks whether the tests notice.

C: the mutants of tests/mutants/mutants_c.txt (the project's own operator
set, below), each applied alone to a copy of the tree under
<work>/w<k>/src, rebuilt in that copy's host-debug preset (ASan + UBSan:
a mutant that overruns an array is caught the way the suite would catch
it) and tested with the ctest subset its block names (--stop-on-failure).
The worktree itself is never written.

Python: cosmic-ray (pinned in cmake/python-requirements.txt) over the
diagnosis modules of tests/mutants/mutants_py.toml, in its own scratch
copy, with the diagnosis unit tests as its test command.

Outcome of a mutant: killed (a test failed, or ran past the timeout),
survived (every test passed), invalid (the C mutant does not compile:
reported, not counted). Writes <out>/summary.json ("total", "killed",
"survived", "survivors" [{file, line, mutation, ...}], ...) and
<out>/report.md.

Operators (C): sign (a sign or +/- flipped), off_by_one (an index, bound or
constant moved by one), swap (operands swapped), drop (a term or a
statement removed), invert (a condition inverted or a comparison turned),
loosen (a constant or tolerance made laxer).

Usage:
  mutate.py [--lang c,py] [--jobs 2] [--budget SECONDS] [--sample N --seed S]
            [--work build/mutants] [--out out/mutants]
"""
import argparse
import concurrent.futures as cf
import json
import os
import random
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
C_SET = os.path.join(HERE, "mutants_c.txt")
PY_SET = os.path.join(HERE, "mutants_py.toml")
OPERATORS = ("sign", "off_by_one", "swap", "drop", "invert", "loosen")


class SetError(Exception):
    pass


def parse_c_set(path):
    """Blocks `[file <path>]` + `tests = <names>`, then one mutant a line:
    `<operator>[@<occurrence>]  <original>  =>  <replacement>`; # comments."""
    mutants, cur_file, cur_tests = [], None, None
    with open(path) as f:
        for ln, raw in enumerate(f, 1):
            line = raw.rstrip("\n")
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            where = f"{os.path.relpath(path, REPO)}:{ln}"
            m = re.fullmatch(r"\[file\s+(\S+)\]", s)
            if m:
                cur_file, cur_tests = m.group(1), None
                if not os.path.isfile(os.path.join(REPO, cur_file)):
                    raise SetError(f"{where}: no file {cur_file}")
                continue
            m = re.fullmatch(r"tests\s*=\s*(.+)", s)
            if m:
                cur_tests = m.group(1).split()
                continue
            if cur_file is None or cur_tests is None:
                raise SetError(f"{where}: a mutant before its [file] block and tests line")
            accepted = None
            if "  # survives: " in s:
                s, accepted = s.split("  # survives: ", 1)
                s = s.rstrip()
            m = re.fullmatch(r"(\w+)(?:@(\d+))?\s+(.+?)\s+=>\s+(.*)", s)
            if not m:
                raise SetError(f"{where}: expected '<operator> <original> => <replacement>'")
            op, occ, orig, repl = m.group(1), int(m.group(2) or 1), m.group(3), m.group(4)
            if op not in OPERATORS:
                raise SetError(f"{where}: operator {op!r} is not one of {', '.join(OPERATORS)}")
            if repl == "''":
                repl = ""
            orig, repl = orig.replace("\\n", "\n"), repl.replace("\\n", "\n")
            text = open(os.path.join(REPO, cur_file)).read()
            pos, n = -1, 0
            for _ in range(occ):
                pos = text.find(orig, pos + 1)
                if pos < 0:
                    break
                n += 1
            if pos < 0:
                raise SetError(f"{where}: {orig!r} occurs {n} time(s) in {cur_file}, occurrence {occ} wanted")
            if occ == 1 and text.count(orig) != 1:
                raise SetError(f"{where}: {orig!r} occurs {text.count(orig)} times in {cur_file}; "
                               "name the occurrence (op@N)")
            line_no = text.count("\n", 0, pos) + 1
            mutants.append({"id": f"c{len(mutants):03d}", "lang": "c", "file": cur_file, "line": line_no,
                            "operator": op, "pos": pos, "original": orig, "replacement": repl,
                            "mutation": (f"{orig}  =>  {repl}" if repl else f"{orig}  =>  (dropped)").replace("\n", " "),
                            "tests": cur_tests, "set_line": ln, "accepted": accepted})
    return mutants


def tree_files():
    """The files of the tree as they are now (tracked and new, not ignored)."""
    out = subprocess.run(["git", "-C", REPO, "ls-files", "-co", "--exclude-standard", "-z"],
                         check=True, capture_output=True, text=True).stdout
    return [p for p in out.split("\0") if p and os.path.isfile(os.path.join(REPO, p))]


def make_copy(dst):
    """A scratch copy of the tree at dst (refreshed: only changed files are
    rewritten, so an earlier build there stays incremental)."""
    for rel in tree_files():
        s, d = os.path.join(REPO, rel), os.path.join(dst, rel)
        if os.path.islink(s):
            continue
        if os.path.isfile(d) and os.path.getsize(d) == os.path.getsize(s):
            with open(s, "rb") as a, open(d, "rb") as b:
                if a.read() == b.read():
                    continue
        os.makedirs(os.path.dirname(d), exist_ok=True)
        shutil.copy(s, d)  # a fresh mtime: the build must see a restored file as changed
    venv = os.path.join(dst, ".venv")
    if not os.path.lexists(venv):
        os.symlink(os.path.realpath(os.path.join(REPO, ".venv")), venv)
    shared = os.path.join(os.path.dirname(dst), "shared")
    if not os.path.lexists(shared) and os.path.isdir(os.path.join(REPO, "..", "shared")):
        os.symlink(os.path.realpath(os.path.join(REPO, "..", "shared")), shared)


def run(cmd, cwd, timeout, log):
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                           timeout=timeout, env=dict(os.environ, ASAN_OPTIONS="detect_leaks=0"))
        rc, out = r.returncode, r.stdout
    except subprocess.TimeoutExpired as e:
        rc, out = "timeout", (e.stdout or b"").decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
    with open(log, "a") as f:
        f.write(f"$ {' '.join(cmd)}  ({time.monotonic() - t0:.1f} s, rc {rc})\n{out[-4000:]}\n")
    return rc, out


class CWorker:
    """One scratch tree and its host-debug build."""

    def __init__(self, work, k):
        self.root = os.path.join(work, f"w{k}")
        self.src = os.path.join(self.root, "src")
        self.bld = os.path.join(self.src, "build", "host-debug")
        self.log = os.path.join(self.root, "log.txt")

    def prepare(self, targets):
        os.makedirs(self.src, exist_ok=True)
        open(self.log, "w").close()
        make_copy(self.src)
        # a run stopped during a mutant: its file is restored above, but may be
        # older than the object built from the mutant; touch it so it is rebuilt
        marker = os.path.join(self.root, "mutating")
        if os.path.exists(marker):
            with open(marker) as f:
                p = os.path.join(self.src, f.read().strip())
            if os.path.exists(p):
                os.utime(p)
            os.remove(marker)
        rc, out = run(["cmake", "--preset", "host-debug"], self.src, 900, self.log)
        if rc != 0:
            raise RuntimeError(f"configure of {self.src} failed:\n{out[-2000:]}")
        rc, out = run(["cmake", "--build", self.bld, "--target", *sorted(targets)], self.src, 3600, self.log)
        if rc != 0:
            raise RuntimeError(f"build of {self.src} failed:\n{out[-2000:]}")

    def ctest(self, tests, timeout):
        regex = "^(" + "|".join(re.escape(t) for t in tests) + ")$"
        return run(["ctest", "--test-dir", self.bld, "-R", regex, "--stop-on-failure", "--output-on-failure",
                    "--timeout", str(int(timeout))], self.src, timeout * len(tests) + 60, self.log)

    def baseline(self, tests):
        t0 = time.monotonic()
        rc, out = self.ctest(tests, 600)
        if rc != 0:
            raise RuntimeError(f"the unmutated tests fail in {self.src}:\n{out[-3000:]}")
        return time.monotonic() - t0

    def apply(self, m, timeout):
        path = os.path.join(self.src, m["file"])
        with open(path) as f:
            orig = f.read()
        assert orig[m["pos"]:m["pos"] + len(m["original"])] == m["original"]
        t0 = time.monotonic()
        marker = os.path.join(self.root, "mutating")
        with open(marker, "w") as f:
            f.write(m["file"])
        try:
            with open(path, "w") as f:
                f.write(orig[:m["pos"]] + m["replacement"] + orig[m["pos"] + len(m["original"]):])
            rc, out = run(["cmake", "--build", self.bld, "--target", *test_targets(m["tests"])], self.src, 900,
                          self.log)
            if rc != 0:
                err = [ln for ln in out.splitlines() if "error" in ln][:2]
                return {"outcome": "invalid", "detail": " / ".join(err)[:300], "seconds": time.monotonic() - t0}
            rc, out = self.ctest(m["tests"], timeout)
            failed = re.findall(r"\d+/\d+ Test\s+#\d+: (\S+) \.+\**\s*(Failed|Timeout|Exception|Subprocess)", out)
            if rc == 0:
                return {"outcome": "survived", "seconds": time.monotonic() - t0}
            how = "timeout" if rc == "timeout" or any(f[1] == "Timeout" for f in failed) else "failed"
            return {"outcome": "killed", "by": [f[0] for f in failed] or ["(ctest " + str(rc) + ")"], "how": how,
                    "seconds": time.monotonic() - t0}
        finally:
            with open(path, "w") as f:
                f.write(orig)
            os.remove(marker)


# ctest names whose executable has another name
# a ctest name -> the build target it runs; None: a script test that builds what it needs itself
# (machine_chain_emps builds its hosts from the scratch copy's source)
TEST_EXE = {"golden_reader_malformed": "test_golden_lugre", "machine_chain_emps": None}


def test_targets(tests):
    return sorted({TEST_EXE.get(t, t) for t in tests} - {None})


def run_c(mutants, a, deadline):
    results = {}
    if not mutants:
        return results
    targets = set(test_targets([t for m in mutants for t in m["tests"]]))
    tests = sorted({t for m in mutants for t in m["tests"]})
    workers = [CWorker(a.work, k) for k in range(a.jobs)]
    # the first copy builds while the second waits: two cold builds at once on 2 cores gain nothing
    for w in workers:
        print(f"mutants: preparing {w.src} (host-debug, {len(targets)} test executables)", flush=True)
        w.prepare(targets)
    base = workers[0].baseline(tests)
    timeout = max(60.0, 10.0 * base)
    print(f"mutants: C baseline {base:.1f} s for {len(tests)} tests; per-mutant test timeout {timeout:.0f} s",
          flush=True)
    free = list(workers)
    pending = list(mutants)
    with cf.ThreadPoolExecutor(len(workers)) as ex:
        futs = {}
        while pending or futs:
            while pending and free and time.monotonic() < deadline:
                m, w = pending.pop(0), free.pop()
                futs[ex.submit(w.apply, m, timeout)] = (m, w)
            if not futs:
                break
            done, _ = cf.wait(futs, return_when=cf.FIRST_COMPLETED)
            for f in done:
                m, w = futs.pop(f)
                free.append(w)
                results[m["id"]] = f.result()
                r = results[m["id"]]
                print(f"  {m['id']} {r['outcome']:8s} {m['file']}:{m['line']} {m['operator']}: {m['mutation']}"
                      + (f"  [{', '.join(r.get('by', []))}]" if r.get("by") else ""), flush=True)
    for m in pending:
        results[m["id"]] = {"outcome": "not_run"}
    return results


def run_py(a, deadline, sample):
    """cosmic-ray over each module group of mutants_py.toml, groups in
    parallel (one scratch copy each)."""
    import tomllib
    with open(PY_SET, "rb") as f:
        spec = tomllib.load(f)
    # --only: the groups with a module matching it (each keeps its index, so its scratch copy)
    groups = [(k, g) for k, g in enumerate(spec["group"])
              if not a.only or any(re.search(a.only, m) for m in g["modules"])]
    results = []

    def one(k, g):
        root = os.path.join(a.work, f"py{k}")
        src = os.path.join(root, "src")
        os.makedirs(src, exist_ok=True)
        make_copy(src)
        log = os.path.join(root, "log.txt")
        open(log, "w").close()
        py = os.path.join(REPO, ".venv", "bin", "python")
        cfg = os.path.join(root, "cr.toml")
        runner = os.path.join(root, "run_tests.sh")
        with open(runner, "w") as f:
            f.write("#!/bin/sh\n# the diagnosis unit tests in the scratch copy (cwd), the first failure ends the run\n"
                    "export PYTHONPATH=python MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1\n")
            for t in spec["tests"]:
                f.write(f"{py} {t} || exit 1\n")
        with open(cfg, "w") as f:
            f.write("[cosmic-ray]\n")
            f.write(f"module-path = {json.dumps(g['modules'])}\n")
            f.write(f"timeout = {float(spec.get('timeout', 60))}\n")
            f.write("excluded-modules = []\n")
            f.write(f"test-command = {json.dumps('sh ' + runner)}\n")
            f.write("[cosmic-ray.distributor]\nname = \"local\"\n")
        db = os.path.join(root, "session.sqlite")
        if os.path.exists(db):
            os.remove(db)
        bin_ = os.path.join(REPO, ".venv", "bin")
        rc, out = run([os.path.join(bin_, "cosmic-ray"), "init", cfg, db], src, 600, log)
        if rc != 0:
            raise RuntimeError(f"cosmic-ray init failed:\n{out[-2000:]}")
        excluded = skip_excluded(db, spec.get("exclude", []), src)
        skip_outside_sample(db, g, sample, a.seed, excluded)
        rc, out = run([os.path.join(bin_, "cosmic-ray"), "exec", cfg, db], src,
                      max(60, deadline - time.monotonic() + 600), log)
        rc, out = run([os.path.join(bin_, "cosmic-ray"), "dump", db], src, 600, log)
        if rc != 0:
            raise RuntimeError(f"cosmic-ray dump failed:\n{out[-2000:]}")
        rows = []
        for ln in out.splitlines():
            ln = ln.strip()
            if not ln.startswith("["):
                continue
            item, res = json.loads(ln)
            for mut in item["mutations"]:
                rel = os.path.relpath(os.path.join(src, mut["module_path"]), src)
                line = mut["start_pos"][0]
                text = _line(os.path.join(src, rel), line)
                if res is None:
                    outcome = "not_run"
                elif res["worker_outcome"] == "skipped":
                    outcome = "excluded" if res.get("output") == "excluded" else "not_sampled"
                elif res["worker_outcome"] != "normal":
                    outcome = "killed" if res["worker_outcome"] == "exception" else "invalid"
                else:
                    outcome = "killed" if res["test_outcome"] == "killed" else (
                        "survived" if res["test_outcome"] == "survived" else "invalid")
                rows.append({"id": f"py{k}-{item['job_id'][:8]}", "lang": "py", "file": rel, "line": line,
                             "operator": f"{mut['operator_name'].split('/')[-1]}#{mut['occurrence']}",
                             "mutation": f"{mut['operator_name'].split('/')[-1]} occurrence {mut['occurrence']} "
                                         f"at col {mut['start_pos'][1]}: {text.strip()}",
                             "outcome": outcome, "by": ["diagnosis unit tests"] if outcome == "killed" else []})
                break  # one mutation per work item
        return rows

    with cf.ThreadPoolExecutor(max(1, min(a.jobs, len(groups)))) as ex:
        for rows in ex.map(lambda kg: one(*kg), groups):
            results.extend(rows)
    return results


def _line(path, n):
    with open(path) as f:
        for i, ln in enumerate(f, 1):
            if i == n:
                return ln
    return ""


def function_ranges(path, names):
    """Line ranges (first, last) of the functions named `Class.method` or
    `function`, and of the module-level assignments named, in a module."""
    import ast
    tree = ast.parse(open(path).read())
    out = []

    def walk(node, prefix):
        for ch in ast.iter_child_nodes(node):
            if isinstance(ch, ast.Assign) and prefix == "":
                for tg in ch.targets:
                    if isinstance(tg, ast.Name) and tg.id in names:
                        out.append((ch.lineno, ch.end_lineno))
            if isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                q = prefix + ch.name
                if q in names and not isinstance(ch, ast.ClassDef):
                    out.append((ch.lineno, ch.end_lineno))
                walk(ch, q + ".")
    walk(tree, "")
    return out


def skip_excluded(db, excludes, src):
    """Work items inside the excluded functions of mutants_py.toml are
    marked skipped (not counted); returns their job ids."""
    from cosmic_ray.work_db import use_db, WorkDB
    from cosmic_ray.work_item import WorkResult, WorkerOutcome
    skipped = set()
    with use_db(db, WorkDB.Mode.open) as wdb:
        items = list(wdb.work_items)
        for ex in excludes:
            ranges = function_ranges(os.path.join(src, ex["module"]), ex["functions"])
            if len(ranges) != len(ex["functions"]):
                raise RuntimeError(f"mutants_py.toml: not every function of {ex['functions']} is in {ex['module']}")
            for w in items:
                for m in w.mutations:
                    if os.path.normpath(str(m.module_path)).endswith(os.path.normpath(ex["module"])) and any(
                            lo <= m.start_pos[0] <= hi for lo, hi in ranges):
                        skipped.add(w.job_id)
        for j in skipped:
            wdb.set_result(j, WorkResult(worker_outcome=WorkerOutcome.SKIPPED, output="excluded"))
    return skipped


def skip_outside_sample(db, group, sample, seed, excluded):
    """A sample (CI): every work item but a seeded choice of `sample` is
    marked skipped before exec (cosmic-ray's own result type)."""
    if sample is None:
        return
    from cosmic_ray.work_db import use_db, WorkDB
    from cosmic_ray.work_item import WorkResult, WorkerOutcome
    with use_db(db, WorkDB.Mode.open) as wdb:
        # ordered by what the mutant is (job ids are random): the same seed, the same sample
        key = {w.job_id: [(str(m.module_path), tuple(m.start_pos), m.operator_name, m.occurrence)
                          for m in w.mutations] for w in wdb.work_items if w.job_id not in excluded}
        jobs = sorted(key, key=lambda j: key[j])
        keep = set(random.Random(seed).sample(jobs, min(sample, len(jobs))))
        for j in jobs:
            if j not in keep:
                wdb.set_result(j, WorkResult(worker_outcome=WorkerOutcome.SKIPPED))


def write_outputs(a, c_mutants, c_results, py_rows, elapsed, sample):
    rows = []
    for m in c_mutants:
        r = c_results.get(m["id"], {"outcome": "not_run"})
        rows.append({k: m[k] for k in ("id", "lang", "file", "line", "operator", "mutation", "accepted")} | r)
    rows += py_rows
    counted = [r for r in rows if r["outcome"] in ("killed", "survived")]
    killed = sum(r["outcome"] == "killed" for r in counted)
    surv = [r for r in counted if r["outcome"] == "survived"]

    def part(lang):
        c = [r for r in counted if r["lang"] == lang]
        k = sum(r["outcome"] == "killed" for r in c)
        return {"total": len(c), "killed": k, "survived": len(c) - k,
                "score": (k / len(c)) if c else None,
                "invalid": sum(r["lang"] == lang and r["outcome"] == "invalid" for r in rows),
                "not_run": sum(r["lang"] == lang and r["outcome"] == "not_run" for r in rows)}

    summary = {"command": " ".join(["tests/mutants/mutate.py"] + sys.argv[1:]),
               "sample": sample, "seed": a.seed if sample is not None else None,
               "total": len(counted), "killed": killed, "survived": len(surv),
               "score": killed / len(counted) if counted else None,
               "invalid": sum(r["outcome"] == "invalid" for r in rows),
               "not_run": sum(r["outcome"] == "not_run" for r in rows),
               "excluded": sum(r["outcome"] == "excluded" for r in rows),
               "by_language": {"c": part("c"), "py": part("py")},
               "elapsed_s": round(elapsed, 1),
               "survivors": [{"file": r["file"], "line": r["line"], "operator": r["operator"],
                              "mutation": r["mutation"], "accepted": r.get("accepted")} for r in surv],
               "new_survivors": sum(1 for r in surv if r["lang"] == "c" and not r.get("accepted")),
               "mutants": [{k: v for k, v in r.items() if k != "pos"} for r in rows
                           if r["outcome"] not in ("not_sampled", "excluded")]}
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
        f.write("\n")
    lines = ["# Mutation check", "", f"Command: `{summary['command']}` ({elapsed:.0f} s)", ""]
    sc = summary["score"]
    lines.append(f"**{killed} of {len(counted)} killed** ({100 * sc:.1f} %)" if counted else "nothing ran")
    lines += ["", "| set | total | killed | survived | score | invalid (not counted) | not run |",
              "|---|---|---|---|---|---|---|"]
    for lang in ("c", "py"):
        p = summary["by_language"][lang]
        if p["total"] or p["invalid"] or p["not_run"]:
            s = f"{100 * p['score']:.1f} %" if p["score"] is not None else "—"
            lines.append(f"| {lang} | {p['total']} | {p['killed']} | {p['survived']} | {s} | {p['invalid']} | "
                         f"{p['not_run']} |")
    lines += ["", "## Survivors", ""]
    lines += [f"- `{r['file']}:{r['line']}` {r['operator']}: `{r['mutation']}`"
              + (f" — accepted: {r['accepted']}" if r.get("accepted") else "") for r in surv] or ["none"]
    lines += ["", "## Every mutant", "", "| id | outcome | where | operator | mutation | caught by |",
              "|---|---|---|---|---|---|"]
    for r in rows:
        if r["outcome"] in ("not_sampled", "excluded"):
            continue
        mut = r["mutation"].replace("|", "\\|")
        lines.append(f"| {r['id']} | {r['outcome']} | {r['file']}:{r['line']} | {r['operator']} | `{mut}` | "
                     f"{', '.join(r.get('by', []))} |")
    with open(os.path.join(a.out, "report.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    return summary


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lang", default="c,py")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--budget", type=float, default=3600.0, help="seconds; mutants not started by then are not run")
    ap.add_argument("--sample", type=int, help="a seeded sample of N mutants per language")
    ap.add_argument("--seed", type=int, default=17)
    ap.add_argument("--work", default=os.path.join(REPO, "build", "mutants"))
    ap.add_argument("--out", default=os.path.join(REPO, "out", "mutants"))
    ap.add_argument("--only", help="C mutants whose id or file matches this regex, and the Python groups "
                                   "with a module matching it")
    ap.add_argument("--check", action="store_true", help="parse the sets and exit")
    ap.add_argument("--min-score", type=float, help="exit 1 when the score is below this fraction")
    ap.add_argument("--no-new-survivors", action="store_true",
                    help="exit 1 when a C mutant survives that mutants_c.txt does not mark '# survives: <reason>'")
    a = ap.parse_args()
    a.work, a.out = os.path.abspath(a.work), os.path.abspath(a.out)
    langs = set(a.lang.split(","))
    t0 = time.monotonic()
    deadline = t0 + a.budget
    try:
        c_mutants = parse_c_set(C_SET) if "c" in langs else []
    except SetError as e:
        print(f"mutants: {e}", file=sys.stderr)
        return 2
    if a.only:
        c_mutants = [m for m in c_mutants if re.search(a.only, m["id"] + " " + m["file"])]
    if a.check:
        print(f"mutants: {len(c_mutants)} C mutants parse and apply")
        return 0
    if a.sample is not None:
        keep = sorted(random.Random(a.seed).sample(range(len(c_mutants)), min(a.sample, len(c_mutants))))
        c_mutants = [c_mutants[i] for i in keep]
    os.makedirs(a.work, exist_ok=True)
    py_rows = []
    with cf.ThreadPoolExecutor(2) as ex:
        fc = ex.submit(run_c, c_mutants, a, deadline) if c_mutants else None
        # the Python run shares the 2 cores with the C one: it starts when C is done unless alone
        c_results = fc.result() if fc else {}
        if "py" in langs:
            py_rows = run_py(a, deadline, a.sample)
    s = write_outputs(a, c_mutants, c_results, py_rows, time.monotonic() - t0, a.sample)
    print(f"mutants: {s['killed']} of {s['total']} killed"
          + (f" ({100 * s['score']:.1f} %)" if s["total"] else "")
          + f", {s['survived']} survived, {s['invalid']} invalid, {s['not_run']} not run "
            f"-> {os.path.relpath(a.out, REPO)}/summary.json, report.md")
    for r in s["survivors"]:
        print(f"  survivor {r['file']}:{r['line']} {r['operator']}: {r['mutation']}")
    if s["not_run"]:
        print(f"mutants: the time budget ({a.budget:.0f} s) ran out: {s['not_run']} not run", file=sys.stderr)
    if a.min_score is not None and (not s["total"] or s["score"] < a.min_score):
        return 1
    if a.no_new_survivors and s["new_survivors"]:
        print(f"mutants: {s['new_survivors']} C mutant(s) survived that the set does not accept", file=sys.stderr)
        return 1
    if s["not_run"] and a.sample is not None:
        return 1  # a CI sample must run whole
    return 0


if __name__ == "__main__":
    sys.exit(main())
