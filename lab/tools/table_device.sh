#!/usr/bin/env bash
# One device-machine call of the whole KAGE-Bench table (issue 27). Builds (lab/tools/device_build.sh), then
# trains task TASK of the table, `kage.bench run kage_bench --seeds 1-10 --share-training --pack PACK --task
# TASK` with the trainer flags FLAGS, in DIR on the machine's disk, for at most LIMIT seconds of the call. A call
# stopped by LIMIT leaves the runs' checkpoints in DIR, and the next call of the same lease resumes them (the
# disk goes with the lease, so size PACK for one lease). When every run of the task has finished, it packs the
# task's run data without checkpoints into $OUT/task_TASK.tar.gz and $OUT/task_TASK.sha256
# (lab/tools/pack_task.py): copy both into the table's results folder at once. A task index names the same
# runs in every lease (kage.bench.tasks), and DIR must be the same path in every lease, since bench.json
# records it. Run with carry [".deps"]:
#   TASK=0 PACK=6 bash lab/tools/table_device.sh
set -uo pipefail
: "${TASK:?TASK=I: the task of the table to train (0 to the number of tasks - 1)}"
source lab/tools/device_build.sh
PACK=${PACK:-6}
DIR=${DIR:-/tmp/kage-table}
LIMIT=${LIMIT:-570}
FLAGS=${FLAGS:---bf16 --fused-input --cuda-graph --triton-conv}
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}  # compiled kernels kept for the lease
left=$((LIMIT - SECONDS - 90))  # 90 s to stop (SIGTERM ends the iteration or evaluation point, then checkpoints) and pack
if [ "$left" -gt 60 ]; then
  # shellcheck disable=SC2086
  timeout --signal=TERM --kill-after=60 "$left" python3 -m kage.bench run kage_bench --seeds 1-10 --share-training \
    --pack "$PACK" --task "$TASK" --out "$DIR" $FLAGS 2>&1 | grep -v '^iteration' | tail -15
fi
python3 -m kage.bench status "$DIR" 2>&1 | tail -15
python3 lab/tools/pack_task.py "$DIR" "$TASK" "$OUT" || echo "task $TASK not finished: call again in this lease to resume"
