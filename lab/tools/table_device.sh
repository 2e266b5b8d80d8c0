#!/usr/bin/env bash
# One device-machine call of the whole KAGE-Bench table (issue 27). Builds (lab/tools/device_build.sh), then
# trains `kage.bench run kage_bench --seeds 1-10 --share-training --pack PACK` with the trainer flags FLAGS, in
# DIR on the machine's disk, for at most LIMIT seconds of the call:
# - GPUS=all (a machine of several GPUs): every task, one worker per GPU (`--gpus all`);
# - TASK=I: task I alone, on one GPU.
# A lease's first call starts DIR from the tasks already published (results/kage-bench-table/packs, unpacked
# with their checksums), so that only the rest is trained. A call stopped by LIMIT leaves the runs' checkpoints
# in DIR, and the next call of the same lease resumes them (the disk goes with the lease, so size PACK for one
# lease). Each task is packed as soon as all its runs have finished: its run data without checkpoints, in
# $OUT/task_I.tar.gz and $OUT/task_I.sha256 (lab/tools/pack_task.py), so a call cut short still brings its
# finished tasks home; copy them into results/kage-bench-table/packs at once. $OUT holds at most MAX_FILES
# (the device's limit on the files a call brings back): the call's log, $OUT/call.log, and as many tasks as
# fit; a task left over is named, for the next call. A task index names the same runs in every lease
# (kage.bench.tasks), and DIR must be the same path in every lease, since bench.json records it. COMMIT names
# the tree's commit (the machine gets no .git) for the packs' provenance, beside the device and the command.
# Run with carry [".deps"]:
#   COMMIT=$(git rev-parse --short HEAD) GPUS=all PACK=6 bash lab/tools/table_device.sh
#   COMMIT=... TASK=0 PACK=6 bash lab/tools/table_device.sh
set -uo pipefail
if [ -n "${GPUS:-}" ]; then scope=(--gpus "$GPUS"); else scope=(--task "${TASK:?GPUS=all or TASK=I}"); fi
: "${COMMIT:?COMMIT=<the commit of this tree>: recorded in the checksum list of each pack}"
source lab/tools/device_build.sh
cat "$OUT/gpu.txt" >"$OUT/call.log" && rm -f "$OUT/gpu.txt" "$OUT/build.log"  # one log file: the build passed
PACK=${PACK:-6}
DIR=${DIR:-/tmp/kage-table}
LIMIT=${LIMIT:-570}
MAX_FILES=${MAX_FILES:-8}
FLAGS=${FLAGS:---bf16 --fused-input --cuda-graph --triton-conv}
PUBLISHED=results/kage-bench-table/packs
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}  # compiled kernels kept for the lease
if [ ! -e "$DIR/tasks.json" ] && compgen -G "$PUBLISHED/task_*.tar.gz" >/dev/null; then
  python3 lab/tools/table_unpack.py "$PUBLISHED" "$DIR" | tail -1 >>"$OUT/call.log" || exit 1
  mkdir -p "$DIR/packed"
  for archive in "$PUBLISHED"/task_*.tar.gz; do name=${archive##*/}; touch "$DIR/packed/${name%.tar.gz}"; done
fi
run=(python3 -m kage.bench run kage_bench --seeds 1-10 --share-training --pack "$PACK" "${scope[@]}" --out "$DIR")
devices=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | sort | uniq -c |
  sed -E 's/^ *([0-9]+) (.*), ([^,]*)$/\1 x \2 (driver \3)/' | paste -sd ';' -)  # 2 x NVIDIA H200 (driver 580.159.04)
KAGE_PACK_PROVENANCE=$(printf 'device: %s\ncommit: %s\ncommand: bash lab/tools/table_device.sh (runs: %s %s)' \
  "$devices" "$COMMIT" "${run[*]}" "$FLAGS")
export KAGE_PACK_PROVENANCE
pack_new() { python3 lab/tools/pack_task.py "$DIR" new "$OUT" "$MAX_FILES" >>"$OUT/call.log"; }
left=$((LIMIT - SECONDS - 75))  # 75 s to stop (SIGTERM ends the iteration or evaluation point, then checkpoints)
if [ "$left" -gt 60 ]; then
  # shellcheck disable=SC2086
  timeout --signal=TERM --kill-after=45 "$left" "${run[@]}" $FLAGS >>"$OUT/call.log" 2>&1 &
  runner=$!
  while kill -0 "$runner" 2>/dev/null; do sleep 10; pack_new; done
  wait "$runner"
fi
pack_new
python3 -m kage.bench status "$DIR" >>"$OUT/call.log" 2>&1
grep -v '^iteration' "$OUT/call.log" | tail -40
