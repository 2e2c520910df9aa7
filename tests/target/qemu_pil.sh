#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ctest target_qemu_pil (docs/link.md, "The image in the loop"): br_pil runs
# 0.2 s of the thesis circle with each estimator (H-inf only, + UKF, + PF),
# each axis's production application on QEMU's Cortex-M7 in lockstep with the
# host plant, and the simulator's same run; br_pil exits 1 when a duty
# differs in one bit. Fails (never skips) when QEMU or the image is missing.
#   qemu_pil.sh BR_PIL IMAGE
set -euo pipefail
pil=$1 image=$2
qemu=${BR_QEMU:-qemu-system-arm}
command -v "$qemu" >/dev/null || { echo "FAIL: $qemu not found (make deps installs qemu-system-arm)" >&2; exit 1; }
[[ -f $image ]] || { echo "FAIL: no image at $image (build the cm7-release preset)" >&2; exit 1; }
out=$("$pil" --image "$image" --est all --duration 0.2 --compare --timeout 60)
echo "$out"
# every estimator compared, none faulted
for e in none ukf pf; do
  grep -q "^$e: .* the duty sequence is the simulator's bit for bit" <<<"$out" || { echo "FAIL: $e not identical" >&2; exit 1; }
done
if grep -q FAULT <<<"$out"; then echo "FAIL: a run faulted" >&2; exit 1; fi
