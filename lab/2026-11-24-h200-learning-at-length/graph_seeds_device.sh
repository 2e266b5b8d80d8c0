#!/usr/bin/env bash
# One device-machine call: does --cuda-graph change what the trainer learns? tests/gpu/test_rollout_graph.py,
# then background/1 with seeds 2-4, each eager and with --cuda-graph (983,040 steps, evaluation every 30
# iterations), all processes on the GPU at once; lab/tools/learning_summary.py prints each run. Carry [".deps"].
set -uo pipefail
source lab/tools/device_build.sh >/dev/null
python3 -m pytest -q -p no:cacheprovider tests/gpu/test_rollout_graph.py 2>&1 | tail -2
dir=/tmp/kage-graph-seeds
rm -rf "$dir"
for seed in 2 3 4; do
  for graph in no-cuda-graph cuda-graph; do
    python3 -m kage.ppo.train --train-config-path configs/kage_bench/bases/shape_black.yaml \
      --eval-config-path configs/kage_bench/background/1-eval.yaml --seed "$seed" --out "$dir/$graph-$seed" \
      --device cuda --total-timesteps 983040 --run-eval-every 30 "--$graph" >"$dir-$graph-$seed.log" 2>&1 &
  done
done
wait
python3 lab/tools/learning_summary.py "$dir"
