#!/usr/bin/env bash
# One lease of one GPU (nvidia-h200), issue 39 item 5: a pack's batches stepped with one launch pair per config
# (kage::step_together) against the launches per batch and part of the commit before (BEFORE, carried as
# build-before-src: `git archive 40a502f` without results/, lab/20*/ and tests/). Run from the repository root
# with carry [".deps", "build-before-src"]. PART picks the call:
#   PART=tests COMMIT=... bash lab/2026-11-29-h200-grouped-steps/lease_device.sh   # build, the GPU tests
#   PART=after COMMIT=... bash lab/2026-11-29-h200-grouped-steps/lease_device.sh   # the rates of this tree
#   PART=before COMMIT=... bash lab/2026-11-29-h200-grouped-steps/lease_device.sh  # build BEFORE, its rates
set -uo pipefail
: "${COMMIT:?COMMIT=<the commit of this tree>}"
OUT=${OUT:-/tmp/kage-device-out}
here=$PWD
mkdir -p "$OUT"
export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
mix4="configs/kage_bench/bases/image_skeleton.yaml configs/kage_bench/filters/1-eval.yaml
      configs/kage_bench/filters/4-eval.yaml configs/kage_bench/effects/1-eval.yaml"
speed=(python3 -m kage.bench speed --warmup 2 --iterations 4 --device cuda --bf16 --fused-input --cuda-graph
       --triton-conv --eval-config-path configs/kage_bench/filters/1-eval.yaml)
rates() {  # $1: the label; K = 16 and 32, one config then the mixture of four
  for k in 16 32; do
    # shellcheck disable=SC2086
    for train in "--train-config-path configs/kage_bench/bases/image_skeleton.yaml" "--train-config-paths $mix4"; do
      echo "== $1 K=$k $(date -u +%T) $train" | tee -a "$OUT/speed.log"
      timeout 150 "${speed[@]}" --packs $k $train --json "$OUT/speed_$1.jsonl" 2>&1 |
        grep -v '^iteration\|^kage.ppo.train' | tee -a "$OUT/speed.log" | tail -3
    done
  done
}
case "${PART:?PART=tests, after or before}" in
tests)
  source lab/tools/device_build.sh >/dev/null || exit 1
  timeout 420 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_step_batches_gpu.py \
    tests/gpu/test_step_graph_gpu.py tests/gpu/test_mixture_gpu.py tests/gpu/test_gpu_vec.py \
    tests/gpu/test_train_mixture_gpu.py >"$OUT/gpu_tests.log" 2>&1
  echo "gpu tests: exit $?" >>"$OUT/gpu_tests.log"
  tail -5 "$OUT/gpu_tests.log"
  ;;
after)
  source lab/tools/device_build.sh >/dev/null || exit 1
  # shellcheck disable=SC2086
  timeout 100 python3 lab/tools/mixture_speed.py --configs $mix4 --num-envs 16384 >"$OUT/mixture_speed.log" 2>&1
  tail -6 "$OUT/mixture_speed.log"
  rates after
  ;;
before)
  cd "$here/build-before-src" || exit 1
  ln -sfn "$here/.deps" .deps
  main_out=$OUT OUT=$OUT/before
  source lab/tools/device_build.sh >/dev/null || exit 1
  OUT=$main_out
  rates before
  ;;
esac
exit 0
