#!/usr/bin/env bash
# One lease of two GPUs (nvidia-h200-x2), issues 38 and 39: the step as a CUDA graph and a mixture's parts side by
# side, measured on GPU 0 while GPU 1 trains DrAC colour jitter's task 1 of `--pack 5` (image_skeleton part 1:
# filters/1-9 and background/9, seeds 1-5; lab/tools/table_device.sh in DIR, which later calls wait for and pack).
# Run from the repository root with carry [".deps", ".old-ppo"] (.old-ppo: python/kage/ppo/evaluation.py, train.py
# and streams.py of fa0c9ec, the package before the graphs, for the before/after rows). PART picks the call:
#   PART=start COMMIT=... bash lab/2026-11-28-h200-step-graphs/lease_device.sh   # build, runner on GPU 1, GPU tests
#   PART=speed COMMIT=... bash lab/2026-11-28-h200-step-graphs/lease_device.sh   # the rates, GPU 0
#   PART=wait  COMMIT=... bash lab/2026-11-28-h200-step-graphs/lease_device.sh   # wait for the runner, pack
set -uo pipefail
: "${COMMIT:?COMMIT=<the commit of this tree>}"
OUT=${OUT:-/tmp/kage-device-out}
here=$PWD
mkdir -p "$OUT"
drac=(env COMMIT="$COMMIT" GPUS=1 TASKS=1 SUITE=kage_bench SEEDS=1-5 PACK=5 DIR=/tmp/kage-m-drac_color_jitter
      PUBLISHED=results/methods/drac_color_jitter/packs OUT="$OUT/drac" MAX_FILES=4
      FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter --augment-mode drac")
case "${PART:?PART=start, speed or wait}" in
start)
  "${drac[@]}" LIMIT=20 bash lab/tools/table_device.sh  # builds the tree's copy, starts the runner, returns
  cd /tmp/kage-table-tree || exit 1
  source lab/tools/device_build.sh >/dev/null || exit 1
  export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
  timeout 330 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_step_graph_gpu.py tests/gpu/test_mixture_gpu.py \
    tests/gpu/test_step_batches_gpu.py tests/gpu/test_gpu_vec.py tests/gpu/test_rollout_graph.py \
    tests/gpu/test_train_mixture_gpu.py >"$OUT/gpu_tests.log" 2>&1
  echo "gpu tests: exit $?" >>"$OUT/gpu_tests.log"
  tail -3 "$OUT/gpu_tests.log"
  ;;
speed)
  cd /tmp/kage-table-tree || exit 1
  source lab/tools/device_build.sh >/dev/null || exit 1
  export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
  old=/tmp/kage-before-graphs
  rm -rf "$old" && cp -a "$PYTHONPATH" "$old" && cp "$here"/.old-ppo/*.py "$old/kage/ppo/" || exit 1
  mix4="configs/kage_bench/bases/image_skeleton.yaml configs/kage_bench/filters/1-eval.yaml
        configs/kage_bench/filters/4-eval.yaml configs/kage_bench/effects/1-eval.yaml"
  # shellcheck disable=SC2086
  timeout 100 python3 lab/tools/mixture_speed.py --configs $mix4 --num-envs 16384 >"$OUT/mixture_speed.log" 2>&1
  tail -8 "$OUT/mixture_speed.log"
  speed=(python3 -m kage.bench speed --packs 16 --warmup 2 --iterations 4 --device cuda --bf16 --fused-input
         --cuda-graph --triton-conv --eval-config-path configs/kage_bench/filters/1-eval.yaml)
  pairs="background/9 filters/1 filters/2 filters/3 filters/4 filters/5 filters/6 filters/7 filters/8 filters/9"
  evals=$(printf 'configs/kage_bench/%s-eval.yaml ' $pairs)
  for v in after before; do
    p=$PYTHONPATH; [ $v = before ] && p=$old
    echo "== $v $(date -u +%T): one config, then the mixture of four, K = 16" | tee -a "$OUT/speed.log"
    # shellcheck disable=SC2086
    for train in "--train-config-path configs/kage_bench/bases/image_skeleton.yaml" "--train-config-paths $mix4"; do
      PYTHONPATH=$p timeout 120 "${speed[@]}" $train --json "$OUT/speed_$v.jsonl" 2>&1 |
        grep -v '^iteration\|^kage.ppo.train' | tee -a "$OUT/speed.log" | tail -4
    done
    echo "== $v $(date -u +%T): K = 10, ten eval configs (image_skeleton part 1)" | tee -a "$OUT/speed.log"
    # shellcheck disable=SC2086
    PYTHONPATH=$p timeout 120 python3 -m kage.bench speed --packs 10 --warmup 2 --iterations 3 --device cuda --bf16 \
      --fused-input --cuda-graph --triton-conv --train-config-path configs/kage_bench/bases/image_skeleton.yaml \
      --eval-config-paths $evals --eval-config-labels ${pairs//\//_} --json "$OUT/speed_$v.jsonl" 2>&1 |
      grep -v '^iteration\|^kage.ppo.train' | tee -a "$OUT/speed.log" | tail -4
  done
  ;;
wait)
  "${drac[@]}" LIMIT=${LIMIT:-560} bash lab/tools/table_device.sh
  ;;
esac
exit 0
