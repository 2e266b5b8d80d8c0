#!/usr/bin/env bash
# kage.compile_kernels on a GPU: tests/gpu/test_compile_kernels_gpu.py, then lab/tools/compile_speed.py on CONFIGS
# (default: the 6 eval configs of the effects and first filters pairs with their train config), each from an empty
# kernel cache. Run from the repository root with carry [".deps"]:
#   bash lab/2026-11-28-h200-compile-ahead/compile_device.sh
set -uo pipefail
source lab/tools/device_build.sh || exit 1
bench=configs/kage_bench
CONFIGS=${CONFIGS:-"$bench/bases/image_skeleton.yaml $bench/effects/1-eval.yaml $bench/effects/2-eval.yaml
  $bench/effects/3-eval.yaml $bench/filters/1-eval.yaml $bench/filters/2-eval.yaml"}
log=$OUT/compile.log
cat "$OUT/gpu.txt" >"$log" && rm -f "$OUT/gpu.txt" "$OUT/build.log"
echo "== tests/gpu/test_compile_kernels_gpu.py ($(date -u +%H:%M:%S) UTC)" >>"$log"
timeout 240 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_compile_kernels_gpu.py >>"$log" 2>&1
echo "rc=$? ($(date -u +%H:%M:%S) UTC)" >>"$log"
echo "== lab/tools/compile_speed.py" >>"$log"
# shellcheck disable=SC2086
timeout 280 python3 lab/tools/compile_speed.py $CONFIGS >>"$log" 2>&1
echo "rc=$? ($(date -u +%H:%M:%S) UTC)" >>"$log"
cat "$log"
