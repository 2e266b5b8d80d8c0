#!/usr/bin/env bash
# One lease: the rollout colour-jitter method's table (lab/tools/table_device.sh, the tasks named in TASKS), with
# kage.step_batches checked on the GPU before any run uses it, and, once a GPU is idle, the GPU tests and the
# evaluation's speed before and after kage.step_batches. Run from the repository root with carry [".deps",
# ".old-ppo"] (.old-ppo: python/kage/ppo/evaluation.py and train.py of the commit before kage.step_batches):
#   CALL=1 COMMIT=... TASKS=0,1 bash lab/2026-11-28-h200-rollout-jitter-table/lease_device.sh   # check, then start
#   CALL=2 COMMIT=... TASKS=0,1 bash ...                                                  # wait and pack
#   CALL=3 IDLE_GPU=0 COMMIT=... TASKS=0,1 bash ...        # wait and pack; the tests and speed on IDLE_GPU
set -uo pipefail
here=$PWD
ROOT=/tmp/kage-table-tree
export ROOT OUT=${OUT:-/tmp/kage-device-out}
FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter --augment-mode rollout"
table=(env GPUS=all TASKS="${TASKS:-}" COMMIT="$COMMIT" SUITE=kage_bench SEEDS=1-5 PACK=13
       DIR=/tmp/kage-m-rollout_color_jitter PUBLISHED=results/methods/rollout_color_jitter/packs FLAGS="$FLAGS")
if [ "$CALL" = 1 ]; then
  rm -rf "$ROOT" && mkdir -p "$ROOT" && cp -a . "$ROOT" && touch "$ROOT/.copied" || exit 1
  (cd "$ROOT" && source lab/tools/device_build.sh >/dev/null &&
   CUDA_VISIBLE_DEVICES=0 timeout 240 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_step_batches_gpu.py) \
    >"$OUT/step_batches_gpu.log" 2>&1 ||
    { echo "lease: kage.step_batches failed on the GPU; the table is not started"; tail -40 "$OUT/step_batches_gpu.log"
      exit 1; }
  echo "step_batches on GPU 0 passed ($(date -u +%H:%M:%S) UTC)"
  exec "${table[@]}" LIMIT=$((565 - SECONDS)) bash lab/tools/table_device.sh
fi
if [ -n "${IDLE_GPU:-}" ]; then
  (cd "$ROOT" || exit 1
   # The lease's build, without device_build.sh, whose files in $OUT would take the packs' places.
   export LD_LIBRARY_PATH=$ROOT/.deps/usr/lib/x86_64-linux-gnu:/usr/local/cuda/lib64:${LD_LIBRARY_PATH:-}
   export PYTHONPATH=$ROOT/build-dev/python KAGE_CACHE_DIR=/tmp/kage-cache-tests TRITON_CACHE_DIR=/tmp/triton-tests
   log=$OUT/extras.log
   echo "== tests/gpu on GPU $IDLE_GPU ($(date -u +%H:%M:%S) UTC)" >"$log"
   CUDA_VISIBLE_DEVICES=$IDLE_GPU timeout 330 python3 -m pytest -q -p no:cacheprovider tests/gpu >>"$log" 2>&1
   echo "rc=$? ($(date -u +%H:%M:%S) UTC)" >>"$log"
   old=/tmp/kage-before-step-batches
   rm -rf "$old" && cp -a "$PYTHONPATH" "$old" && cp "$here"/.old-ppo/evaluation.py "$here"/.old-ppo/train.py "$old/kage/ppo/"
   pairs="background/9 filters/1 filters/2 filters/3 filters/4 filters/5 filters/6 filters/7 filters/8 filters/9"
   # shellcheck disable=SC2086
   evals=$(printf 'configs/kage_bench/%s-eval.yaml ' $pairs)
   labels=${pairs//\//_}  # two eval files share a name (9-eval.yaml): the trainer wants labels
   for variant in before after; do
     path=$PYTHONPATH; [ "$variant" = before ] && path=$old
     echo "== speed $variant kage.step_batches, GPU $IDLE_GPU ($(date -u +%H:%M:%S) UTC)" >>"$log"
     # shellcheck disable=SC2086
     CUDA_VISIBLE_DEVICES=$IDLE_GPU PYTHONPATH=$path timeout 150 python3 -m kage.bench speed --packs 10 --warmup 2 \
       --iterations 3 --json /tmp/speed_$variant.jsonl $FLAGS \
       --train-config-path configs/kage_bench/bases/image_skeleton.yaml --eval-config-paths $evals --eval-config-labels $labels >>"$log" 2>&1
     echo "rc=$?" >>"$log"; cat /tmp/speed_$variant.jsonl >>"$log" 2>/dev/null
   done) &
  extras=$!
fi
"${table[@]}" LIMIT=565 MAX_FILES=7 bash lab/tools/table_device.sh
[ -n "${extras:-}" ] && { wait "$extras"; tail -30 "$OUT/extras.log"; }
exit 0
