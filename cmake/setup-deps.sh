#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs what building and testing bristle needs, idempotently:
#   Debian packages: host compiler, CMake, Ninja, cmocka, cJSON (the
#   simulator's model.json reader), the Arm cross
#   toolchain with newlib, qemu-system-arm (the emulated Cortex-M7 of the
#   target tests and make target-bench, docs/target.md), cppcheck (the
#   static test), clang with its compiler-rt (the libFuzzer targets of the
#   fuzz preset), Python's venv module;
#   .venv in the project root (or BR_VENV: the install test's fresh one) with
#   the pinned cmake/python-requirements.txt and, without its declared
#   dependencies, sim/bench/requirements-particles.txt (make bench's
#   third-party PF): every file checked against the --hash lines
#   (pip --require-hashes; cmake/pin-hashes.py writes them). This is the only
#   place that installs Python packages: no make target or test does at run time.
# Quick when everything is in place: dpkg status checks, and a stamp in .venv
# keyed by the hash of the requirements files (and of the interpreter).
# Exits non-zero with a message when something cannot be installed.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
req="$root/cmake/python-requirements.txt"
req_nodeps="$root/sim/bench/requirements-particles.txt"
venv="${BR_VENV:-$root/.venv}"
stamp="$venv/.bristle-requirements.sha256"

die() { echo "setup-deps: error: $*" >&2; exit 1; }
say() { echo "setup-deps: $*"; }

# ---- Debian packages ----------------------------------------------------------
pkgs=(
  gcc libc6-dev make cmake ninja-build
  libcmocka-dev
  libcjson-dev
  gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi
  qemu-system-arm
  cppcheck
  clang libclang-rt-14-dev
  python3 python3-venv
)
installed() {
  local st
  st="$(dpkg -s "$1" 2>/dev/null || true)"
  [[ $st == *"Status: install ok installed"* ]]
}
missing=()
for p in "${pkgs[@]}"; do
  installed "$p" || missing+=("$p")
done
if ((${#missing[@]})); then
  say "installing Debian packages: ${missing[*]}"
  command -v apt-get >/dev/null || die "apt-get not found; install manually: ${missing[*]}"
  sudo=()
  if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || die "not root and no sudo; install manually: ${missing[*]}"
    sudo=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo[@]}" apt-get update -q || die "apt-get update failed"
  "${sudo[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}" ||
    die "apt-get install failed for: ${missing[*]}"
  for p in "${missing[@]}"; do
    installed "$p" || die "package $p is still not installed"
  done
fi
for t in cmake ninja arm-none-eabi-gcc arm-none-eabi-size qemu-system-arm cppcheck clang; do
  command -v "$t" >/dev/null || die "$t not on PATH after installation"
done

# ---- Python virtual environment ---------------------------------------------------
python="${BR_PYTHON3:-python3}"
command -v "$python" >/dev/null || die "$python not found"
"$python" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' ||
  die "$python is $("$python" -V 2>&1); numpy 2.4 needs Python >= 3.11"

if [[ -x "$venv/bin/python" ]] && ! "$venv/bin/python" -c 'import sys' >/dev/null 2>&1; then
  say "removing a broken .venv (its interpreter does not start)"
  rm -rf "$venv"
fi
if [[ ! -x "$venv/bin/python" ]]; then
  say "creating .venv with $("$python" -V 2>&1)"
  "$python" -m venv "$venv" || die "python3 -m venv failed (Debian: apt-get install python3-venv)"
fi

key="$( { sha256sum "$req" "$req_nodeps" | cut -d' ' -f1; "$venv/bin/python" -VV; } | sha256sum | cut -d' ' -f1)"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$key" ]]; then
  exit 0
fi
say "installing pinned Python packages into .venv"
rm -f "$stamp"
pip=("$venv/bin/python" -m pip install --quiet --disable-pip-version-check --require-virtualenv --require-hashes)
"${pip[@]}" -r "$req" || die "pip install --require-hashes -r cmake/python-requirements.txt failed"
"${pip[@]}" --no-deps -r "$req_nodeps" ||
  die "pip install --require-hashes --no-deps -r sim/bench/requirements-particles.txt failed"

# Every pin must be what is installed, not merely something that imports.
"$venv/bin/python" - "$req" "$req_nodeps" <<'PY' || die "installed Python packages do not match the pins"
import re, sys
from importlib.metadata import version, PackageNotFoundError
bad = []
text = "".join(open(p).read() for p in sys.argv[1:])
for line in re.sub(r"\\\n", " ", text).splitlines():
    line = line.split("#", 1)[0].strip()
    if not line:
        continue
    m = re.fullmatch(r"([A-Za-z0-9_.\-]+)==(\S+)(\s+--hash=sha256:[0-9a-f]{64})+", line)
    if not m:
        bad.append(f"requirement without an exact pin and a hash: {line}")
        continue
    name, want = m.group(1), m.group(2)
    try:
        have = version(name)
    except PackageNotFoundError:
        have = None
    if have != want:
        bad.append(f"{name}: want {want}, have {have}")
for b in bad:
    print("setup-deps:", b, file=sys.stderr)
sys.exit(1 if bad else 0)
PY
"$venv/bin/python" -c 'import numpy, scipy, matplotlib' || die "numpy/scipy/matplotlib do not import"
echo "$key" > "$stamp"
say "Python environment ready ($("$venv/bin/python" -V 2>&1))"
