#!/usr/bin/env bash
# One device-machine call of the whole KAGE-Bench table (issue 27), or of another suite's (SUITE, SEEDS, PAIRS). The
# runner, `kage.bench run SUITE --seeds SEEDS [--pairs PAIRS] --share-training --pack PACK` with the trainer flags
# FLAGS (defaults: kage_bench, 1-10, every pair), trains in DIR on the machine's disk:
# - GPUS=all (a machine of several GPUs): every task, one worker per GPU (`--gpus all`), or with TASKS=0,3 only
#   those tasks (`--tasks`: what fits a lease, the others left for the next), TASKS=12+13 the two as one process
#   and one pack of their runs (a GPU that a pack of 5 leaves idle), each packed as its own task;
# - TASK=I: task I alone, on one GPU. Two runners side by side on one GPU train no faster together than one after
#   the other (lab/2026-11-29-h200-drac-two-tasks), and a task must finish inside the lease (its checkpoints, 58 MB a
#   run, cannot travel to the next): on one GPU, start the tasks that fit, one at a time.
# The runner runs in a process session of its own (setsid), which the device machine leaves running when a
# call returns, so it trains on through the lease's calls and the gaps between them, never stopped and resumed.
# It runs from a copy of the tree made by the lease's first call (ROOT), since every call copies the working
# tree afresh over the repository root, which must not change under a running process: a lease runs the code
# of its first call. That call builds (lab/tools/device_build.sh) and, with PUBLISHED=FOLDER, starts DIR from the
# tasks already published there (unpacked with their checksums), so that only the rest is trained. The packs
# published so far (results/) ran shape_black's and image_skeleton's pairs in two parts of at most 10 eval
# configs, which kage.bench run now refuses to extend (it runs them in one): the default, PUBLISHED=none, starts
# DIR empty.
# Every call then waits until LIMIT seconds of the call have passed or the runner has ended, packing each task
# as soon as all its runs have finished: its run data without checkpoints, in $OUT/task_I.tar.gz and
# $OUT/task_I.sha256 (lab/tools/pack_task.py), so a call brings home what finished since the last; publish them
# at once (`python3 lab/tools/packs_publish.py FILES_AT PACKS --note '...'`, PACKS results/kage-bench-table/packs
# or results/methods/METHOD/packs). Tasks past the file limit come in one file, $OUT/more_tasks.tar, which
# packs_publish.py publishes too. A call that finds no runner with tasks left (it failed, or the
# first call's ended) starts one again, which resumes the runs from their checkpoints. $OUT holds at most
# MAX_FILES (the device's limit on the files a call brings back): the call's log, $OUT/call.log (the build's
# lines, then the runner's since the last call), and the tasks, the last ones bundled; a finished task left over
# even so ends the call at once and is named, for the next call. Every call also brings home the unfinished runs' logs so far
# ($OUT/runs_so_far.tar.gz, one file of MAX_FILES): what the runner has not finished when the lease ends goes with
# the machine, but not its evaluations up to the last call. The device gives a machine back 30 s after a call
# returns: make the next call at once, or the runner and every unfinished run go with the machine. A task index
# names the same runs in every lease (kage.bench.tasks), and DIR must be the same path in every lease, since
# bench.json records it. COMMIT names the tree's commit (the machine gets no .git) for the
# packs' provenance, beside the device, the command (each call that started the runner, which trained the
# task), the call that packed it, and when it was trained and packed. A call copies the working tree and its carry,
# which must stay under the device's 64 MiB: the published run data outgrow that, so move every results/ folder
# (but PUBLISHED) out of the working tree for the lease's calls (the deletions are not committed) and back
# afterwards.
# Two suites or methods share a lease of several GPUs as two runners, each with its GPUS, DIR and a folder of the
# call's $OUT (OUT=$OUT/NAME; MAX_FILES split between them, 8 in all), started side by side in each call.
# Run with carry [".deps"]:
#   COMMIT=$(git rev-parse --short HEAD) GPUS=all PACK=6 bash lab/tools/table_device.sh
#   COMMIT=... TASK=0 PACK=6 bash lab/tools/table_device.sh
#   C="COMMIT=... SEEDS=1-5 PACK=5 LIMIT=570"; env $C OUT=$OUT/a MAX_FILES=4 GPUS=0,1 TASKS=3,4 DIR=/tmp/a
#     FLAGS="..." bash lab/tools/table_device.sh >/dev/null & env $C OUT=$OUT/b MAX_FILES=4 GPUS=2,3 TASKS=4,5
#     SUITE=kage_bench_loo DIR=/tmp/b FLAGS="..." bash lab/tools/table_device.sh; wait; tail -20 $OUT/a/call.log
set -uo pipefail
if [ -n "${GPUS:-}" ]; then scope=(--gpus "$GPUS" ${TASKS:+--tasks "$TASKS"}); else scope=(--task "${TASK:?GPUS=all or TASK=I}"); fi
: "${COMMIT:?COMMIT=<the commit of this tree>: recorded in the checksum list of each pack}"
ROOT=${ROOT:-/tmp/kage-table-tree}
# Two runners started side by side (their own DIR and OUT) copy and build one at a time: the second finds it done.
exec 9>"$ROOT.lock" && flock 9 || exit 1
if [ ! -e "$ROOT/.copied" ]; then
  rm -rf "$ROOT" && mkdir -p "$ROOT" && cp -a . "$ROOT" && touch "$ROOT/.copied" || exit 1
