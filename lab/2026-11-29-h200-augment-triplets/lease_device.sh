#!/usr/bin/env bash
# The augmentation pass per pixel triplet against the pass per element (the module as it was, carried as
# .before-aug/augment_kernel_before.py): kernel_speed.py on minibatches of K = 5 and 16 runs, the GPU equality
# tests, then kage.bench speed at K = 5 with DrAC random convolution's flags, with this tree's module and then
# with the one before copied over the build's. Run with carry [".deps", ".before-aug"].
set -uo pipefail
OUT=${OUT:-/tmp/kage-device-out}
mkdir -p "$OUT"
PYTHONPATH=$PWD/python PYTHONUNBUFFERED=1 python3 lab/2026-11-29-h200-augment-triplets/kernel_speed.py \
  .before-aug/augment_kernel_before.py 5 16 2>&1 | tee "$OUT/kernel_speed.md"
PYTHONPATH=$PWD/python python3 -m pytest -q -p no:cacheprovider tests/gpu/test_augment_gpu.py 2>&1 | tail -3 |
  tee "$OUT/gpu_tests.txt"
source lab/tools/device_build.sh
F="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:random_conv --augment-mode drac"
# shellcheck disable=SC2086
timeout 150 python3 -m kage.bench speed --packs 5 --device cuda $F >"$OUT/speed_after.txt" 2>&1
grep '^|' "$OUT/speed_after.txt"
cp .before-aug/augment_kernel_before.py "$BUILD/python/kage/ppo/fast/augment_kernel.py"
# shellcheck disable=SC2086
timeout 150 python3 -m kage.bench speed --packs 5 --device cuda $F >"$OUT/speed_before.txt" 2>&1
grep '^|' "$OUT/speed_before.txt"
