#!/usr/bin/env bash
# One device-machine call of the whole KAGE-Bench table (issue 27). Builds (lab/tools/device_build.sh), then
# trains `kage.bench run kage_bench --seeds 1-10 --share-training --pack PACK` with the trainer flags FLAGS, in
# DIR on the machine's disk, for at most LIMIT seconds of the call:
# - GPUS=all (a machine of several GPUs): every task, one worker per GPU (`--gpus all`);
# - TASK=I: task I alone, on one GPU.
# A call stopped by LIMIT leaves the runs' checkpoints in DIR, and the next call of the same lease resumes them
# (the disk goes with the lease, so size PACK for one lease). Each task is packed as soon as all its runs have
# finished: its run data without checkpoints, in $OUT/task_I.tar.gz and $OUT/task_I.sha256
# (lab/tools/pack_task.py), so a call cut short still brings its finished tasks home. Copy them into the table's
# results folder at once. A task index names the same runs in every lease (kage.bench.tasks), and DIR must be
# the same path in every lease, since bench.json records it. Run with carry [".deps"]:
#   GPUS=all PACK=6 bash lab/tools/table_device.sh
#   TASK=0 PACK=6 bash lab/tools/table_device.sh
set -uo pipefail
if [ -n "${GPUS:-}" ]; then scope=(--gpus "$GPUS"); else scope=(--task "${TASK:?GPUS=all or TASK=I}"); fi
source lab/tools/device_build.sh
PACK=${PACK:-6}
DIR=${DIR:-/tmp/kage-table}
LIMIT=${LIMIT:-570}
FLAGS=${FLAGS:---bf16 --fused-input --cuda-graph --triton-conv}
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}  # compiled kernels kept for the lease
pack_new() { python3 lab/tools/pack_task.py "$DIR" new "$OUT"; }
left=$((LIMIT - SECONDS - 75))  # 75 s to stop (SIGTERM ends the iteration or evaluation point, then checkpoints)
if [ "$left" -gt 60 ]; then
  # shellcheck disable=SC2086
  timeout --signal=TERM --kill-after=45 "$left" python3 -m kage.bench run kage_bench --seeds 1-10 \
    --share-training --pack "$PACK" "${scope[@]}" --out "$DIR" $FLAGS >"$OUT/run.log" 2>&1 &
  runner=$!
  while kill -0 "$runner" 2>/dev/null; do sleep 10; pack_new; done
  wait "$runner"
  grep -v '^iteration' "$OUT/run.log" | tail -30
fi
pack_new
python3 -m kage.bench status "$DIR" 2>&1 | tail -25