fi
cd "$ROOT" || exit 1
source lab/tools/device_build.sh  # incremental: builds once a lease, since ROOT does not change
flock -u 9 && exec 9>&-
cat "$OUT/gpu.txt" >"$OUT/call.log" && rm -f "$OUT/gpu.txt" "$OUT/build.log"  # one log file: the build passed
PACK=${PACK:-6}
DIR=${DIR:-/tmp/kage-table}
LIMIT=${LIMIT:-585}
MAX_FILES=${MAX_FILES:-8}
FLAGS=${FLAGS:---bf16 --fused-input --cuda-graph --triton-conv}
PUBLISHED=${PUBLISHED:-none}
SUITE=${SUITE:-kage_bench}
SEEDS=${SEEDS:-1-10}
export TRITON_CACHE_DIR=${TRITON_CACHE_DIR:-/tmp/kage-triton-cache}  # compiled kernels kept for the lease
if [ ! -e "$DIR/tasks.json" ] && compgen -G "$PUBLISHED/task_*.tar.gz" >/dev/null; then
  python3 lab/tools/table_unpack.py "$PUBLISHED" "$DIR" | tail -1 >>"$OUT/call.log" || exit 1
  mkdir -p "$DIR/packed"
  for archive in "$PUBLISHED"/task_*.tar.gz; do name=${archive##*/}; touch "$DIR/packed/${name%.tar.gz}"; done
fi
# shellcheck disable=SC2206
run=(python3 -m kage.bench run "$SUITE" --seeds "$SEEDS" ${PAIRS:+--pairs $PAIRS} --share-training --pack "$PACK"
     "${scope[@]}" --out "$DIR")
devices=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader | sort | uniq -c |
  sed -E 's/^ *([0-9]+) (.*), ([^,]*)$/\1 x \2 (driver \3)/' | paste -sd ';' -)  # 2 x NVIDIA H200 (driver 580.159.04)
# The exact call, its settings included: the one that started the runner is the command of what it trains.
call="COMMIT=$COMMIT ${GPUS:+GPUS=$GPUS }${TASKS:+TASKS=$TASKS }${TASK:+TASK=$TASK }SUITE=$SUITE SEEDS=$SEEDS ${PAIRS:+PAIRS='$PAIRS' }PACK=$PACK"
call+=" LIMIT=$LIMIT DIR=$DIR PUBLISHED=$PUBLISHED FLAGS='$FLAGS' bash lab/tools/table_device.sh"
pack_new() { python3 lab/tools/pack_task.py "$DIR" new "$OUT" "$MAX_FILES" >>"$OUT/call.log"; }
runner_alive() { [ -s "$DIR/runner.pid" ] && kill -0 "$(cat "$DIR/runner.pid")" 2>/dev/null; }
mkdir -p "$DIR"
runner_log=$DIR/runner.log
seen=$(stat -c %s "$runner_log" 2>/dev/null || echo 0)  # what earlier calls brought home
if ! runner_alive; then  # with every task finished, the runner says so and ends at once
  echo "table_device: starting the runner ($(date -u +%H:%M:%S) UTC)" >>"$runner_log"
  rm -f "$DIR/runner.pid"
  # The runner writes its own pid: setsid forks when it cannot make its caller a session leader.
  # shellcheck disable=SC2016,SC2086
  setsid bash -c 'echo $$ >"$0/runner.pid" && exec "$@"' "$DIR" "${run[@]}" $FLAGS >>"$runner_log" 2>&1 </dev/null &
  for _ in 1 2 3 4 5; do [ -s "$DIR/runner.pid" ] && break; sleep 1; done
  printf '%s (%s UTC)\n' "$call" "$(date -u +%H:%M)" >>"$DIR/runner.calls"
