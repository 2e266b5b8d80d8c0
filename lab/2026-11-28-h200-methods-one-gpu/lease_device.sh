#!/usr/bin/env bash
# One lease of one GPU, two methods' tasks trained side by side on it (lab/tools/table_device.sh, each in a
# folder of $OUT of its own, 4 files each): task 4 of rollout colour jitter (effects/1-3, PACK 13, the method's
# last task) and DrAC colour jitter's tasks DRAC_TASKS (PACK 5: its task table in every lease). The first
# table_device.sh builds; the second starts once the first has written its log, so the two never build at once.
# Run from the repository root with carry [".deps"], calls back to back (the machine goes back when idle):
#   COMMIT=... DRAC_TASKS=1 bash lab/2026-11-28-h200-methods-one-gpu/lease_device.sh
set -uo pipefail
export ROOT=/tmp/kage-table-tree OUT=${OUT:-/tmp/kage-device-out}
table=(lab/tools/table_device.sh)
base="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter"
common=(env COMMIT="$COMMIT" GPUS=all SUITE=kage_bench SEEDS=1-5 MAX_FILES=4)
rollout=("${common[@]}" OUT="$OUT/rollout_color_jitter" TASKS=4 PACK=13 DIR=/tmp/kage-m-rollout_color_jitter
         PUBLISHED=results/methods/rollout_color_jitter/packs FLAGS="$base --augment-mode rollout")
drac=("${common[@]}" OUT="$OUT/drac_color_jitter" TASKS="${DRAC_TASKS:?DRAC_TASKS=1,8}" PACK=5
      DIR=/tmp/kage-m-drac_color_jitter PUBLISHED=results/methods/drac_color_jitter/packs FLAGS="$base --augment-mode drac")
limit=565
"${rollout[@]}" LIMIT=$limit bash "${table[@]}" >/tmp/lease.rollout.tail 2>&1 &
first=$!
until [ -e "$OUT/rollout_color_jitter/call.log" ] || ! kill -0 $first 2>/dev/null; do sleep 2; done
"${drac[@]}" LIMIT=$((limit - SECONDS)) bash "${table[@]}" >/tmp/lease.drac.tail 2>&1 &
second=$!
wait $first; echo "== rollout colour jitter"; cat /tmp/lease.rollout.tail
wait $second; echo "== drac colour jitter"; cat /tmp/lease.drac.tail
exit 0
