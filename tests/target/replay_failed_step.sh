#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# ctest target_replay_failed_step: br_replay_run ends the replay at a failed
# step (target/replay/br_replay.h: -4, the later axes of that period not
# stepped, the records of those that were written first). A two-axis stream
# whose axis 0 jumps by 10^6 counts at period K (the application's speed
# guard faults): the host replay must fail with -4 after 2 K + 1 records, the
# last axis 0's at period K with a failure status.
#   replay_failed_step.sh RECORD HOST WORK
set -uo pipefail
record=$1 host=$2 work=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
rm -rf "$work" && mkdir -p "$work"
"$record" --out "$work/stream.bin" --duration 0.03 --axes 2 >/dev/null || fail "recording"
K=10
hdr_h=$(dirname "$0")/../../target/replay/br_replay.h
python3 - "$work/stream.bin" "$work/bad.bin" "$K" "$hdr_h" <<'PY' || fail "no stream to corrupt"
import re, struct, sys
d = bytearray(open(sys.argv[1], "rb").read())
h = open(sys.argv[4]).read()  # br_replay.h: header words, words per period and axis
hdr, words = (int(re.search(r"#define %s (\d+)u" % n, h).group(1)) for n in ("BR_REPLAY_HDR_WORDS", "BR_REPLAY_STEP_WORDS"))
axes, k = 2, int(sys.argv[3])
off = 4 * (hdr + words * axes * k)  # period k, axis 0: its counts
struct.pack_into("<i", d, off, struct.unpack_from("<i", d, off)[0] + 1000000)
open(sys.argv[2], "wb").write(d)
PY
msg=$("$host" "$work/bad.bin" "$work/out.bin" 2>&1)
rc=$?
echo "$msg"
[[ $rc -eq 1 && $msg == *"replay failed (-4)"* ]] || fail "exit $rc, expected the replay's -4"
python3 - "$work/out.bin" "$K" <<'PY' || fail "records"
import struct, sys
d, k = open(sys.argv[1], "rb").read(), int(sys.argv[2])
n = len(d) // 24  # 6 words per record
last = struct.unpack_from("<6i", d, 24 * (n - 1))
print(f"{n} records; the last: period {last[0]}, status {last[1]}")
sys.exit(0 if n == 2 * k + 1 and last[0] == k and last[1] < 0 else 1)
PY
