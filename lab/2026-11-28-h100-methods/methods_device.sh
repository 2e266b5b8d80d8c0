#!/usr/bin/env bash
# Issues 39 and 40 on one lease of four GPUs, three calls back to back (carry [".deps", ".old-ppo"]):
#   COMMIT=$(git rev-parse --short HEAD) CALL=1 bash lab/2026-11-28-h100-methods/methods_device.sh
# .old-ppo holds python/kage/ppo/train.py and evaluation.py of the commit before kage.ppo.streams (every batch on
# the legacy default stream), for the trainer's speed before and after on the same machine.
# Every call: the methods, each a runner (lab/tools/table_device.sh) of the filters and effects pairs of
# suites/kage_bench.yaml (all train on IMAGE_SKELETON; under --share-training two trainings per seed, one evaluated
# on filters/1-9 and effects/1, one on effects/2-3), seeds 1-5, the protocol's 25 M steps, the table's flags and one
# augmentation: GPU 1 drac colour jitter, GPU 2 drac random convolution, GPU 3 rollout colour jitter (started by
# call 1), GPU 0 drac overlay (started by call 2, after GPU 0's measurements).
# Call 1 also, on GPU 0: the GPU tests of the trainer on mixtures, of mixtures and of resume; the mixture's stepping
# rate (lab/tools/mixture_speed.py). Call 2, on GPU 0 first: the trainer's rate at K = 16 on IMAGE_SKELETON and on a
# mixture of four, with and without a stream per run. Calls 2 and 3 wait (LIMIT seconds). Every call brings home, in
# one archive, every runner's finished tasks (pack_task.py, with checksums and provenance) and every run's log so far.
set -uo pipefail
: "${COMMIT:?COMMIT=<the commit of this tree>}" "${CALL:?CALL=1, 2 or 3}"
OUT=${OUT:-/tmp/kage-device-out}
ROOT=/tmp/kage-table-tree
FIRST=configs/kage_bench/filters
PAIRS="filters/1 filters/2 filters/3 filters/4 filters/5 filters/6 filters/7 filters/8 filters/9 effects/1 effects/2 effects/3"
TABLE="--bf16 --fused-input --cuda-graph --triton-conv"
MIX4="configs/kage_bench/bases/image_skeleton.yaml $FIRST/1-eval.yaml $FIRST/4-eval.yaml configs/kage_bench/effects/1-eval.yaml"
declare -A GPU=([drac_color_jitter]=1 [drac_random_conv]=2 [rollout_color_jitter]=3 [drac_overlay]=0)
declare -A AUG=([drac_color_jitter]="color_jitter --augment-mode drac" [drac_random_conv]="random_conv --augment-mode drac"
                [rollout_color_jitter]="color_jitter --augment-mode rollout" [drac_overlay]="overlay --augment-mode drac")
runner() {  # runner NAME LIMIT: starts (or waits for, and packs) method NAME's runner
  mkdir -p "$OUT/$1"
  OUT=$OUT/$1 GPUS=${GPU[$1]} SUITE=kage_bench SEEDS=1-5 PACK=5 DIR=/tmp/kage-m-$1 PUBLISHED=results/methods/none \
    PAIRS=$PAIRS LIMIT=$2 FLAGS="$TABLE --augment kage.ppo.augment:${AUG[$1]}" bash lab/tools/table_device.sh >/dev/null
}
summary() {  # each runner's call log and status, into one file
  { date -u +"call $CALL ends %H:%M:%S UTC"; for name in "${!GPU[@]}"; do
      echo "== $name"; tail -25 "$OUT/$name/call.log" 2>/dev/null; rm -f "$OUT/$name/call.log"; done; } >>"$OUT/call$CALL.log"
}
if [ "$CALL" = 1 ]; then
  for name in drac_color_jitter drac_random_conv rollout_color_jitter; do runner "$name" 20; done
  cd "$ROOT" || exit 1
  source lab/tools/device_build.sh >/dev/null
  export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
  timeout 270 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_train_mixture_gpu.py tests/gpu/test_mixture_gpu.py \
    tests/gpu/test_resume_gpu.py >"$OUT/gpu_tests.log" 2>&1
  echo "gpu tests: exit $? ($(date -u +%H:%M:%S) UTC)" >>"$OUT/gpu_tests.log"
  echo "== the mixture's stepping rate" >>"$OUT/speed.log"
  # shellcheck disable=SC2086
  timeout 80 python3 lab/tools/mixture_speed.py --configs $MIX4 --num-envs 16384 --json "$OUT/mixture_speed.json" \
    >>"$OUT/speed.log" 2>&1
  cd - >/dev/null || exit 1
  unset CUDA_VISIBLE_DEVICES  # the runners name their GPU
  summary
fi
if [ "$CALL" = 2 ]; then
  cd "$ROOT" || exit 1
  source lab/tools/device_build.sh >/dev/null
  export CUDA_VISIBLE_DEVICES=0 TRITON_CACHE_DIR=/tmp/kage-triton-cache
  old=/tmp/kage-default-stream  # the package with every batch on the default stream (the commit before)
  rm -rf "$old" && cp -a "$PYTHONPATH" "$old" && cp .old-ppo/train.py .old-ppo/evaluation.py "$old/kage/ppo/" || exit 1
  # shellcheck disable=SC2206
  SPEED=(timeout 100 python3 -m kage.bench speed --packs 16 --iterations 5 --device cuda $TABLE
         --eval-config-path $FIRST/1-eval.yaml)
  for variant in stream_per_run default_stream; do
    path=$PYTHONPATH; [ "$variant" = default_stream ] && path=$old
    echo "== $variant: one config" >>"$OUT/speed.log"
    PYTHONPATH=$path "${SPEED[@]}" --train-config-path configs/kage_bench/bases/image_skeleton.yaml \
      --json "$OUT/trainer_speed.jsonl" >>"$OUT/speed.log" 2>&1
    echo "== $variant: a mixture of four" >>"$OUT/speed.log"
    # shellcheck disable=SC2086
    PYTHONPATH=$path "${SPEED[@]}" --train-config-paths $MIX4 --json "$OUT/trainer_speed.jsonl" >>"$OUT/speed.log" 2>&1
  done
  cd - >/dev/null || exit 1
  unset CUDA_VISIBLE_DEVICES  # the runners name their GPU
  runner drac_overlay 20
  runner drac_color_jitter $((${LIMIT:-560} - SECONDS))
  summary
fi
if [ "$CALL" = 3 ]; then
  runner drac_color_jitter "${LIMIT:-450}"
  for name in drac_random_conv rollout_color_jitter drac_overlay; do runner "$name" 20; done
  summary
fi
# Every call brings home every run's log so far, finished or not: a machine given back between calls (idle over
# its release time) takes the runs with it, as it did once between calls 2 and 3.
for name in "${!GPU[@]}"; do
  [ -d "/tmp/kage-m-$name" ] || continue
  (cd "/tmp/kage-m-$name" && tar czf "$OUT/$name/runs_so_far.tar.gz" --exclude=checkpoints --exclude=tensorboard \
    --exclude='*.lock' bench.json suite.json runner.log runner.calls tasks.json runs tasks/*.log 2>/dev/null)
done
(cd "$OUT" && tar cf methods.tar drac_* rollout_* && rm -rf drac_* rollout_*)
tail -80 "$OUT/call$CALL.log"
