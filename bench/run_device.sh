#!/usr/bin/env bash
# One device-machine call: build the GPU benchmark if no build was carried, then check (GPU vs CPU) and
# time everything, logging under $OUT. The asset blob (build-bench/data/assets.bin) is made here with
# kage_asset_blob (it needs image decoders) and carried along with the build.
# Usage on the device: bash bench/run_device.sh [kage_gpu_bench options]
set -uo pipefail
OUT=${OUT:-/tmp/kage-bench-out}
BUILD=${BUILD:-build-bench}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv >"$OUT/gpu.txt" 2>&1
cat "$OUT/gpu.txt"
if [ ! -x "$BUILD/bench/kage_gpu_bench" ]; then
  cmake -S . -B "$BUILD" -G Ninja -DKAGE_BUILD_FRONTEND=OFF -DCMAKE_BUILD_TYPE=Release >"$OUT/build.log" 2>&1 &&
    ninja -C "$BUILD" kage_gpu_bench >>"$OUT/build.log" 2>&1 || { tail -50 "$OUT/build.log"; exit 1; }
fi
# NVRTC is opened at run time; the toolkit directory is often not on the loader path.
export LD_LIBRARY_PATH=/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
export KAGE_CACHE_DIR=/tmp/kage-cache
rm -rf "$KAGE_CACHE_DIR"
"$BUILD/bench/kage_gpu_bench" "$BUILD/bench" "$BUILD/data/assets.bin" --nvrtc-root "$PWD" "$@" 2>&1 | tee "$OUT/bench.log"
exit "${PIPESTATUS[0]}"
