#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ctest target_qemu_replay (docs/target.md): record a 1 s stream of the
# H-inf + PF circle on the host simulator (both axes of the X-Y table), replay
# it through two applications (br_app_step with the PF, m = 1500 each, the
# two axes in turn every period, as on one MCU) on the host and on the
# Cortex-M7 image under
# qemu-system-arm (mps2-an500, semihosting), and compare the outputs.
# Fails (never skips) when QEMU or the image is missing.
#   qemu_replay.sh RECORD HOST_REPLAY CMP IMAGE WORKDIR
# BR_QEMU_MACHINE: the emulated board (default mps2-an500, the M7; mps2-an386:
# the Cortex-M4 image of the cm4-release preset, target_qemu_replay_m4).
# BR_REPLAY_RECORD_ARGS: more br_replay_record options (target_qemu_replay_ahead:
# --ahead 0.5); BR_REPLAY_PATHS: the image's PF paths to run (default "0 1").
set -euo pipefail
record=$1 host=$2 cmp=$3 image=$4 work=$5
qemu=${BR_QEMU:-qemu-system-arm}
command -v "$qemu" >/dev/null || { echo "FAIL: $qemu not found (make deps installs qemu-system-arm)" >&2; exit 1; }
[[ -f $image ]] || { echo "FAIL: no replay image at $image (build the cm7-release preset: make test / make firmware)" >&2; exit 1; }
mkdir -p "$work"
rm -f "$work"/{stream,expect,host,target}.bin
"$record" --out "$work/stream.bin" --expect "$work/expect.bin" --duration 1.0 --axes 2 ${BR_REPLAY_RECORD_ARGS:-}
"$host" "$work/stream.bin" "$work/host.bin"
# Under QEMU the image's I/O paths are the host's (semihosting, target=native).
# The image runs the PF's vector path (the default) and its scalar reference
# path; both must equal the host's vector path, which must equal the closed loop.
for sp in ${BR_REPLAY_PATHS:-0 1}; do
  timeout 600 "$qemu" -M "${BR_QEMU_MACHINE:-mps2-an500}" -nographic -monitor none -serial none \
    -semihosting-config "enable=on,target=native,arg=replay,arg=$work/stream.bin,arg=$work/target.bin,arg=0,arg=$sp" \
    -kernel "$image"
  "$cmp" "$work/host.bin" "$work/target.bin" --expect "$work/expect.bin"
done
