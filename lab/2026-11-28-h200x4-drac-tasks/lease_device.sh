#!/usr/bin/env bash
# One lease of four GPUs (nvidia-h200-x4), issue 40: DrAC colour jitter's tasks 0, 6, 7 and 8 of `--pack 5`
# (lab/tools/table_device.sh in DIR: one task a GPU, longest first), the GPU tests of the commits since the last
# lease beside them on GPU 3 (task 6, the lightest). Run from the repository root with carry [".deps"]. PART
# picks the call:
#   PART=start COMMIT=... bash lab/2026-11-28-h200x4-drac-tasks/lease_device.sh   # build, runner, GPU tests
#   PART=wait  COMMIT=... bash lab/2026-11-28-h200x4-drac-tasks/lease_device.sh   # wait for the runner, pack
set -uo pipefail
: "${COMMIT:?COMMIT=<the commit of this tree>}"
OUT=${OUT:-/tmp/kage-device-out}
mkdir -p "$OUT"
drac=(env COMMIT="$COMMIT" GPUS=all TASKS=0,6,7,8 SUITE=kage_bench SEEDS=1-5 PACK=5 DIR=/tmp/kage-m-drac_color_jitter
      PUBLISHED=results/methods/drac_color_jitter/packs OUT="$OUT/drac" MAX_FILES=5
      FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter --augment-mode drac")
case "${PART:?PART=start or wait}" in
start)
  "${drac[@]}" LIMIT=20 bash lab/tools/table_device.sh  # builds the tree's copy, starts the runner, returns
  cd /tmp/kage-table-tree || exit 1
  source lab/tools/device_build.sh >/dev/null || exit 1
  export CUDA_VISIBLE_DEVICES=3 TRITON_CACHE_DIR=/tmp/kage-triton-cache
  timeout 420 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_step_graph_gpu.py \
    tests/gpu/test_step_batches_gpu.py >"$OUT/gpu_tests.log" 2>&1
  echo "gpu tests: exit $?" >>"$OUT/gpu_tests.log"
  tail -3 "$OUT/gpu_tests.log"
  ;;
wait)
  "${drac[@]}" LIMIT=${LIMIT:-560} bash lab/tools/table_device.sh
  ;;
esac
exit 0
