#!/usr/bin/env bash
# One device-machine call: build the GPU benchmark if no build was carried, then check (GPU vs CPU),
# time loading and stepping, logging under $OUT. The configs are `kagec compile` output directories
# (bench-data/simplest, bench-data/hardest by default: the device build has no front end, so carry
# them), made here with: kagec compile configs/throughput/NAME.yaml -o bench-data/NAME --no-host
# Usage on the device: bash lab/tools/run_device.sh [kage_gpu_throughput options]  (BENCH_DIRS: the dirs)
# Every shipped config (generic build vs CPU): kagec compile CFG -o bench-data/all/ID --no-gpu --no-host here,
# then on the device: BENCH_DIRS="bench-data/all/*" bash lab/tools/run_device.sh --check-only --check-envs 32
set -uo pipefail
OUT=${OUT:-/tmp/kage-bench-out}
BUILD=${BUILD:-build-bench}
DIRS=${BENCH_DIRS:-bench-data/simplest bench-data/hardest}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem --format=csv >"$OUT/gpu.txt" 2>&1
cat "$OUT/gpu.txt"
if [ ! -x "$BUILD/verify/throughput/kage_gpu_throughput" ]; then
  # nlohmann-json (the manifest reader) comes from the carried .deps (lab/tools/make_deps.sh) when the machine lacks it.
  cmake -S . -B "$BUILD" -G Ninja -DKAGE_BUILD_FRONTEND=OFF -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$PWD/.deps/usr" >"$OUT/build.log" 2>&1 &&
    ninja -C "$BUILD" kage_gpu_throughput >>"$OUT/build.log" 2>&1 || { tail -50 "$OUT/build.log"; exit 1; }
fi
# NVRTC is opened at run time; the toolkit directory is often not on the loader path.
export LD_LIBRARY_PATH=/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
# An empty cache, so that the first NVRTC load of each config is cold.
export KAGE_CACHE_DIR=/tmp/kage-cache
rm -rf "$KAGE_CACHE_DIR"
# shellcheck disable=SC2086
"$BUILD/verify/throughput/kage_gpu_throughput" "$BUILD/verify/throughput/dynamic.fatbin" --compiled $DIRS \
  --nvrtc-root "$PWD" "$@" 2>&1 |
  tee "$OUT/bench.log"
exit "${PIPESTATUS[0]}"
