#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# A stand-in for qemu-system-arm in test_pil_signal.py: it writes its work
# folder (the "pipe:DIR/link" of its -serial options) and its process id as a
# line to $BR_FAKE_QEMU_LOG, then never answers (sleeps) or, with
# BR_FAKE_QEMU_EXIT=1, ends at once, as a QEMU that cannot start the image.
for a in "$@"; do
  case $a in
    pipe:*/link) dir=${a#pipe:}; dir=${dir%/link} ;;
  esac
done
echo "$dir $$" >> "$BR_FAKE_QEMU_LOG"
[ "${BR_FAKE_QEMU_EXIT:-0}" = 1 ] && exit 3
exec sleep 600
