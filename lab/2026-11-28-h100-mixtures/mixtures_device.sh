#!/usr/bin/env bash
# Issue 39, items 5 and 6, on a lease of four GPUs (carry [".deps"]), first call:
# - GPUs 1-3: the leave-one-out suite's filters pairs, seeds 1-5, in the background (lab/tools/table_device.sh,
#   which copies the tree, builds it and starts the runner; later calls of table_device.sh with the same settings
#   wait for it and bring the packs home);
# - GPU 0, in the same tree and build: the GPU tests of mixtures and augmentation, the mixture's stepping rate
#   against its parts' (lab/tools/mixture_speed.py) and the trainer's at K = 16 on one config and on a mixture of
#   four (kage.bench speed), each into $OUT.
#   COMMIT=$(git rev-parse --short HEAD) bash lab/2026-11-28-h100-mixtures/mixtures_device.sh
set -uo pipefail
: "${COMMIT:?COMMIT=<the commit of this tree>}"
OUT=${OUT:-/tmp/kage-device-out}
mkdir -p "$OUT"
export GPUS=1,2,3 SUITE=kage_bench_loo SEEDS=1-5 PACK=${PACK:-15} DIR=/tmp/kage-loo PUBLISHED=results/methods/none
export PAIRS="filters/1 filters/2 filters/3 filters/4 filters/5 filters/6 filters/7 filters/8 filters/9"
export FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --total-timesteps ${STEPS:-12500000}"
LIMIT=30 bash lab/tools/table_device.sh  # returns once the runner has started
mv "$OUT/call.log" "$OUT/runner_start.log"
cd /tmp/kage-table-tree || exit 1
source lab/tools/device_build.sh >/dev/null  # the build table_device.sh made: nothing to do
export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
python3 -m pytest -q -p no:cacheprovider tests/gpu/test_mixture_gpu.py tests/gpu/test_augment_gpu.py \
  >"$OUT/gpu_tests.log" 2>&1
echo "gpu tests: exit $?" >>"$OUT/gpu_tests.log"
MIX4="configs/kage_bench/bases/image_skeleton.yaml configs/kage_bench/filters/1-eval.yaml
      configs/kage_bench/filters/4-eval.yaml configs/kage_bench/effects/1-eval.yaml"
# shellcheck disable=SC2086
python3 lab/tools/mixture_speed.py --configs $MIX4 --num-envs 16384 >"$OUT/mixture_speed.log" 2>&1
SPEED=(python3 -m kage.bench speed --packs 16 --iterations 5 --device cuda --bf16 --fused-input --cuda-graph
       --triton-conv --eval-config-path configs/kage_bench/filters/1-eval.yaml)
{
  echo "one config:"
  "${SPEED[@]}" --train-config-path configs/kage_bench/bases/image_skeleton.yaml --json "$OUT/speed.jsonl"
  echo "a mixture of four:"
  # shellcheck disable=SC2086
  "${SPEED[@]}" --train-config-paths $MIX4 --json "$OUT/speed.jsonl"
} >"$OUT/trainer_speed.log" 2>&1
tail -3 /tmp/kage-loo/runner.log >>"$OUT/runner_start.log"
