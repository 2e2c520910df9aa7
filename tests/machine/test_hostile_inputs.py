#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Inputs that cannot inject (docs/tools.md, "Inputs that cannot inject"):
paths and fields given to the Makefile and to the header generators are data,
never shell, make or C text.

- every make target that takes a path or a value (firmware MACHINE=, tune MACHINE=, diagnose
  LOG= OUT= MACHINE=, validate MODEL= LOG=, emps EMPS_LOG=, demo RADIUS_M=
  FEED= DIR=, target-chain PLANT=) run as `make -n` with values that hold a double and a single
  quote, a backtick, $(...), make's $(shell ...), "*/" and a newline, each
  trying to create a marker file: no marker appears, and the value is never
  printed as recipe text; diagnose and validate also run for real (they fail
  on the missing files, nothing else); BOARD and the counts (N, ...) must be
  what they select; the Makefile has no $(shell ...);
- gen_machine.py and synth_hinf.py on a machine file in such a folder: the
  headers compile (-std=c99 -Wall -Wextra -Werror -pedantic) and
  BR_MACHINE_FILE reads back as the path, byte for byte;
- cmake/machine.cmake takes such a path, and refuses one with a newline (no
  Ninja rule can name it) or a ';' (a CMake list) with the reason;
- a hostile "name" is refused by the loader, the generators and build_dir.py
  with a line naming the field;
- two machine files with the same name get different build folders (one file
  spelt two ways the same one);
- a generation that fails while writing leaves the old header, and no
  temporary file.

