#!/usr/bin/env bash
# One device-machine call: which speed flag lowers the policy's entropy? Seed 1 of background/1 alone,
# once per flag (fp32, --bf16, --channels-last, --fused-input), STEPS steps (default 2,621,440), all at
# once; prints the entropy every 20 iterations and the evaluation points. Carry [".deps"].
set -uo pipefail
source lab/tools/device_build.sh
dir=/tmp/kage-entropy
rm -rf "$dir"
for flag in fp32 bf16 channels-last fused-input; do
  extra=()
  [[ $flag != fp32 ]] && extra=("--$flag")
  python3 -m kage.ppo.train --train-config-path configs/kage_bench/bases/shape_black.yaml \
    --eval-config-path configs/kage_bench/background/1-eval.yaml --seed 1 --out "$dir/$flag" --device cuda \
    --total-timesteps "${STEPS:-2621440}" --run-eval-every 40 "${extra[@]}" >"$dir-$flag.log" 2>&1 &
done
wait
python3 lab/tools/learning_summary.py "$dir"
