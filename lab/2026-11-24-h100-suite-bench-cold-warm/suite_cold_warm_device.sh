#!/usr/bin/env bash
# One device-machine call: the GPU bench of the whole suite on an empty kernel cache (every config compiled
# by NVRTC, in parallel), then again on the filled cache; wall times and the rows each printed. Carry
# [".deps"]:
#   bash lab/2026-11-24-h100-suite-bench-cold-warm/suite_cold_warm_device.sh
set -uo pipefail
source lab/tools/device_build.sh
rm -rf "$KAGE_CACHE_DIR"
for run in cold warm; do
  start=$(date +%s%N)
  "$BUILD"/kagec bench suites/kage_bench.yaml --gpu --min-log2 14 --max-log2 14 >"$OUT/$run.txt" 2>"$OUT/$run.err"
  status=$?
  end=$(date +%s%N)
  rows=$(grep -c '^| ' "$OUT/$run.txt")
  printf '%s: exit %d, %d.%d s, %d table lines (header and separator included)\n' "$run" "$status" \
    $(((end - start) / 1000000000)) $(((end - start) / 100000000 % 10)) "$rows" | tee -a "$OUT/summary.txt"
done
tail -5 "$OUT/cold.err"
