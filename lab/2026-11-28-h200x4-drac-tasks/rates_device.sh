#!/usr/bin/env bash
# One call on one GPU (nvidia-h200), issue 40's planning: what a GPU trains DrAC at, packed K = 5 (the pack of
# DrAC colour jitter's published tasks) and K = 13 (rollout colour jitter's), and two K = 5 processes side by side
# on the same GPU (can two runners share a GPU to more effect than one?); then issue 39's profile of a mixture's
# iteration without --cuda-graph, as long as the call lasts. Run from the repository root with carry [".deps"].
set -uo pipefail
source lab/tools/device_build.sh >/dev/null || exit 1
export TRITON_CACHE_DIR=/tmp/kage-triton-cache
flags=(--device cuda --bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter
       --augment-mode drac --train-config-path configs/kage_bench/bases/image_skeleton.yaml
       --eval-config-path configs/kage_bench/filters/1-eval.yaml --warmup 2 --iterations 4)
speed() { timeout "$1" python3 -m kage.bench speed "${@:2}" "${flags[@]}" 2>&1 | grep -v '^iteration\|^kage.ppo.train'; }
echo "== $(date -u +%T) DrAC colour jitter, K = 5, alone" | tee -a "$OUT/rates.log"
speed 150 --packs 5 --json "$OUT/rates.jsonl" | tee -a "$OUT/rates.log" | tail -3
echo "== $(date -u +%T) DrAC colour jitter, K = 13, alone" | tee -a "$OUT/rates.log"
speed 150 --packs 13 --json "$OUT/rates.jsonl" | tee -a "$OUT/rates.log" | tail -3
echo "== $(date -u +%T) DrAC colour jitter, K = 5, two processes on the GPU at once" | tee -a "$OUT/rates.log"
for i in 1 2; do
  speed 180 --packs 5 --json "$OUT/rates_pair$i.jsonl" >"$OUT/rates_pair$i.log" 2>&1 &
done
wait
tail -n 3 "$OUT"/rates_pair*.log | tee -a "$OUT/rates.log"
left=$((560 - SECONDS))
echo "== $(date -u +%T) the mixture of four at K = 16, no graph, profiled (${left} s left)" | tee -a "$OUT/rates.log"
if [ "$left" -gt 90 ]; then
  timeout $((left - 10)) python3 lab/tools/profile_iteration.py --packs 16 --bf16 --fused-input --triton-conv \
    --train-config-paths configs/kage_bench/bases/image_skeleton.yaml configs/kage_bench/filters/1-eval.yaml \
    configs/kage_bench/filters/4-eval.yaml configs/kage_bench/effects/1-eval.yaml 2>&1 |
    grep -v '^iteration\|^kage.ppo.train' >"$OUT/profile_mixture.log"
  tail -40 "$OUT/profile_mixture.log"
fi
exit 0
