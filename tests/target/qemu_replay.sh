#!/usr/bin/env bash
# ctest target_qemu_replay (docs/target.md): record a 1 s stream of the
# H-inf + PF circle on the host simulator, replay it through the application
# (br_app_step with the PF, m = 1500) on the host and on the Cortex-M7 image under
# qemu-system-arm (mps2-an500, semihosting), and compare the outputs.
# Fails (never skips) when QEMU or the image is missing.
#   qemu_replay.sh RECORD HOST_REPLAY CMP IMAGE WORKDIR
set -euo pipefail
record=$1 host=$2 cmp=$3 image=$4 work=$5
qemu=${BR_QEMU:-qemu-system-arm}
command -v "$qemu" >/dev/null || { echo "FAIL: $qemu not found (make deps installs qemu-system-arm)" >&2; exit 1; }
[[ -f $image ]] || { echo "FAIL: no replay image at $image (build the cm7-release preset: make test / make firmware)" >&2; exit 1; }
mkdir -p "$work"
rm -f "$work"/{stream,expect,host,target}.bin
"$record" --out "$work/stream.bin" --expect "$work/expect.bin" --duration 1.0
"$host" "$work/stream.bin" "$work/host.bin"
# Under QEMU the image's I/O paths are the host's (semihosting, target=native).
timeout 600 "$qemu" -M mps2-an500 -nographic -monitor none -serial none \
  -semihosting-config "enable=on,target=native,arg=replay,arg=$work/stream.bin,arg=$work/target.bin,arg=0" \
  -kernel "$image"
"$cmp" "$work/host.bin" "$work/target.bin" --expect "$work/expect.bin"
