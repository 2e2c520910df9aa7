# SPDX-License-Identifier: Apache-2.0
"""docs/architecture.md's worked example, "Adding a cause", checked: in a
scratch copy of the tracked files that the steps touch, add a toy force-term
cause by the documented steps 1-3 (a cause module and its registry line, then
regenerate the causes' C tables and the machine header), and check

  - that the registry carried it everywhere it should without another edit:
    the machine file's schema, the detection-limits study, the C tables
    (BR_CAUSE_FIELDS, as a force term that switches the extended model on,
    br_causes_t's field; BR_CAUSE_PARAMS, its parameter row and option),
    BR_MACHINE_CAUSES;
  - that the firmware's model and feedforward and a machine configuration
    compile against it (-fsyntax-only with the firmware's warnings);
  - that the simulator's cause options take it: a probe built with the
    plant and br_cause_args (the host's warnings) sets the toy's field by
    its option, lays it over a plant (br_causes_apply), sees it switch the
    plant's causes on, and prints it in the usage text (br_cause_usage);
  - that every file it touched is one the docs' table names, and that it
    touched no more files by hand, nor regenerated more, than the docs state.

The physics steps (4-7: plant, kernel term, golden reference, tests and
docs) are code, not rows, and are not made here.

Usage: test_add_cause.py [--cc CC] [--keep DIR]"""
import argparse
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ARCH = os.path.join(REPO, "docs", "architecture.md")
# what the scratch copy holds: the tracked files below these
COPY = ("python", "firmware", "machines", "sim/lib/plant", "sim/lib/cause_args", "sim/studies")
CAUSE = "toy_load"
FIELD = "toy_N"
FIRMWARE_WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-Wdouble-promotion", "-Wconversion",
                     "-Wsign-conversion", "-Wshadow", "-Wstrict-prototypes", "-Wmissing-prototypes", "-Wundef",
                     "-Wvla", "-Wcast-qual"]
HOST_WARNINGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-Wshadow", "-Wvla"]

# the toy's module: offset.py's, renamed (a constant force, a cause of the same kind)
TOY_FROM = "python/bristle/diagnose/causes/offset.py"
TOY_RENAME = (('"--offset"', '"--toy"'), ("offset_N", FIELD), ('"offset"', '"%s"' % CAUSE))


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def documented():
    """From the docs' worked example: the files of the force-term table (by
    hand, generated) and the stated counts."""
    with open(ARCH, encoding="utf-8") as f:
        text = f.read()
    sec = text[text.index("### What a force term touches"):]
    sec = sec[:sec.index("\n## ")]
    hand, gen = set(), set()
    for line in sec.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 3 or not re.fullmatch(r"\d+|gen", cells[0]):
            continue
        files = {p.replace("<cause>", CAUSE) for p in re.findall(r"`([\w./<>-]+\.\w+)`", cells[1])}
        (gen if cells[0] == "gen" else hand).update(files)
    m = re.search(r"\*\*(\d+) files by hand and (\d+) regenerated\*\*", sec)
    if not m:
        fail("docs/architecture.md states no '**N files by hand and M regenerated**'")
    n_hand, n_gen = int(m.group(1)), int(m.group(2))
    if len(hand) != n_hand or len(gen) != n_gen:
        fail("docs/architecture.md's table names %d files by hand and %d generated, its sentence says %d and %d"
             % (len(hand), len(gen), n_hand, n_gen))
    return hand, gen, n_hand, n_gen


def copy_tracked(dst):
    files = subprocess.run(["git", "-C", REPO, "ls-files", "-z", "--", *COPY], check=True,
                           capture_output=True).stdout.decode().split("\0")
    for rel in filter(None, files):
        src = os.path.join(REPO, rel)
        if os.path.isfile(src):
            os.makedirs(os.path.dirname(os.path.join(dst, rel)), exist_ok=True)
            shutil.copy2(src, os.path.join(dst, rel))


