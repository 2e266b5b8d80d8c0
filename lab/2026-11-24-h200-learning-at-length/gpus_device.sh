#!/usr/bin/env bash
# One device-machine call for `kage.bench run --gpus`: build (lab/tools/device_build.sh), then two short runs
# of two pairs on the machine's GPUs, once with --gpus 0 and once with --gpus all, each followed by
# `kage.bench status` and `kage.bench report`; the logs come back under $OUT. Run with carry [".deps"]:
#   bash lab/2026-11-24-h200-learning-at-length/gpus_device.sh [extra trainer flags]
set -uo pipefail
source lab/tools/device_build.sh
short=(--total-timesteps 131072 --run-eval-every 4 --eval-episodes 32)
for gpus in 0 all; do
  dir=/tmp/kage-bench-gpus-$gpus
  rm -rf "$dir"
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/1 agent_appearance/1 --seeds 1-2 --pack 2 \
    --out "$dir" --gpus "$gpus" "${short[@]}" "$@" 2>&1 | tee "$OUT/run_gpus_$gpus.log"
  python3 -m kage.bench status "$dir" 2>&1 | tee "$OUT/status_gpus_$gpus.log"
  python3 -m kage.bench report "$dir" 2>&1 | tee -a "$OUT/status_gpus_$gpus.log"
  mkdir -p "$OUT/gpus_$gpus" && cp "$dir"/tasks/*.log "$dir"/report/pairs.md "$OUT/gpus_$gpus/" 2>/dev/null
done
nvidia-smi --query-gpu=index,name --format=csv | tee -a "$OUT/gpu.txt"
