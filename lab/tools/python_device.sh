#!/usr/bin/env bash
# One device-machine call for the Python package: build (lab/tools/device_build.sh), then the GPU tests
# (tests/gpu) and the Python step loop beside `kagec bench --gpu`, logging under $OUT.
# Make .deps here first (lab/tools/make_deps.sh), then run with carry [".deps"]:
#   bash lab/tools/python_device.sh [CONFIG ...]
set -uo pipefail
source lab/tools/device_build.sh
python3 -m pytest -q -p no:cacheprovider tests/gpu 2>&1 | tee "$OUT/gpu_tests.log"
configs=("$@")
[ ${#configs[@]} -eq 0 ] && configs=(configs/throughput/simplest.yaml configs/kage_bench/filters/3-eval.yaml)
python3 lab/tools/python_step_loop.py "${configs[@]}" 2>&1 | tee "$OUT/python_loop.log"
for c in "${configs[@]}"; do
  "$BUILD/kagec" bench "$c" --gpu --min-log2 14 --max-log2 14 2>&1 | tee -a "$OUT/kagec_bench.log"
done
