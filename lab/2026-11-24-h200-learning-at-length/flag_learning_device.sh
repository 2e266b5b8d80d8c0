#!/usr/bin/env bash
# One device-machine call: does each speed flag keep the trainer learning? Short runs of background/1
# (seed 1, STEPS steps, evaluation every 40 iterations), one process per flag set, all on the GPU at
# once; then 4 packed runs (background/1 and agent_appearance/1, seeds 1-2) with
# every flag. Prints the train config's evaluation return and success_once per run and evaluation point.
# Carry [".deps"]:  bash lab/2026-11-24-h200-learning-at-length/flag_learning_device.sh
set -uo pipefail
source lab/tools/device_build.sh
steps=${STEPS:-1310720}
dir=/tmp/kage-flag-learning
rm -rf "$dir"
common=(--device cuda --total-timesteps "$steps" --run-eval-every 40)
while IFS='|' read -r name flags; do
  # shellcheck disable=SC2086
  python3 -m kage.ppo.train --train-config-path configs/kage_bench/bases/shape_black.yaml \
    --eval-config-path configs/kage_bench/background/1-eval.yaml --seed 1 --out "$dir/lone-$name" \
    "${common[@]}" $flags >"$dir-lone-$name.log" 2>&1 &
done <<'SETS'
fp32|
bf16|--bf16
fused|--fused-input
channels_last|--channels-last
cuda_graph|--cuda-graph
all|--bf16 --channels-last --fused-input --cuda-graph
SETS
for set in "all|--bf16 --channels-last --fused-input --cuda-graph"; do
  # shellcheck disable=SC2086
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/1 agent_appearance/1 --seeds 1-2 \
    --pack 4 --out "$dir/pack4-${set%%|*}" "${common[@]}" ${set#*|} >"$dir-pack-${set%%|*}.log" 2>&1 &
done
wait
python3 lab/tools/learning_summary.py "$dir"
tail -n 3 "$dir"-*.log
