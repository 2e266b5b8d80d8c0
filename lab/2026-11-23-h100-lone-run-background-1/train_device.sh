#!/usr/bin/env bash
# One device-machine call for the trainer: build (lab/tools/device_build.sh), then a lone run of
# `python3 -m kage.ppo.train` on background/1, seed 1, with the spec's defaults but its length
# (TOTAL_TIMESTEPS, default 1,703,936 = 104 iterations: evaluations at steps 0, 819,200, 1,638,400 and
# 1,703,936). Its run directory's files come back under $OUT. Run with carry [".deps"]:
#   bash lab/2026-11-23-h100-lone-run-background-1/train_device.sh [extra trainer flags]
set -uo pipefail
source lab/tools/device_build.sh
run=/tmp/kage-run-bg1
rm -rf "$run"
python3 -m kage.ppo.train --train-config-path configs/kage_bench/bases/shape_black.yaml \
  --eval-config-path configs/kage_bench/background/1-eval.yaml --seed 1 --device cuda \
  --total-timesteps "${TOTAL_TIMESTEPS:-1703936}" --out "$run" "$@" 2>&1 | tee "$OUT/train.log"
cp "$run/metrics.jsonl" "$run/run.json" "$OUT/" 2>/dev/null
cp "$run/summary.json" "$OUT/" 2>/dev/null
