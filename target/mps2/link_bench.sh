#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The link's and the recorder's cost per control period on QEMU's Cortex-M7
# and the production period against its deadline (docs/link.md, "Cost on the
# M7"); run by make target-bench (target_bench.sh) and by the ctest
# target_link_deadline.
#   link_bench.sh CM7_BUILD_DIR OUT_DIR PERIODS
# Runs br_link_bench_mps2 (target/mps2/link_bench_main.c) twice, with
# telemetry every period (full) and at the image's decimation (shipped), under
# -icount shift=0 (1 SysTick tick = 40 instructions, the calibration line
# checks it). Prints each part's mean and worst instructions per period and
# their share of the period, then exits 1 when the worst period with full
# telemetry is above deadline-share (target/mps2/budget.txt) of the period's
# cycles, when the calibration is not 40 instructions per tick, or when the
# run did not exercise what it measures (telemetry dropped at the full rate,
# no dump chunk, no bad frame, or an axis that did not hold: a measurement the
# estimator rejected while the reference holds the axis still). The period and
# the clock are the image's own output, from their generated / port headers.
set -euo pipefail
cm7=$1 out=$2 periods=$3
qemu=${BR_QEMU:-qemu-system-arm}
image=$cm7/target/mps2/br_link_bench_mps2.elf
budget_file=$(dirname "$0")/budget.txt
share=$(awk '$1 == "deadline-share" { print $2 }' "$budget_file")
[[ -n $share ]] || { echo "link-bench: no deadline-share in $budget_file" >&2; exit 1; }
command -v "$qemu" >/dev/null || { echo "link-bench: $qemu not found (make deps)" >&2; exit 1; }
[[ -f $image ]] || { echo "link-bench: no image at $image" >&2; exit 1; }
mkdir -p "$out"
rc=0
for mode in full shipped; do
  every=1; [[ $mode == shipped ]] && every=0  # 0: the image's BR_IMAGE_TLM_EVERY
  log=$("$qemu" -M mps2-an500 -nographic -monitor none -serial none -icount shift=0 \
    -semihosting-config "enable=on,target=native,arg=link-bench,arg=$periods,arg=$every" \
    -kernel "$image" 2>&1) || { echo "$log" >&2; echo "link-bench: the $mode run failed" >&2; exit 1; }
  echo "$log" > "$out/qemu_link_$mode.log"
  awk -v mode="$mode" -v share="$share" '
    /^calib / { split($2, a, "="); split($3, b, "="); ipt = a[2] / b[2] }
    /^link_bench / { for (i = 2; i <= NF; i++) { split($i, kv, "="); h[kv[1]] = kv[2] } }
    /^part / { n[$2] = substr($3, 3); s[$2] = substr($4, 11); x[$2] = substr($5, 11) }
    /^counters / { for (i = 2; i <= NF; i++) { split($i, kv, "="); c[kv[1]] = kv[2] } }
    /^hold / { for (i = 2; i <= NF; i++) { split($i, kv, "="); hd[kv[1]] = kv[2] } }
    END {
      if (ipt == "" || ipt != 40) { printf "link-bench: calibration %s instructions per tick, expected 40\n", ipt; exit 1 }
      cyc = h["period_ns"] * h["cpu_hz"] / 1e9; lim = cyc * share / 100
      printf "link-bench (%s telemetry: a sample every %d periods): QEMU mps2-an500 (Cortex-M7), -icount shift=0, %d periods of %.3f ms; %.0f cycles per period at %.0f MHz\n", mode, h["tlm_every"], n["total"], h["period_ns"] / 1e6, cyc, h["cpu_hz"] / 1e6
      split("svc app tlm rec dump total", order, " ")
      name["svc"] = "br_svc (link, request, reference, reports)"; name["app"] = "br_app_step (estimator, control)"
      name["tlm"] = "sample + br_tlm_step"; name["rec"] = "br_rec_push"; name["dump"] = "br_rec_command + dump chunk"
      name["total"] = "the production period"
      for (i = 1; i <= 6; i++) { p = order[i]; if (n[p] == 0) { m = 0 } else { m = s[p] / n[p] * ipt }
        printf "  %-44s mean %8.0f  worst %8.0f instructions  (%6.2f%% / %6.2f%% of the period; %d periods)\n", name[p], m, x[p] * ipt, 100 * m / cyc, 100 * x[p] * ipt / cyc, n[p] }
      printf "  link + telemetry + recorder (svc + tlm + rec + dump), sum of the worst: %.0f instructions (%.2f%% of the period)\n", (x["svc"] + x["tlm"] + x["rec"] + x["dump"]) * ipt, 100 * (x["svc"] + x["tlm"] + x["rec"] + x["dump"]) * ipt / cyc
      printf "  counters: %d frames accepted, %d bad CRC, %d unknown id; %d frames sent, %d refused; telemetry dropped %d\n", c["rx_frames"], c["rx_bad_crc"], c["rx_unknown_id"], c["tx_frames"], c["tx_busy"], c["tlm_dropped"]
      if (mode == "full" && (c["tlm_dropped"] != 0 || h["tlm_every"] != 1)) { print "link-bench: FAIL: telemetry not at the control rate"; exit 1 }
      printf "  the held axis: %s measurements rejected (BR_W_OUTLIER), largest |count| %s (the reference at 0.5)\n", hd["outliers"], hd["max_abs_counts"]
      if (n["dump"] == 0 || c["rx_bad_crc"] == 0) { print "link-bench: FAIL: no dump chunk or no bad frame in the run"; exit 1 }
      if (hd["outliers"] == "" || hd["outliers"] != 0) { print "link-bench: FAIL: the held axis did not hold (a measurement rejected: the bench plant or the loop)"; exit 1 }
      w = x["total"] * ipt
      if (mode == "full") {
        printf "  deadline: worst period %.0f instructions, budget %.0f (%s%% of %.0f cycles, target/mps2/budget.txt): %s\n", w, lim, share, cyc, (w <= lim) ? "within" : "OVER"
        if (w > lim) { print "link-bench: FAIL: a period with full telemetry is over the deadline budget"; exit 1 }
      }
    }' "$out/qemu_link_$mode.log" || rc=1
done
exit $rc
