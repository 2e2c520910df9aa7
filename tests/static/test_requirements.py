# SPDX-License-Identifier: Apache-2.0
"""The Python supply chain (label `static`, docs/regenerate.md, "Python pins"):
- every line of cmake/python-requirements.txt and
  sim/bench/requirements-particles.txt is `name==version` with at least one
  `--hash=sha256:<64 hex>` (what pip's --require-hashes needs);
- the pins are a closed set: each pinned distribution, as installed in the
  running interpreter's environment (.venv), at its pinned version, requires
  (Requires-Dist, markers evaluated for this Python, extras followed) only
  pinned names at versions its specifiers accept; so do pyproject.toml's
  dependencies and extras. A file installed with --no-deps
  (requirements-particles.txt: particles declares numpy < 2, docs/bench.md)
  needs its dependencies pinned, not its version ranges, but for
  NOT_INSTALLED: names that no module the project imports needs (checked:
  importing what sim/bench/pf_particles.py imports loads none of them);
- no file of the repository but cmake/setup-deps.sh runs pip's install
  command, unless with --no-index (nothing fetched): no make target, script
  or test installs from the index at run time.
Each check is also run on made-up input that it must reject.

Usage: test_requirements.py [--root DIR]"""
import argparse
import os
import re
import subprocess
import sys
import tomllib
import unittest
from importlib import metadata

from packaging.requirements import Requirement

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
MAIN = "cmake/python-requirements.txt"
NODEPS = "sim/bench/requirements-particles.txt"
INSTALLER = "cmake/setup-deps.sh"
LINE = re.compile(r"([A-Za-z0-9][A-Za-z0-9_.\-]*)==(\S+)((?:\s+--hash=sha256:[0-9a-f]{64})+)")
PIP_INSTALL = re.compile(r"\bpip[0-9.]*[\"',\s]+install\b")
SCRIPT_EXT = (".sh", ".py", ".cmake", ".mk", ".in")
# declared by a --no-deps pin, deliberately not installed: {name: (the modules
# the project imports from that pin, why)}
NOT_INSTALLED = {
    "scikit-learn": (["particles", "particles.distributions", "particles.state_space_models"],
                     "only particles.binary_smc imports sklearn; sim/bench/pf_particles.py does not"),
}


def canonical(name):
    return re.sub(r"[-_.]+", "-", name).lower()


def logical_lines(text):
    """Lines with backslash continuations joined."""
    return re.sub(r"\\\n", " ", text).splitlines()


def parse_pins(text):
    """({canonical name: version}, [problems]) of a requirements file."""
    pins, bad = {}, []
    for line in logical_lines(text):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        m = LINE.fullmatch(line)
        if m:
            pins[canonical(m.group(1))] = m.group(2)
        else:
            bad.append(f"not 'name==version --hash=sha256:...': {line}")
    return pins, bad


def unmet(req, pins, who, hold_version=True):
    """Problems of one requirement string of `who` against the pins."""
    r = Requirement(req)
    name = canonical(r.name)
    if name not in pins:
        return [f"{who} requires {req}: {r.name} is not pinned"]
    if hold_version and not r.specifier.contains(pins[name], prereleases=True):
        return [f"{who} requires {req}: pinned {r.name}=={pins[name]} is outside it"]
    return []


def closure(pins, nodeps, requires, roots, not_installed=()):
    """Problems of the pins as a closed set. requires(name) -> Requires-Dist
    strings of the installed distribution; roots: requirement strings (the
    project's own) that must resolve within the pins too."""
    bad = []
    seen = set()
    todo = [(n, "") for n in pins]
    for req in roots:
        bad += unmet(req, pins, "pyproject.toml")
        r = Requirement(req)
        todo += [(canonical(r.name), e) for e in r.extras]
    while todo:
        name, extra = todo.pop()
        if (name, extra) in seen or name not in pins:
            continue
        seen.add((name, extra))
        for req in requires(name):
            r = Requirement(req)
            if r.marker and not r.marker.evaluate({"extra": extra}):
                continue
            bad += unmet(req, pins, f"{name}=={pins[name]}" + (f"[{extra}]" if extra else ""))
            todo += [(canonical(r.name), e) for e in r.extras]
    for name in nodeps:
        for req in requires(name):
            r = Requirement(req)
            if canonical(r.name) in not_installed:
                continue
            if not r.marker or r.marker.evaluate({"extra": ""}):
                bad += unmet(req, pins, f"{name} (--no-deps)", hold_version=False)
    return bad


def pip_installs(files):
    """(path, line) of each call of pip's install command that may fetch:
    outside the installer and without --no-index. files: {path: text}."""
    hits = []
    for path, text in files.items():
        if path == INSTALLER:
            continue
        for line in logical_lines(text):
            if PIP_INSTALL.search(line) and "--no-index" not in line:
                hits.append((path, line.strip()))
    return hits


def installed_requires(name):
    return metadata.distribution(name).requires or []


