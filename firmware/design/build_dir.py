#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The build folder of another machine: its image's cross build (`make
firmware MACHINE=FILE`, docs/configure.md) or its host build (`make tune
MACHINE=FILE`, docs/tuning.md): build/<preset>-<name>-<hash>, <name> the
file's validated "name" ([a-z0-9][a-z0-9_-]*) and <hash> the first 8 hex
digits of the SHA-256 of the file's real path, so that two machine files
with the same name never share a folder (nor one image).

  build_dir.py PRESET FILE     prints the folder (relative to the repository)
A bad machine file: its "FILE: field a.b.c: problem" lines, exit status 1;
a preset not among PRESETS: exit status 2."""
import hashlib
import os
import re
import sys

import machine

PRESETS = ("cm7-release", "cm4-release", "host-release")  # the images; the host build `make tune MACHINE=` runs


def build_dir(preset, path):
    """build/<preset>-<name>-<8 hex> for the machine file at path (validated)."""
    if preset not in PRESETS:
        raise ValueError("preset %r is not one of %s" % (preset, ", ".join(PRESETS)))
    m = machine.load(path)
    name = m["name"]
    # the schema's pattern; checked again here, the name becomes a path and shell text
    if not re.fullmatch(r"[a-z0-9][a-z0-9_-]*", name):
        raise machine.MachineError(["%s: field name: %r is not [a-z0-9][a-z0-9_-]*" % (m["file"], name)])
    digest = hashlib.sha256(os.fsencode(os.path.realpath(path))).hexdigest()[:8]
    return os.path.join("build", "%s-%s-%s" % (preset, name, digest))


def main(argv):
    if len(argv) != 2 or argv[0] not in PRESETS:
        sys.stderr.write("usage: build_dir.py {%s} MACHINE.json\n" % "|".join(PRESETS))
        return 2
    try:
        print(build_dir(argv[0], argv[1]))
    except machine.MachineError as e:
        for line in e.lines:
            sys.stderr.write(line + "\n")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
