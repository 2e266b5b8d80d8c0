#!/usr/bin/env bash
# One lease of one GPU, two tasks of DrAC colour jitter's `--pack 5` (issue 40) trained side by side: task 3
# (background/6) and task 4 (background/7), seeds 1-5, each by its own runner of lab/tools/table_device.sh (its own
# DIR and OUT folder), from the .before tree (d0be770, the code the method's other tasks were trained with). Both
# runners share the one GPU; task 3 comes first: if the two together would not finish inside the lease, PART=solo
# stops task 4's runner and lets task 3 train alone.
# PART (one a call; make the next call at once, the device gives the machine back 30 s after a call):
#   both   the first call builds .before's tree and starts both runners; every call waits for them, packing each
#          task as it finishes
#   park   task 4 alone for PARK_AT s, then stopped and its folder brought home with its checkpoints
#   solo   stops task 4's runner (SIGTERM: it stops its trainer), then waits for task 3
# Every call writes $OUT/progress.log: the UTC time and each task's last trainer line, every 30 s.
# Prepare here: git archive d0be770 -- . ':!results' ':!lab/2026*' | tar -x -C .before; move
# results/kage-bench-table out of the working tree for the calls (64 MiB); carry [".deps", ".before"].
set -uo pipefail
OUT=${OUT:-/tmp/kage-device-out}
FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter --augment-mode drac"
dir_of() { if [ "$1" = 3 ]; then echo /tmp/kage-m-drac_color_jitter; else echo "/tmp/kage-m-drac_color_jitter-$1"; fi; }
table() {  # TASK LIMIT MAX_FILES: the runner's table_device.sh call, from the .before tree, its output in $OUT/tTASK
  ln -sfn "$PWD/.deps" .before/.deps  # absolute: table_device.sh copies the tree to its ROOT
  (cd .before && OUT=$OUT/t$1 BUILD=build-runner COMMIT=d0be770 TASK=$1 SUITE=kage_bench SEEDS=1-5 PACK=5 \
     DIR=$(dir_of "$1") PUBLISHED=none FLAGS="$FLAGS" LIMIT=$2 MAX_FILES=$3 bash lab/tools/table_device.sh)
}
progress() {  # every 30 s until killed: each task's last trainer line
  while true; do
    { date -u +%H:%M:%S
      for task in 3 4; do echo "  task $task: $(tail -n1 "$(dir_of $task)/packs/task_${task}_pack_0.log" 2>/dev/null)"; done
    } >>"$OUT/progress.log"
    sleep 30
  done
}
both() {  # LIMIT: both runners' calls side by side; task 4's starts once task 3's has built and started its
  # runner, and 20 s later at least (the build folder is shared: no two builds at once)
  local start=$SECONDS
  table 3 "$1" 4 &
  local first=$!
  sleep 20
  until [ -s "$(dir_of 3)/runner.pid" ] || ! kill -0 $first 2>/dev/null; do sleep 5; done
  table 4 $(($1 - (SECONDS - start))) 3
  wait $first  # not a bare wait: progress runs till the end
}
mkdir -p "$OUT"
progress &
progress_pid=$!
trap 'kill $progress_pid 2>/dev/null' EXIT
case ${PART:?PART=both or solo} in
  both)
    both 560 ;;
  solo)
    pid=$(cat "$(dir_of 4)/runner.pid") && kill "$pid"  # the runner stops its trainer (a session of its own)
    for _ in $(seq 30); do kill -0 "$pid" 2>/dev/null || break; sleep 1; done
    kill -0 "$pid" 2>/dev/null && echo "task 4's runner $pid still runs" || echo "stopped task 4's runner $pid"
    table 3 560 4 ;;
  park)  # the lease's end: task 4 trains alone until PARK_AT s, then stops; its DIR, checkpoints included, comes
    # home as $OUT/task4_dir.tar.gz.* (15 MB parts), for a later lease to carry and resume
    table 4 "${PARK_AT:?PARK_AT=seconds}" 3
    pid=$(cat "$(dir_of 4)/runner.pid") && kill "$pid"
    for _ in $(seq 60); do kill -0 "$pid" 2>/dev/null || break; sleep 1; done
    python3 -m kage.bench status "$(dir_of 4)"
    tar czf - -C /tmp "$(basename "$(dir_of 4)")" | split -b 15M - "$OUT/task4_dir.tar.gz."
    ls -la "$OUT" ;;
esac