def repo_scripts(root):
    """{path: text} of the repository's scripts, make and CMake files."""
    out = subprocess.run(["git", "-C", root, "ls-files", "--cached", "--others", "--exclude-standard", "-z"],
                         check=True, capture_output=True).stdout.decode()
    files = {}
    for path in sorted(set(p for p in out.split("\0") if p)):
        base = os.path.basename(path)
        full = os.path.join(root, path)
        if not os.path.isfile(full):
            continue
        with open(full, "rb") as f:
            data = f.read()
        if (base.endswith(SCRIPT_EXT) or base in ("Makefile", "CMakeLists.txt") or path.startswith(".ci/")
                or data.startswith(b"#!")):
            files[path] = data.decode("utf-8", "replace")
    return files


def read(root, path):
    with open(os.path.join(root, path), encoding="utf-8") as f:
        return f.read()


class MadeUp(unittest.TestCase):
    """Each check rejects what it is there to reject."""
    H = " --hash=sha256:" + "a" * 64

    def test_line_without_hash(self):
        pins, bad = parse_pins("a==1.0" + self.H + "\nb==2.0\n")
        self.assertEqual(pins, {"a": "1.0"})
        self.assertEqual(len(bad), 1)
        self.assertIn("b==2.0", bad[0])

    def test_unpinned_and_short_hash(self):
        _, bad = parse_pins("a>=1.0" + self.H + "\nb==1 --hash=sha256:abc\n")
        self.assertEqual(len(bad), 2)

    def test_continuation_lines(self):
        pins, bad = parse_pins("# c\nA_b==1.0 \\\n   " + self.H + " \\\n   " + self.H + "\n")
        self.assertEqual((pins, bad), ({"a-b": "1.0"}, []))

    def test_closure(self):
        reqs = {"a": ["b>=2", "c; python_version < '3'", "d; extra == 'x'"], "b": [], "d": ["e"], "p": ["b<1"]}
        pins = {"a": "1", "b": "2"}
        self.assertEqual(closure(pins, {}, reqs.get, []), [])
        self.assertEqual(closure(pins, {"p": "1"}, reqs.get, []), [])  # --no-deps: the name, not the range
        self.assertIn("b is not pinned", closure({"a": "1"}, {}, reqs.get, [])[0])
        self.assertIn("outside", closure({"a": "1", "b": "1.9"}, {}, reqs.get, [])[0])
        self.assertIn("d is not pinned", closure(pins, {}, reqs.get, ["a[x]>=1"])[0])
        self.assertIn("e is not pinned", closure(dict(pins, d="1"), {}, reqs.get, ["a[x]"])[0])
        self.assertIn("outside", closure(pins, {}, reqs.get, ["a>=2"])[0])
        req_q = {"p": ["q"]}
        self.assertIn("q is not pinned", closure(pins, {"p": "1"}, lambda n: req_q.get(n, []), [])[0])
        self.assertEqual(closure(pins, {"p": "1"}, lambda n: req_q.get(n, []), [], {"q"}), [])

    def test_pip_install_outside_the_installer(self):
        pip = "pip"
        files = {
            "Makefile": f"bench:\n\t$(PYTHON) -m {pip} install --no-deps \\\n\t  -r x.txt\n",
            "t.py": f'subprocess.run([sys.executable, "-m", "{pip}", "install", "x"])\n',
            "ok.sh": f"python -m {pip} install --no-index .\n",
            INSTALLER: f"python -m {pip} install -r r.txt\n",
        }
        self.assertEqual([p for p, _ in pip_installs(files)], ["Makefile", "t.py"])


class Repository(unittest.TestCase):
    """The repository's own files and the environment they installed."""

    def test_every_requirement_hashed(self):
        for path in (MAIN, NODEPS):
            pins, bad = parse_pins(read(ROOT, path))
            self.assertTrue(pins, path)
            self.assertEqual(bad, [], path)

    def test_installed_at_the_pins(self):
        for path in (MAIN, NODEPS):
            pins, _ = parse_pins(read(ROOT, path))
            have = {n: metadata.version(n) for n in pins}
            self.assertEqual(have, pins, f"{sys.executable}: not the pins of {path}; run cmake/setup-deps.sh")

    def test_closed_set(self):
        pins, _ = parse_pins(read(ROOT, MAIN))
        nodeps, _ = parse_pins(read(ROOT, NODEPS))
        project = tomllib.loads(read(ROOT, "pyproject.toml"))["project"]
        roots = list(project["dependencies"])
        for reqs in project.get("optional-dependencies", {}).values():
            roots += reqs
        self.assertEqual(closure(pins, nodeps, installed_requires, roots, set(NOT_INSTALLED)), [])

    def test_not_installed_is_not_imported(self):
        for name, (modules, why) in NOT_INSTALLED.items():
            mod = {"scikit-learn": "sklearn"}.get(name, name.replace("-", "_"))
            code = (f"import sys\nfor m in {modules!r}: __import__(m)\n"
                    f"sys.exit(1 if {mod!r} in sys.modules else 0)")
            rc = subprocess.run([sys.executable, "-c", code]).returncode
            self.assertEqual(rc, 0, f"importing {modules} loads {mod}, left uninstalled because {why}")

    def test_no_pip_install_at_run_time(self):
        files = repo_scripts(ROOT)
        self.assertIn("Makefile", files)
        self.assertIn(INSTALLER, files)
        self.assertEqual(pip_installs(files), [])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--root", default=ROOT)
    args, rest = ap.parse_known_args()
    ROOT = os.path.abspath(args.root)
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