Usage: test_hostile_inputs.py --work DIR [--cc CC]"""
import argparse
import glob
import json
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import DESIGN, REPO, check, result  # noqa: E402
import machine  # noqa: E402


def hostile(markers, tag):
    """Text that runs `touch MARKERS/<tag>-<how>` wherever a shell or make re-reads it."""
    m = markers + "/" + tag
    return ('q"d\'s`touch %s-bt`$(touch %s-cs)$(shell touch %s-mk)\';touch %s-sq;\'"*/c\n#error x'
            % (m, m, m, m))


def no_markers(markers, what):
    found = sorted(os.listdir(markers))
    check(not found, "%s: no command ran%s" % (what, "" if not found else " (made %s)" % found))
    for f in found:
        os.unlink(os.path.join(markers, f))


def make_env():
    env = dict(os.environ)
    for k in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL", "MAKEOVERRIDES", "MACHINE", "LOG", "OUT", "MODEL",
              "EMPS_LOG", "RADIUS_M", "FEED", "DIR", "PLANT", "BOARD", "V", "N"):
        env.pop(k, None)
    return env


def make(*args):
    return subprocess.run(["make", "-C", REPO, "--no-print-directory"] + list(args), capture_output=True, text=True,
                          env=make_env(), timeout=600)


def heavy_copy(folder, name=None):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(REPO, "machines", "heavy.json"), encoding="utf-8") as f:
        m = json.load(f)
    if name is not None:
        m["name"] = name
    path = os.path.join(folder, "m.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(m, f, indent=2)
    return path


def check_make(markers):
    # what each target takes (a hostile value for each, one marker tag per variable)
    cases = [("firmware", ["MACHINE"]), ("tune", ["MACHINE"]), ("diagnose", ["LOG", "OUT", "MACHINE"]), ("validate", ["MODEL", "LOG"]),
             ("emps", ["EMPS_LOG"]), ("demo", ["RADIUS_M", "FEED", "DIR"]), ("target-chain", ["PLANT"])]
    for target, names in cases:
        for extra in ([], ["BOARD=stm32g4"]) if target == "firmware" else ([],):
            vals = ["%s=%s" % (n, hostile(markers, n.lower())) for n in names]
            p = make("-n", target, *(vals + extra))
            what = "make -n %s %s" % (target, " ".join(names + extra))
            check(p.returncode == 0, "%s: exit 0%s" % (what, "" if p.returncode == 0 else " (%s)" % p.stderr[-400:]))
            check(markers not in p.stdout, "%s: the values are not recipe text" % what)
            no_markers(markers, what)
    # diagnose and validate for real: their tools refuse the missing files, nothing else runs
    for target, names in (("validate", ["MODEL", "LOG"]), ("diagnose", ["LOG", "OUT", "MACHINE"])):
        vals = ["%s=%s" % (n, hostile(markers, n.lower())) for n in names]
        p = make(target, *vals)
        check(p.returncode != 0 and "cannot open" in p.stderr and "Traceback" not in p.stderr,
              "make %s with missing hostile files: the tool gets the path and cannot open it (exit %d)"
              % (target, p.returncode))
        no_markers(markers, "make %s" % target)
    # make-level values: $(value ...) keeps $(shell ...) from running; BOARD and counts are checked
    p = make("-n", "help", "V=$(shell touch %s/v-mk)" % markers)
    no_markers(markers, "make -n help V=$(shell ...)")
    p = make("-n", "firmware", "BOARD=$(shell touch %s/board-mk)" % markers)
    check(p.returncode != 0 and "BOARD must be stm32h7 or stm32g4" in p.stderr, "make BOARD=<not a board>: refused")
    no_markers(markers, "make -n firmware BOARD=$(shell ...)")
    for var in ("N", "SEED", "JOBS", "DL_N", "DIAGNOSE_FIRST", "FUZZ_SECONDS", "MUTANTS_BUDGET"):
        p = make("-n", "robustness", "%s=1;touch %s/%s-sq $(shell touch %s/%s-mk)" % (var, markers, var, markers, var))
        check(p.returncode != 0 and ("%s must be a whole number" % var) in p.stderr,
              "make %s=<not a number>: refused" % var)
        no_markers(markers, "make -n robustness %s=..." % var)
    with open(os.path.join(REPO, "Makefile"), encoding="utf-8") as f:
        text = f.read()
    check("$(shell" not in text, "the Makefile has no $(shell ...)")
    used = [l for l in text.splitlines() if re.search(r"\$\((MACHINE|LOG|OUT|MODEL|EMPS_LOG|RADIUS_M|FEED|DIR)\)", l)
            and not re.match(r"(export BR_MK_\w+ +:= |ifeq )", l)]
    check(not used, "the Makefile expands the user paths only where it exports them%s" % ("" if not used else
                                                                                         " (also: %s)" % used))


def compile_headers(cc, gen_root, work, tag):
    """cc -std=c99 -Wall -Wextra -Werror -pedantic on every generated header, and
    BR_MACHINE_FILE printed by the compiled program."""
    headers = sorted(glob.glob(os.path.join(gen_root, "bristle_gen", "*", "*.h")))
    src = os.path.join(work, tag + ".c")
    with open(src, "w", encoding="utf-8") as f:
        f.write("#include <stdio.h>\n")
        for h in headers:
            f.write('#include "%s"\n' % os.path.relpath(h, gen_root))
        f.write("int main(void) { fputs(BR_MACHINE_FILE, stdout); return 0; }\n")
    exe = os.path.join(work, tag)
    p = subprocess.run([cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-I", gen_root, src, "-o", exe],
                       capture_output=True, text=True)
    check(p.returncode == 0, "%s: the %d generated headers compile%s" % (tag, len(headers), "" if p.returncode == 0
                                                                         else " (%s)" % p.stderr[-600:]))
    if p.returncode != 0:
        return None
    return subprocess.run([exe], capture_output=True).stdout


def check_generators(cc, work, markers):
    folder = os.path.join(work, "gen-path", hostile(markers, "path"), "evil*")
    try:
        path = heavy_copy(folder)
    except OSError:  # a file system without newlines (or quotes) in names
        folder = os.path.join(work, "gen-path", hostile(markers, "path").replace("\n", " "), "evil*")
        path = heavy_copy(folder)
    gen_root = os.path.join(work, "gen")
    shutil.rmtree(gen_root, ignore_errors=True)
    p = subprocess.run([sys.executable, os.path.join(DESIGN, "gen_machine.py"), "--machine", path, "--gen-root", gen_root,
                        "--tuned"], capture_output=True, text=True)
    check(p.returncode == 0, "gen_machine.py on a hostile path: exit 0 (%s)" % p.stderr[-300:])
    p = subprocess.run([sys.executable, os.path.join(DESIGN, "synth_hinf.py"), "--machine", path, "--out",
                        os.path.join(gen_root, "bristle_gen", "ctrl", "br_hinf_gains.h")], capture_output=True, text=True)
    check(p.returncode == 0, "synth_hinf.py on a hostile path: exit 0 (%s)" % p.stderr[-300:])
    no_markers(markers, "the generators on a hostile path")
    out = compile_headers(cc, gen_root, work, "hostile_headers")
    check(out == os.fsencode(machine.display_name(path)), "BR_MACHINE_FILE is the path, byte for byte")
    with open(os.path.join(gen_root, "bristle_gen", "machine", "br_machine.h"), encoding="utf-8") as f:
        text = f.read()
    m = re.search(r'#define BR_MACHINE_FILE_COMMENT "([^"\\]*)"', text)
    check(m is not None and re.fullmatch(r"[A-Za-z0-9 ._+,:=@%~/-]*", m.group(1)) is not None,
          "BR_MACHINE_FILE_COMMENT holds only comment-safe characters")
    for h in glob.glob(os.path.join(gen_root, "bristle_gen", "*", "*.h")):
        with open(h, encoding="utf-8") as f:
            first = f.readline()
        check(first.startswith("/* generated by") and "*/" not in first[2:-4] and "#error" not in first,
              "%s: the banner line neither ends early nor holds a directive" % os.path.basename(h))
    no_markers(markers, "compiling the headers")
    with open(os.path.join(REPO, "sim", "apps", "br_tune_est.c"), encoding="utf-8") as f:
        tune = f.read()
    check("BR_MACHINE_FILE_COMMENT" in tune and not re.search(r"BR_MACHINE_FILE\b(?!_)", tune),
          "br_tune_est writes the path into its banner only in the comment-safe form")
    # the build: cmake/machine.cmake takes a path with quotes and $(...), and refuses a newline with the reason
    ok_path = os.path.join(work, "cmake-path", hostile(markers, "cm").replace("\n", " ").replace(";", ","))
    for label, p, ok in (("quotes, backtick, $(...)", heavy_copy(ok_path), True),
                         ("a newline", heavy_copy(os.path.join(work, "cmake-nl", "a\nb")), False),
                         ("a ';'", heavy_copy(os.path.join(work, "cmake-sc", "a;b")), False)):
        r = subprocess.run(["cmake", "-DBR_MACHINE=" + p, "-P", os.path.join(REPO, "cmake", "machine.cmake")],
                           capture_output=True, text=True)
        if ok:
            check(r.returncode == 0, "cmake/machine.cmake takes a path with %s" % label)
        else:
            check(r.returncode != 0 and "holds a newline, a carriage return or a ';'" in " ".join(r.stderr.split()),
                  "cmake/machine.cmake refuses a path with %s, naming the reason" % label)
    no_markers(markers, "cmake/machine.cmake")


def check_names(work):
    for i, bad in enumerate(('a"b', "x*/y", "a\nb", "../up", "Upper", "", "a b", "a`b`", "$(x)")):
        path = heavy_copy(os.path.join(work, "names", "%d" % i), name=bad)
        try:
            machine.load(path)
            lines = []
        except machine.MachineError as e:
            lines = e.lines
        check(any(": field name: " in l for l in lines), "name %r: the loader refuses it (field name)" % bad)
        for script, args in (("gen_machine.py", ["--machine", path, "--gen-root", os.path.join(work, "names-gen")]),
                             ("synth_hinf.py", ["--machine", path, "--out", os.path.join(work, "names-gen", "g.h")]),
                             ("build_dir.py", ["cm7-release", path])):
            p = subprocess.run([sys.executable, os.path.join(DESIGN, script)] + args, capture_output=True, text=True)
            check(p.returncode == 1 and "field name" in p.stderr and "Traceback" not in p.stderr,
                  "name %r: %s refuses it naming the field" % (bad, script))
        check(not os.path.exists(os.path.join(work, "names-gen", "bristle_gen")) and
              not os.path.exists(os.path.join(work, "names-gen", "g.h")), "name %r: nothing generated" % bad)


def check_build_dirs(work, markers):
    try:
        import build_dir
    except ImportError:
        check(False, "firmware/design/build_dir.py exists")
        return
    a = heavy_copy(os.path.join(work, "same-name", "a"))
    b = heavy_copy(os.path.join(work, "same-name", hostile(markers, "bd").replace("\n", "n")))
    da, db = build_dir.build_dir("cm7-release", a), build_dir.build_dir("cm7-release", b)
    pat = r"build/cm7-release-heavy-[0-9a-f]{8}"
    check(re.fullmatch(pat, da) is not None and re.fullmatch(pat, db) is not None,
          "build folders are build/<preset>-<name>-<8 hex> (%s, %s)" % (da, db))
    check(da != db, "two files named \"heavy\" get different build folders")
    rel = os.path.relpath(a)
    check(build_dir.build_dir("cm7-release", rel) == da, "one file spelt two ways: one folder")
    check(build_dir.build_dir("cm4-release", a) != da, "the preset is in the folder")
    p = subprocess.run([sys.executable, os.path.join(DESIGN, "build_dir.py"), "cm7-release", b], capture_output=True,
                       text=True)
    check(p.returncode == 0 and p.stdout.strip() == db, "build_dir.py prints the folder")
    no_markers(markers, "build_dir.py on a hostile path")


def check_atomic(work):
    if not hasattr(machine, "write_atomic"):
        check(False, "machine.write_atomic exists")
        return
    path = os.path.join(work, "atomic", "br_x.h")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        f.write("/* old */\n")
    failed = False
    try:  # a lone surrogate cannot be encoded: the write fails half way
        machine.write_atomic(path, "/* new */\n" * 1000 + "\ud800")
    except UnicodeEncodeError:
        failed = True
    with open(path, encoding="utf-8") as f:
        kept = f.read()
    check(failed and kept == "/* old */\n", "a write that fails half way leaves the old header")
    check(os.listdir(os.path.dirname(path)) == ["br_x.h"], "and no temporary file")
    machine.write_atomic(path, "/* new */\n")
    with open(path, encoding="utf-8") as f:
        check(f.read() == "/* new */\n", "a write that succeeds replaces it")
    # each generator writes through write_atomic
    for script in ("gen_machine.py", "synth_hinf.py", "gen_noise.py"):
        with open(os.path.join(DESIGN, script), encoding="utf-8") as f:
            text = f.read()
        check("write_atomic(" in text and not re.search(r"open\([^)]*, \"w\"", text),
              "%s writes its headers only through machine.write_atomic" % script)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--work", required=True)
    ap.add_argument("--cc", default="cc")
    ap.add_argument("--no-make", action="store_true", help="skip the Makefile checks")
    a = ap.parse_args()
    work = os.path.abspath(a.work)
    shutil.rmtree(work, ignore_errors=True)
    markers = os.path.join(work, "markers")
    os.makedirs(markers)
    check_generators(a.cc, work, markers)
    check_names(work)
    check_build_dirs(work, markers)
    check_atomic(work)
    if not a.no_make:
        check_make(markers)
    return result()


if __name__ == "__main__":
    sys.exit(main())
