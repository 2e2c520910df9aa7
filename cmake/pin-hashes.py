#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the --hash lines of the pinned Python requirements
(cmake/python-requirements.txt, sim/bench/requirements-particles.txt), which
cmake/setup-deps.sh installs with pip's --require-hashes
(docs/regenerate.md, "Python pins").

Usage: pin-hashes.py [--python PY] [FILE...]

Each `name==version` line of each FILE (default: the two files above) gets the
sha256 of the distribution file that pip downloads for it on this machine
(`PY -m pip download --no-deps`, default .venv/bin/python: its Python and
platform, so the wheel pip's install command chooses there, or the sdist where the
version has no wheel for it). Comments and the order of the lines stay; the
hashes already in FILE are replaced. The output depends only on the pins and
the files the index serves for them: run it again and nothing changes.

Exit status: 0 written, 1 a pin has no file or pip download failed, 2 bad
usage or a line that is not `name==version`."""
import argparse
import hashlib
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = ["cmake/python-requirements.txt", "sim/bench/requirements-particles.txt"]
PIN = re.compile(r"([A-Za-z0-9][A-Za-z0-9_.\-]*)==([A-Za-z0-9_.+!\-]+)")


def fail(msg, code):
    print(f"pin-hashes: {msg}", file=sys.stderr)
    sys.exit(code)


def canonical(name):
    """PEP 503 normalised project name."""
    return re.sub(r"[-_.]+", "-", name).lower()


def parse(path):
    """The file as a list of items: ("text", line) for comments and blank
    lines, ("pin", name, version) for requirements (their hash lines dropped)."""
    items = []
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            items.append(("text", line))
            i += 1
            continue
        # a requirement and its continuation lines (" \" ... "--hash=...")
        body = stripped
        while body.endswith("\\") and i + 1 < len(lines):
            i += 1
            body = body[:-1] + " " + lines[i].strip()
        i += 1
        words = body.split()
        m = PIN.fullmatch(words[0])
        if not m or any(not w.startswith("--hash=") for w in words[1:]):
            fail(f"{path}: not 'name==version [--hash=...]': {body}", 2)
        items.append(("pin", m.group(1), m.group(2)))
    return items


def dist_key(filename):
    """(canonical name, version) of a wheel or sdist file name."""
    if filename.endswith(".whl"):
        name, ver = filename.split("-")[:2]
    else:
        base = re.sub(r"\.(tar\.gz|zip|tar\.bz2)$", "", filename)
        name, ver = base.rsplit("-", 1)
    return canonical(name), ver


def download(python, pins, dest):
    """{(canonical name, version): sha256} of the files pip downloads."""
    req = os.path.join(dest, "requirements.txt")
    with open(req, "w", encoding="utf-8") as f:
        f.writelines(f"{n}=={v}\n" for n, v in pins)
    files = os.path.join(dest, "files")
    cmd = [python, "-m", "pip", "download", "--quiet", "--disable-pip-version-check",
           "--no-deps", "--dest", files, "-r", req]
    if subprocess.run(cmd).returncode != 0:
        fail("pip download failed", 1)
    hashes = {}
    for fn in sorted(os.listdir(files)):
        with open(os.path.join(files, fn), "rb") as f:
            hashes.setdefault(dist_key(fn), []).append(hashlib.sha256(f.read()).hexdigest())
    return hashes


def render(items, hashes):
    out = []
    for item in items:
        if item[0] == "text":
            out.append(item[1])
            continue
        _, name, ver = item
        digests = hashes.get((canonical(name), ver))
        if not digests:
            fail(f"pip downloaded no file for {name}=={ver}", 1)
        out.append(f"{name}=={ver} \\")
        out.extend(f"    --hash=sha256:{d}" + (" \\" if k + 1 < len(digests) else "")
                   for k, d in enumerate(sorted(digests)))
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--python", default=os.path.join(ROOT, ".venv", "bin", "python"))
    ap.add_argument("files", nargs="*", default=[os.path.join(ROOT, f) for f in FILES])
    args = ap.parse_args()
    parsed = {path: parse(path) for path in args.files}
    pins = sorted({(i[1], i[2]) for items in parsed.values() for i in items if i[0] == "pin"})
    with tempfile.TemporaryDirectory(prefix="pin-hashes-") as tmp:
        hashes = download(args.python, pins, tmp)
    for path, items in parsed.items():
        text = render(items, hashes)
        with open(path + ".tmp", "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(path + ".tmp", path)
        print(f"pin-hashes: {os.path.relpath(path, ROOT)}: "
              f"{sum(1 for i in items if i[0] == 'pin')} pins hashed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
