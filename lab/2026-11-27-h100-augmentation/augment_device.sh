#!/usr/bin/env bash
# The augmentation issue's GPU work in one lease of 4 GPUs, with run's carry [".deps"]:
# - CHECK=1 (any machine, one call): the build, tests/gpu/test_augment_gpu.py, and two iterations of the fast path
#   with color_jitter in each mode (kage.bench speed --packs 2), so that a mistake costs one short call;
# - otherwise the runner: three learning checks, IMAGE_SKELETON trained with color_jitter under update, rollout
#   and drac (seeds 1-4, one pack, evaluated on the nine filters pairs' eval configs, the table's flags, STEPS
#   steps: 10 M by default, what one lease holds beside the speed table) on GPUs 0-2, and the speed table
#   (kage.bench speed --packs 16 with the table's flags: the plain fast path, then each shipped augmentation under
#   update, rollout and drac, then the plain path again) on GPU 3, and on GPUs 0-2 once their check has ended.
#   It runs in a process session of its own (setsid) from a copy of the tree made by the first call, so it
#   trains on through the lease's calls; each call waits up to LIMIT seconds, then brings home what is there:
#   per mode a tarball of its runs' logs and report (no checkpoints), the learning summaries, the speed rows.
set -uo pipefail
ROOT=${ROOT:-/tmp/kage-augment-tree}
if [ ! -e "$ROOT/.copied" ]; then
  rm -rf "$ROOT" && mkdir -p "$ROOT" && cp -a . "$ROOT" && touch "$ROOT/.copied" || exit 1
fi
cd "$ROOT" || exit 1
source lab/tools/device_build.sh
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}
FAST="--bf16 --fused-input --cuda-graph --triton-conv"
RUNS=${RUNS:-/tmp/kage-augment}
LIMIT=${LIMIT:-570}
mkdir -p "$RUNS"
if [ -n "${CHECK:-}" ]; then
  python3 -m pytest -q -p no:cacheprovider tests/gpu/test_augment_gpu.py 2>&1 | tail -15 | tee "$OUT/gpu_tests.txt"
  # shellcheck disable=SC2086
  python3 -m kage.bench speed --packs ${CHECK_PACKS:-2} --warmup 1 --iterations 2 --device cuda $FAST 2>&1 |
    tail -1 | tee -a "$OUT/smoke.txt"
  for mode in update rollout drac; do
    # shellcheck disable=SC2086
    python3 -m kage.bench speed --packs ${CHECK_PACKS:-2} --warmup 1 --iterations 2 --device cuda $FAST \
      --augment kage.ppo.augment:color_jitter --augment-mode "$mode" 2>&1 | tail -1 | tee -a "$OUT/smoke.txt"
  done
  exit 0
fi
cat "$OUT/gpu.txt" >>"$OUT/call.log" && rm -f "$OUT/gpu.txt" "$OUT/build.log"  # one log: the build passed
pairs=(filters/1 filters/2 filters/3 filters/4 filters/5 filters/6 filters/7 filters/8 filters/9)
STEPS=${STEPS:-10000000}
runner_alive() { [ -s "$RUNS/runner.pid" ] && kill -0 "$(cat "$RUNS/runner.pid")" 2>/dev/null; }
if [ ! -e "$RUNS/runner.pid" ]; then
  # The speed table's jobs (kage.bench speed --packs 16, the table's flags): the plain fast path, each shipped
  # augmentation under update, rollout and drac, and the plain path again; GPU 3 takes them from the start, GPUs 0-2
  # once their learning check has ended, each job claimed by one worker (mkdir).
  jobs=("")
  for name in random_shift random_crop color_jitter grayscale random_conv cutout_color gaussian_noise overlay; do
    for mode in update rollout drac; do jobs+=("--augment kage.ppo.augment:$name --augment-mode $mode"); done
  done
  jobs+=("")
  printf '%s\n' "${jobs[@]}" >"$RUNS/speed_jobs.txt"
  mkdir -p "$RUNS/claimed"
  cat >"$RUNS/runner.sh" <<RUNNER
speed_worker() {
  local gpu=\$1 index=0
  while IFS= read -r flags; do
    if mkdir "$RUNS/claimed/\$index" 2>/dev/null; then
      echo "gpu \$gpu: speed job \$index (\$(date -u +%H:%M:%S)): \$flags"
      CUDA_VISIBLE_DEVICES=\$gpu python3 -m kage.bench speed --packs 16 --device cuda $FAST --json $RUNS/speed.jsonl \
        \$flags 2>&1 | grep '^| 16'
    fi
    index=\$((index + 1))
  done <"$RUNS/speed_jobs.txt"
}
learn_then_speed() {
  local gpu=\$1 mode=\$2
  CUDA_VISIBLE_DEVICES=\$gpu python3 -m kage.bench run kage_bench --pairs ${pairs[*]} --seeds 1-4 --share-training \
    --pack 4 --device cuda $FAST --total-timesteps $STEPS --augment kage.ppo.augment:color_jitter \
    --augment-mode \$mode --out $RUNS/\$mode >$RUNS/\$mode.log 2>&1
  echo "gpu \$gpu: \$mode learning check ended (\$(date -u +%H:%M:%S))"
  speed_worker \$gpu
}
learn_then_speed 0 update >>$RUNS/speed.log 2>&1 &
learn_then_speed 1 rollout >>$RUNS/speed.log 2>&1 &
learn_then_speed 2 drac >>$RUNS/speed.log 2>&1 &
(CUDA_VISIBLE_DEVICES=3 python3 -m pytest -q -p no:cacheprovider tests/gpu/test_augment_gpu.py >$RUNS/gpu_tests.txt 2>&1
 speed_worker 3) >>$RUNS/speed.log 2>&1 &
wait
date -u +%H:%M:%S >$RUNS/done
RUNNER
  echo "augment_device: starting the runner ($(date -u +%H:%M:%S) UTC)" | tee -a "$OUT/call.log"
  # shellcheck disable=SC2016
  CUDA_DEVICE_ORDER=PCI_BUS_ID setsid bash -c 'echo $$ >"$0/runner.pid" && exec bash "$0/runner.sh"' "$RUNS" \
    >"$RUNS/runner.log" 2>&1 </dev/null &
  sleep 5
fi
while runner_alive && [ ! -e "$RUNS/done" ] && [ "$SECONDS" -lt "$LIMIT" ]; do sleep 10; done
for mode in update rollout drac; do
  [ -d "$RUNS/$mode" ] || continue
  python3 -m kage.bench report "$RUNS/$mode" --partial >/dev/null 2>&1
  python3 lab/tools/learning_summary.py "$RUNS/$mode" >"$RUNS/$mode/learning_summary.txt" 2>&1
  tail -3 "$RUNS/$mode.log" | tr '\r' '\n' | tail -2 >>"$OUT/call.log"
  tar -czf "$OUT/$mode.tar.gz" -C "$RUNS" --exclude checkpoints --exclude tensorboard --exclude videos "$mode" "$mode.log"
done
cp "$RUNS/speed.log" "$RUNS/speed.jsonl" "$RUNS/gpu_tests.txt" "$OUT/" 2>/dev/null
if [ -e "$RUNS/done" ]; then echo "augment_device: the runner ended at $(cat "$RUNS/done") UTC" >>"$OUT/call.log"
else echo "augment_device: the runner trains on ($(date -u +%H:%M:%S) UTC); call again" >>"$OUT/call.log"; fi
