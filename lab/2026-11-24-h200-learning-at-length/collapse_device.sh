#!/usr/bin/env bash
# One device-machine call: the policy collapse seen in a full-length packed run (background/1 and
# agent_appearance/1 seed 1, entropy 0 from about iteration 120 with --bf16 --channels-last --fused-input)
# under each condition at once: seed 1 alone and packed (4 runs: both pairs, seeds 1-2), in fp32 and with
# those flags, for STEPS steps (default 2,621,440 = 160 iterations). Prints per run the evaluation return
# and success_once, and the entropy every 20 iterations. Carry [".deps"]:
#   bash lab/2026-11-24-h200-learning-at-length/collapse_device.sh
set -uo pipefail
source lab/tools/device_build.sh
steps=${STEPS:-2621440}
dir=/tmp/kage-collapse
rm -rf "$dir"
common=(--device cuda --total-timesteps "$steps" --run-eval-every 40)
fast=(--bf16 --channels-last --fused-input)
for set in fp32 fast; do
  flags=()
  [[ $set == fast ]] && flags=("${fast[@]}")
  python3 -m kage.ppo.train --train-config-path configs/kage_bench/bases/shape_black.yaml \
    --eval-config-path configs/kage_bench/background/1-eval.yaml --seed 1 --out "$dir/lone-$set" \
    "${common[@]}" "${flags[@]}" >"$dir-lone-$set.log" 2>&1 &
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/1 agent_appearance/1 --seeds 1-2 \
    --pack 4 --out "$dir/pack4-$set" "${common[@]}" "${flags[@]}" >"$dir-pack4-$set.log" 2>&1 &
done
wait
python3 lab/tools/learning_summary.py "$dir"
tail -n 2 "$dir"-*.log
