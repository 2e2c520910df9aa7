#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ctest study_faults: the fault campaign (sim/studies/faults.sh) holds every
# bound it does not list as known broken, its page is the committed
# docs/reliability-faults.md, and br_faults fails on what it must fail on: a
# broken bound not listed, a listed bound that holds.
# usage: test_faults.sh BR_FAULTS SOURCE_DIR WORK_DIR
set -euo pipefail
exe=$1 src=$2 work=$3
mkdir -p "$work"
bash "$src/sim/studies/faults.sh" "$exe" "$work/reliability-faults.md"
if ! diff -u "$src/docs/reliability-faults.md" "$work/reliability-faults.md"; then
  echo "test_faults: docs/reliability-faults.md is not what make faults writes (run make faults)" >&2
  exit 1
fi
# the UKF without its external-force state trips under the load step: without the list the
# tool fails
if "$exe" --plant realistic --only load_half_30 --ctrl hinf_ukf --ukf-load 0 >/dev/null; then
  echo "test_faults: br_faults passed a broken bound it was not told of" >&2
  exit 1
fi
# H-inf only holds the stuck encoder's bounds: listing it as broken fails
if "$exe" --plant realistic --only enc_stuck_90 --ctrl hinf_only --expect enc_stuck_90/hinf_only >/dev/null 2>&1; then
  echo "test_faults: br_faults accepted a known-broken list naming a bound that holds" >&2
  exit 1
fi
# and it holds them
"$exe" --plant realistic --only enc_stuck_90,enc_drop5_90,ref_nan_90,deadline_90 --ctrl hinf_only >/dev/null
echo "test_faults: the campaign's bounds hold as listed"
