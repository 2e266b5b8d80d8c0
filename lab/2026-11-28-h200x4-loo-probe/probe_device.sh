#!/usr/bin/env bash
# One call on a lease of four GPUs (nvidia-h200-x4), carry [".deps"]: the arms of SUITE (default probe_suite.yaml,
# its three; probe_suite_looks.yaml has four), seeds 1-5, one pack of five runs a GPU, in DIR, for STEPS steps a
# run at the table's flags; after LIMIT seconds of the call (or once the runner ends) every run's metrics.jsonl
# so far comes home in $OUT/probe_runs.tar.gz.
#   STEPS=3276800 LIMIT=430 bash lab/2026-11-28-h200x4-loo-probe/probe_device.sh
#   SUITE=probe_suite_looks.yaml DIR=/tmp/kage-loo-looks STEPS=6553600 LIMIT=400 \
#     bash lab/2026-11-28-h200x4-loo-probe/probe_device.sh
set -uo pipefail
source lab/tools/device_build.sh >/dev/null || exit 1
export TRITON_CACHE_DIR=/tmp/kage-triton-cache
DIR=${DIR:-/tmp/kage-loo-probe}
SUITE=${SUITE:-probe_suite.yaml}
LIMIT=${LIMIT:-430}
python3 -m kage.bench run "lab/2026-11-28-h200x4-loo-probe/$SUITE" --seeds 1-5 --share-training --pack 5 \
  --gpus all --out "$DIR" --bf16 --fused-input --cuda-graph --triton-conv --total-timesteps "${STEPS:-3276800}" \
  >"$OUT/runner.log" 2>&1 &
runner=$!
while kill -0 "$runner" 2>/dev/null && [ "$SECONDS" -lt "$LIMIT" ]; do sleep 5; done
echo "probe_device: $(date -u +%T) UTC, ${SECONDS} s into the call" >>"$OUT/runner.log"
python3 -m kage.bench status "$DIR" >>"$OUT/runner.log" 2>&1
(cd "$DIR" && find runs -name metrics.jsonl -o -name run.json |
  tar czf "$OUT/probe_runs.tar.gz" -T - bench.json suite.json tasks.json)
tail -c 3000 "$DIR"/tasks/task_1.log >"$OUT/task_1_tail.log" 2>/dev/null
grep -v '^iteration' "$OUT/runner.log" | tail -20
