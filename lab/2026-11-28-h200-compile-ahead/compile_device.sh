#!/usr/bin/env bash
# kage.compile_kernels on a GPU: tests/gpu/test_compile_kernels_gpu.py after compile_probe.py (compile_kernels and
# make_vec from empty kernel caches, wall and CPU time). Run on a fresh machine (the device's NVRTC reuses what it
# compiled before, across processes: see the record), from the repository root with carry [".deps"]:
#   bash lab/2026-11-28-h200-compile-ahead/compile_device.sh
set -uo pipefail
source lab/tools/device_build.sh || exit 1
log=$OUT/compile.log
cat "$OUT/gpu.txt" >"$log" && rm -f "$OUT/gpu.txt" "$OUT/build.log"
# The probe first: the test compiles some of its configs.
echo "== compile_probe.py" >>"$log"
timeout 200 python3 lab/2026-11-28-h200-compile-ahead/compile_probe.py >>"$log" 2>&1
echo "rc=$? ($(date -u +%H:%M:%S) UTC)" >>"$log"
echo "== tests/gpu/test_compile_kernels_gpu.py ($(date -u +%H:%M:%S) UTC)" >>"$log"
timeout 240 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_compile_kernels_gpu.py >>"$log" 2>&1
echo "rc=$? ($(date -u +%H:%M:%S) UTC)" >>"$log"
cat "$log"