fi
# A runner restarted by a later call (resuming) names each call that started it.
KAGE_PACK_PROVENANCE=$(printf 'device: %s\ncommit: %s\ncommand: %s, started the runner: %s %s\npacked by: %s' \
  "$devices" "$COMMIT" "$(paste -sd ';' "$DIR/runner.calls" | sed 's/;/; /g')" "${run[*]}" "$FLAGS" "$call")
export KAGE_PACK_PROVENANCE
# A finished task that $OUT has no room for (pack_task's status 3) ends the call at once, for the next to
# bring home while the lease lasts; so does any other failure of packing, which the log then shows.
while runner_alive && [ "$SECONDS" -lt $((LIMIT - 25)) ]; do sleep 10; pack_new || break; done  # 25 s: log, status
pack_new
new_lines=$(tail -c +$((seen + 1)) "$runner_log" | grep -v '^iteration')
printf '%s\n' "$new_lines" >>"$OUT/call.log"
for log in $(printf '%s\n' "$new_lines" | grep -o 'FAILED (exit [0-9-]*); see [^ ]*' | sed 's/.*; see //' | sort -u); do
  { echo "table_device: the end of $log"; tail -25 "$log"; } >>"$OUT/call.log"  # the cause, without another call
done
# The unfinished runs' logs so far, so that a machine given back before the next call (idle past its release
# time, say) takes no evaluation already logged with it: $OUT/runs_so_far.tar.gz (run directories without
# checkpoints, TensorBoard files or summary.json; unpack it over the packs for kage.bench compare --max-step).
bring_so_far() {
  local list
  list=$(mktemp)
  (cd "$DIR" && find runs -name metrics.jsonl -printf '%h\n' | while read -r run; do
     [ -e "$run/summary.json" ] || echo "$run"; done) >"$list"
  [ -s "$list" ] || { rm -f "$list"; return 0; }
  if [ "$(find "$OUT" -maxdepth 1 -type f | wc -l)" -ge "$MAX_FILES" ]; then
    echo "table_device: no room in \$OUT for runs_so_far.tar.gz (MAX_FILES $MAX_FILES)" >>"$OUT/call.log"
    rm -f "$list"
    return 0
  fi
  tar czf "$OUT/runs_so_far.tar.gz" -C "$DIR" --exclude=checkpoints --exclude=tensorboard --exclude='*.lock' \
    bench.json suite.json tasks.json -T "$list" &&
    echo "table_device: $(wc -l <"$list") unfinished runs' logs in runs_so_far.tar.gz" >>"$OUT/call.log"
  rm -f "$list"
}
bring_so_far
runner_alive && echo "table_device: the runner trains on ($(date -u +%H:%M:%S) UTC); call again" >>"$OUT/call.log"
# Each unfinished pack's last trainer line (iteration, rate, ETA): whether what is left fits the lease.
for log in "$DIR"/packs/task_*_pack_*.log; do
  [ -e "$log" ] && ! grep -q '^kage.ppo.train: done' "$log" && printf '%s: %s\n' "${log##*/}" "$(tail -n1 "$log")"
done >>"$OUT/call.log"
python3 -m kage.bench status "$DIR" >>"$OUT/call.log" 2>&1
tail -40 "$OUT/call.log"
