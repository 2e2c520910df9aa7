#!/usr/bin/env bash
# make target-bench (docs/target.md): instructions per PF particle-step and per
# control period of the firmware on QEMU's emulated Cortex-M7 (mps2-an500),
# and flash / RAM from the replay image's map file.
#   target_bench.sh HOST_BUILD_DIR CM7_BUILD_DIR OUT_DIR
# Method: the replay image times every br_app_step with SysTick (CPU clock
# source, 25 MHz in QEMU's model); QEMU runs with -icount shift=0, so virtual
# time advances by exactly 1 ns per executed instruction and 1 tick = 40
# instructions, which a calibration loop of 2e6 known instructions checks on
# every run. Two particle counts separate the per-particle slope from the
# fixed per-period cost. A third, short run (20 periods, m_hi) with QEMU's
# translation-block log gives the profile: instructions per particle-step by
# function and by block (target/mps2/tb_profile.py).
set -euo pipefail
host=$1 cm7=$2 out=$3
qemu=${BR_QEMU:-qemu-system-arm}
image=$cm7/target/mps2/br_replay_mps2.elf
map=$cm7/target/mps2/br_replay_mps2.map
m_hi=${BR_BENCH_M_HI:-1500}
m_lo=${BR_BENCH_M_LO:-100}
command -v "$qemu" >/dev/null || { echo "target-bench: $qemu not found (make deps)" >&2; exit 1; }
[[ -f $image && -f $map ]] || { echo "target-bench: no image/map at $image" >&2; exit 1; }
mkdir -p "$out"
"$host/tests/target/br_replay_record" --out "$out/stream.bin" --duration 1.0 >/dev/null

declare -A mean med min max p99 ipt
for m in "$m_hi" "$m_lo"; do
  log=$("$qemu" -M mps2-an500 -nographic -monitor none -serial none -icount shift=0 \
    -semihosting-config "enable=on,target=native,arg=replay,arg=$out/stream.bin,arg=$out/target_m$m.bin,arg=$m" \
    -kernel "$image" 2>&1)
  echo "$log" > "$out/qemu_m$m.log"
  read -r ci ct < <(sed -n 's/^calib insns=\([0-9]*\) ticks=\([0-9]*\).*/\1 \2/p' <<<"$log")
  [[ -n ${ct:-} && $ct -gt 0 ]] || { echo "target-bench: calibration failed: $log" >&2; exit 1; }
  ipt[$m]=$(awk -v i="$ci" -v t="$ct" 'BEGIN { printf "%.6f", i / t }')
  read -r n mean[$m] med[$m] min[$m] max[$m] p99[$m] < <("$host/tests/target/br_replay_cmp" --cost "$out/target_m$m.bin")
  sizes=$(sed -n 's/.*sizeof_replay=\([0-9]*\) sizeof_pf=\([0-9]*\).*/\1 \2/p' <<<"$log")
done
read -r sz_replay sz_pf <<<"$sizes"

awk -v mh="$m_hi" -v ml="$m_lo" -v n="$n" \
    -v ah="${mean[$m_hi]}" -v al="${mean[$m_lo]}" -v dh="${med[$m_hi]}" -v dl="${med[$m_lo]}" \
    -v xh="${max[$m_hi]}" -v ph="${p99[$m_hi]}" -v ih="${ipt[$m_hi]}" -v il="${ipt[$m_lo]}" '
BEGIN {
  printf "target-bench: QEMU mps2-an500 (Cortex-M7, FPU), -icount shift=0, %d control periods of 1.5 ms (k >= 1)\n", n - 1
  printf "  calibration: %.3f instructions per SysTick tick (expected 40)\n", ih
  printf "  instructions per control period (br_app_step: encoder, PF, controller, PWM)\n"
  printf "    m = %4d: mean %9.0f  median %9.0f  p99 %9.0f  max %9.0f\n", mh, ah * ih, dh * ih, ph * ih, xh * ih
  printf "    m = %4d: mean %9.0f  median %9.0f\n", ml, al * il, dl * il
  slope = (ah * ih - al * il) / (mh - ml); fixed = al * il - ml * slope
  printf "  per particle-step (slope of the means): %.1f instructions   (goal <= 250)\n", slope
  printf "  fixed per period (intercept):           %.0f instructions\n", fixed
  printf "  at m = %d: %.0f instructions per period; at 1 instruction/cycle and 480 MHz: %.3f ms of the 1.5 ms period (%.0f%%; goal <= 50%%)\n", mh, ah * ih, ah * ih / 480e3, 100 * ah * ih / 480e3 / 1.5
  printf "  budget: half of 480 MHz x 1.5 ms = 360000 cycles / 1500 particles = 240 per particle-step, fixed part included\n"
  printf "  operation-count lower bound per particle-step: about 200 instructions (docs/target.md)\n"
}'

# Profile: a 0.03 s stream (20 periods), one execution trace, then the log is deleted.
"$host/tests/target/br_replay_record" --out "$out/stream_prof.bin" --duration 0.03 >/dev/null
"$qemu" -M mps2-an500 -nographic -monitor none -serial none -icount shift=0 \
  -semihosting-config "enable=on,target=native,arg=replay,arg=$out/stream_prof.bin,arg=$out/target_prof.bin,arg=$m_hi" \
  -kernel "$image" -d in_asm,exec,nochain -D "$out/qemu_prof.log" >/dev/null 2>&1
read -r n_prof _ < <("$host/tests/target/br_replay_cmp" --cost "$out/target_prof.bin")
"${BR_PYTHON:-python3}" "$(dirname "$0")/tb_profile.py" "$out/qemu_prof.log" "$image" \
  --particle-steps $(( (n_prof - 1) * m_hi )) --skip main  # main: the calibration loop
rm -f "$out/qemu_prof.log"

# Memory from the map file: output sections in CODE (0x0...) and RAM (0x2...).
awk -v szr="$sz_replay" -v szp="$sz_pf" '
  function hex(h,   i, c, v) { v = 0; h = tolower(substr(h, 3))
    for (i = 1; i <= length(h); i++) { c = index("0123456789abcdef", substr(h, i, 1)) - 1; v = v * 16 + c }
    return v }
  /^\.[A-Za-z_]/ { sec = $1 }
  /^\.[A-Za-z_]/ && NF >= 3 && $2 ~ /^0x/ { a = hex($2); s = hex($3)
    if (sec ~ /^\.debug|^\.comment|^\.ARM\.attributes/) next
    if (a < 536870912) code += s; else { ram += s; if (sec == ".data") code += s; if (sec == ".stack") stk = s } }
  sec ~ /^\.(text|rodata|data|bss)$/ && /libbristle\.a\(/ {
    if ($1 ~ /^0x/ && NF >= 3) fw += hex($2); else if ($2 ~ /^0x/ && NF >= 4) fw += hex($3) }
  END {
    printf "  memory (map file %s):\n", FILENAME
    printf "    flash/code: %7d bytes (vectors, code, rodata incl. the 16 KiB noise table, .data image)\n", code
    printf "      of which libbristle.a input sections: %d bytes\n", fw
    printf "    RAM:        %7d bytes (.data + .bss + %d bytes reserved stack)\n", ram, stk
    printf "      on the stack: br_replay_t %d bytes, of which br_pf_t %d bytes (BR_PF_MAX_PARTICLES 2048)\n", szr, szp
  }' "$map"