def digest(root):
    out = {}
    for d, _, files in os.walk(root):
        if "__pycache__" in d:
            continue
        for f in files:
            p = os.path.join(d, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = hashlib.sha256(fh.read()).hexdigest()
    return out


def edit(root, rel, old, new):
    p = os.path.join(root, rel)
    with open(p, encoding="utf-8") as f:
        s = f.read()
    if s.count(old) != 1:
        fail("%s: the step's anchor %r is not there once" % (rel, old))
    with open(p, "w", encoding="utf-8") as f:
        f.write(s.replace(old, new))


def add_cause(root):
    """Steps 1 and 2 of the worked example (step 3 regenerates); returns the files written by hand."""
    rel = "python/bristle/diagnose/causes/%s.py" % CAUSE
    with open(os.path.join(root, TOY_FROM), encoding="utf-8") as f:
        text = f.read()
    for a, b in TOY_RENAME:
        text = text.replace(a, b)
    with open(os.path.join(root, rel), "w", encoding="utf-8") as f:
        f.write(text)
    init = "python/bristle/diagnose/causes/__init__.py"
    edit(root, init, "presliding_hysteresis)\n", "presliding_hysteresis, %s)\n" % CAUSE)
    edit(root, init, "    friction_drift,\n", "    friction_drift,\n    %s,\n" % CAUSE)
    return {rel, init}


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if r.returncode != 0:
        fail("%s exited %d:\n%s%s" % (" ".join(cmd), r.returncode, r.stdout, r.stderr))
    return r.stdout


CHECK = r'''
import sys
sys.path.insert(0, "firmware/design"); sys.path.insert(0, "sim/studies"); sys.path.insert(0, "python")
import machine, detection_limits, robustness
from bristle.diagnose import causes
assert causes.NAMES.index("toy_load") == causes.NAMES.index("friction_drift") + 1, causes.NAMES
assert "toy_load" in machine.SCHEMA["causes"], "schema"
assert "toy_N" in machine.SCHEMA["causes"]["toy_load"].section, "schema field"
assert "toy_load" in machine.FORCE_CAUSES, "force causes"
assert detection_limits.GENERATORS["toy_load"][3](0.5) == ["--toy", "0.5"], "detection limits"
assert "toy_load" in robustness.CAUSES, "robustness"
print("registry ok")
'''

MACHINE_C = '''#include "bristle/br_model.h"
#include "bristle_gen/machine/br_machine.h"
float br_toy_probe(void);
float br_toy_probe(void)
{
    static const br_causes_t c = BR_MACHINE_CAUSES;
    return c.toy_N;
}
'''

# the simulator's side: the toy's option, its application over a plant, its usage line
OPTIONS_C = '''#include <stdio.h>

#include "cause_args/br_cause_args.h"

int main(void)
{
    br_plant_cfg_t opt = br_plant_cfg_reference(), plant = br_plant_cfg_reference();
    if (opt.toy_N != 0.0 || br_plant_causes_on(&opt)) return 1;      /* the reference has it off */
    if (br_cause_arg("--toy", "0.5", &opt) != 1 || opt.toy_N != 0.5) return 2;
    if (br_cause_arg("--toy", "2e5", &opt) != -1 || opt.toy_N != 0.5) return 3; /* its bounds */
    br_causes_apply(&plant, &opt);
    if (plant.toy_N != 0.5 || !br_plant_causes_on(&plant)) return 4;
    br_cause_usage(stdout, "");
    return 0;
}
'''
SIM_SOURCES = ("sim/lib/cause_args/br_cause_args.c", "sim/lib/plant/br_sim_plant.c", "sim/lib/plant/br_gms.c")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cc", default=os.environ.get("CC", "cc"))
    ap.add_argument("--keep", help="work in this folder (kept) instead of a temporary one")
    a = ap.parse_args()
    hand_doc, gen_doc, n_hand, n_gen = documented()
    root = a.keep or tempfile.mkdtemp(prefix="br_add_cause_")
    try:
        if a.keep:
            shutil.rmtree(root, ignore_errors=True)
        copy_tracked(root)
        before = digest(root)
        hand = add_cause(root)
        # regenerate: the causes' table and the machine header (the reference machine)
        py = sys.executable
        run([py, "firmware/design/gen_causes.py"], cwd=root)
        run([py, "firmware/design/gen_machine.py"], cwd=root)
        print(run([py, "-c", CHECK], cwd=root).strip())
        table = open(os.path.join(root, "firmware/gen/bristle_gen/model/br_causes.h")).read()
        if "X(%s, %s, BR_CAUSE_FORCE, 1)" % (FIELD, CAUSE) not in table:
            fail("br_causes.h has no force row for %s" % FIELD)
        if 'X("%s", %s, "N", -1e5, 1e5, "%s", "--toy", 1)' % (FIELD, FIELD, CAUSE) not in table:
            fail("br_causes.h has no BR_CAUSE_PARAMS row for %s" % FIELD)
        # the firmware compiles against it: the model, the feedforward, a machine's causes
        with open(os.path.join(root, "probe.c"), "w") as f:
            f.write(MACHINE_C)
        inc = ["-Ifirmware/include", "-Ifirmware/private", "-Ifirmware/gen"]
        for src in ("firmware/model/br_model.c", "firmware/ff/br_ff.c", "probe.c"):
            run([a.cc, *FIRMWARE_WARNINGS, *inc, "-fsyntax-only", src], cwd=root)
        os.remove(os.path.join(root, "probe.c"))
        print("compiled: br_model.c, br_ff.c, BR_MACHINE_CAUSES")
        with open(os.path.join(root, "options.c"), "w") as f:
            f.write(OPTIONS_C)
        exe = os.path.join(root, "options_probe")
        run([a.cc, *HOST_WARNINGS, "-Isim/lib", "-Isim/lib/plant", "-Ifirmware/include", "-Ifirmware/gen",
             "-o", exe, "options.c", *SIM_SOURCES, "-lm"], cwd=root)
        usage = run([exe], cwd=root)
        if not re.search(r"^ +--toy %s +%s$" % (FIELD, CAUSE), usage, re.M):
            fail("the cause options' usage text has no line for --toy:\n" + usage)
        os.remove(os.path.join(root, "options.c"))
        os.remove(exe)
        print("cause options: --toy sets %s, br_causes_apply lays it over a plant, the usage lists it" % FIELD)
        after = digest(root)
        touched = {p for p in after if before.get(p) != after[p]} | {p for p in before if p not in after}
        regenerated = touched - hand
        print("by hand (%d): %s" % (len(hand), ", ".join(sorted(hand))))
        print("regenerated (%d): %s" % (len(regenerated), ", ".join(sorted(regenerated))))
        stray = (hand - hand_doc) | (regenerated - gen_doc)
        if stray:
            fail("touched files the docs' table does not name: %s" % ", ".join(sorted(stray)))
        if len(hand) > n_hand or len(regenerated) > n_gen:
            fail("touched %d by hand and %d regenerated, the docs state %d and %d"
                 % (len(hand), len(regenerated), n_hand, n_gen))
        print("ok: %d of the docs' %d files by hand, %d of %d regenerated (steps 1-3)"
              % (len(hand), n_hand, len(regenerated), n_gen))
    finally:
        if not a.keep:
            shutil.rmtree(root, ignore_errors=True)


if __name__ == "__main__":
    main()
