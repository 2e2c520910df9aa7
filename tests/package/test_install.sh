#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The Python package as a user gets it (docs/python-package.md): a fresh
# virtual environment with the pinned set, hash-checked, by the one script
# that installs Python packages (cmake/setup-deps.sh, BR_VENV), then
# `pip install --no-index` of the repository (nothing more is fetched: its
# declared dependency ranges must accept the pins), then the console command
# from a directory outside the source tree, with no PYTHONPATH:
#   --help (of the command and of both sub-commands), --version (= VERSION),
#   a usage error (exit 2), a missing log (exit 1, "error: ..."),
#   a tiny diagnosis of a simulated log (exit 0, report/model/machine.json),
#   validate of its model on the log (exit 0, one relerr line on stdout),
#   and --quiet (no progress on stderr).
# Usage: test_install.sh SRC WORK PYTHON3 SIMLOG
set -euo pipefail
src=$1 work=$2 py3=$3 simlog=$4
fail() { echo "FAIL: $*" >&2; exit 1; }

rm -rf "$work"
mkdir -p "$work/run"
BR_VENV="$work/venv" BR_PYTHON3="$py3" "$src/cmake/setup-deps.sh" > /dev/null ||
  fail "cmake/setup-deps.sh into a fresh venv"
# --no-build-isolation: the build back-end is the venv's pinned setuptools;
# DIST_EXTRA_CONFIG keeps setuptools' build/ and egg-info out of the source tree
mkdir -p "$work/setuptools"
printf '[build]\nbuild_base = %s/build\n[egg_info]\negg_base = %s\n' "$work/setuptools" "$work/setuptools" \
  > "$work/setuptools.cfg"
DIST_EXTRA_CONFIG="$work/setuptools.cfg" "$work/venv/bin/python" -m pip install --quiet \
  --disable-pip-version-check --require-virtualenv --no-index --no-build-isolation "$src" ||
  fail "pip install --no-index $src"
cmd="$work/venv/bin/bristle-diagnose"
[[ -x $cmd ]] || fail "the install made no console command bristle-diagnose"
cd "$work/run"   # outside the source tree: the package must not need it
unset PYTHONPATH
export MPLBACKEND=Agg OPENBLAS_NUM_THREADS=1

for sub in "" diagnose validate; do
  h="$("$cmd" $sub --help)" || fail "bristle-diagnose $sub --help exits non-zero"
  # every option has a help text: argparse prints an option with no help
  # text as its name alone on a line
  bare="$(grep -E '^  (-[a-zA-Z], )?--?[a-z-]+( [A-Z]+)?$' <<<"$h" || true)"
  [[ -z $bare ]] || fail "bristle-diagnose $sub --help: options without help: $bare"
  grep -q "exit status" <<<"$h" || fail "bristle-diagnose $sub --help does not document the exit status"
done
want="bristle-diagnose $(tr -d '[:space:]' < "$src/VERSION")"
have="$("$cmd" --version)"
[[ $have == "$want" ]] || fail "--version printed '$have', want '$want'"

set +e
"$cmd" diagnose --log x.csv 2> usage.err; rc=$?
set -e
[[ $rc -eq 2 ]] || fail "a usage error (no --out) exits $rc, want 2"
set +e
"$cmd" diagnose --log missing.csv --out out 2> missing.err; rc=$?
set -e
[[ $rc -eq 1 ]] || fail "a missing log exits $rc, want 1"
grep -q "^error: .*missing.csv" missing.err || fail "a missing log: no 'error: ...missing.csv' line: $(cat missing.err)"
! grep -q Traceback missing.err || fail "a missing log printed a traceback"

"$simlog" --out log.csv --seed 3 --force-noise 0.1 --cycles 1 > /dev/null
"$cmd" diagnose --log log.csv --out diag --no-plots 2> diag.err || fail "diagnose failed: $(cat diag.err)"
for f in report.json model.json machine.json report.md; do
  [[ -s diag/$f ]] || fail "diagnose wrote no diag/$f"
done
grep -q "^verdict: " diag.err || fail "diagnose logged no verdict line: $(cat diag.err)"
"$work/venv/bin/python" - diag <<'PY' || fail "machine.json does not load with the installed loader"
import sys, os
from bristle.design import machine
m = machine.load(os.path.join(sys.argv[1], "machine.json"))
print("machine.json loads:", m["name"])
PY
"$work/venv/bin/python" - <<'PY' || fail "bristle.link does not round-trip a frame when installed"
from bristle.link import decode_frame, encode_frame, pack, unpack
f = decode_frame(encode_frame(0x21, 7, pack("param_write", param=3, value=0.5)))
assert unpack(f.id, f.payload) == ("param_write", {"param": 3, "value": 0.5}), f
print("bristle.link installed: a param_write frame round-trips")
PY
link="$work/venv/bin/bristle-link"
[[ -x $link ]] || fail "the install made no console command bristle-link"
"$link" --help > link.help || fail "bristle-link --help exits non-zero"
grep -q "stream" link.help || fail "bristle-link --help names no stream subcommand"
set +e
"$link" --port /dev/null status 2> link.err; rc=$?
set -e
[[ $rc -eq 2 ]] || fail "bristle-link without --machine exits $rc, want 2"
"$work/venv/bin/python" -c "import serial" || fail "pyserial (bristle-link's port) is not installed"
"$cmd" validate --model diag/model.json --log log.csv > val.out 2> val.err || fail "validate failed: $(cat val.err)"
grep -q "relerr [0-9.e+-]* % over" val.out || fail "validate printed no relerr line on stdout: $(cat val.out)"
"$cmd" diagnose --log log.csv --out diag2 --no-plots --quiet 2> quiet.err || fail "diagnose --quiet failed"
[[ ! -s quiet.err ]] || fail "--quiet still logged: $(cat quiet.err)"
echo "installed bristle $("$cmd" --version | cut -d' ' -f2) in a fresh venv; $(grep '^verdict' diag.err); $(cat val.out)"
