#!/usr/bin/env bash
# Does the number of hardware queues bound a mixture's training rate? `kage.bench speed` at K = 16 (the table's
# flags, evaluated on filters/1) on image_skeleton and on the mixture of four of this lease's record, with
# CUDA_DEVICE_MAX_CONNECTIONS at the driver's default (8) and at its maximum (32), alternating. One GPU; carry
# [".deps"]:   bash lab/2026-11-28-h200-step-graphs/connections_device.sh
set -uo pipefail
source lab/tools/device_build.sh >/dev/null || exit 1
export TRITON_CACHE_DIR=/tmp/kage-triton-cache
mix4="configs/kage_bench/bases/image_skeleton.yaml configs/kage_bench/filters/1-eval.yaml
      configs/kage_bench/filters/4-eval.yaml configs/kage_bench/effects/1-eval.yaml"
speed=(python3 -m kage.bench speed --packs 16 --warmup 2 --iterations 4 --device cuda --bf16 --fused-input
       --cuda-graph --triton-conv --eval-config-path configs/kage_bench/filters/1-eval.yaml)
for connections in 8 32 8 32; do
  # shellcheck disable=SC2086
  for train in "--train-config-paths $mix4" "--train-config-path configs/kage_bench/bases/image_skeleton.yaml"; do
    echo "== CUDA_DEVICE_MAX_CONNECTIONS=$connections $(date -u +%T) ${train%% *}" | tee -a "$OUT/connections.log"
    CUDA_DEVICE_MAX_CONNECTIONS=$connections timeout 90 "${speed[@]}" $train --json "$OUT/connections.jsonl" 2>&1 |
      grep -v '^iteration\|^kage.ppo.train' | tee -a "$OUT/connections.log" | tail -1
  done
  [ "$SECONDS" -gt 300 ] && break  # the lease's remaining device time: one round
done
