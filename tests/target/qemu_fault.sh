#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ctest target_qemu_fault: the mps2-an500 startup's fault handler
# (target/mps2/startup_mps2.c). The image executes an undefined instruction;
# QEMU must exit with status 3 and the handler's message, not hang (the
# timeout is the failure without a handler) nor return from main (status 0).
#   qemu_fault.sh IMAGE
set -uo pipefail
image=$1
qemu=${BR_QEMU:-qemu-system-arm}
command -v "$qemu" >/dev/null || { echo "FAIL: $qemu not found (make deps installs qemu-system-arm)" >&2; exit 1; }
[[ -f $image ]] || { echo "FAIL: no image at $image" >&2; exit 1; }
out=$(timeout 60 "$qemu" -M mps2-an500 -nographic -monitor none -serial none \
  -semihosting-config enable=on,target=native -kernel "$image" 2>&1)
rc=$?
echo "$out"
[[ $rc -eq 3 ]] || { echo "FAIL: exit status $rc, expected 3 (124: timed out)" >&2; exit 1; }
grep -q "unexpected exception" <<<"$out" || { echo "FAIL: no fault message" >&2; exit 1; }
echo "fault handler: exit status 3"
