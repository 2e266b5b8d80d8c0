#!/usr/bin/env bash
# One device-machine call of the full-length comparison with the paper: background/1 and agent_appearance/1,
# seeds SEEDS (default 1-3), 25 M steps per run with the spec's evaluation. The two pairs share their train
# config, so under --share-training each seed is one run evaluating both eval configs, and all seeds are
# packed in one process. Trainer flags: FLAGS (default none: float32). A call trains until BUDGET seconds
# (default 540, the build included) have passed, then SIGTERM makes the trainer checkpoint and exit; call
# again on the warm machine and it resumes from the checkpoints on that machine's disk. Once every run is
# finished, the report is written. Logs, metrics and the report (no checkpoints) come back under $OUT.
# Carry [".deps"]:
#   BUDGET=540 bash lab/2026-11-24-h200-paper-gaps/paper_gaps_device.sh
set -uo pipefail
source lab/tools/device_build.sh
dir=/tmp/kage-paper-gaps
seeds=${SEEDS:-1-3}
runs=$(seq -s ' ' ${seeds/-/ } | wc -w)
# shellcheck disable=SC2206
flags=(--device cuda ${FLAGS:-})
timeout -s TERM --kill-after=180 $((${BUDGET:-540} - SECONDS)) \
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/1 agent_appearance/1 --seeds "$seeds" \
  --share-training --pack "$runs" --out "$dir" "${flags[@]}"
echo "kage.bench run: exit $?"
tail -3 "$dir"/packs/*.log
if [ "$(find "$dir/runs" -name summary.json | wc -l)" -eq "$runs" ]; then
  python3 -m kage.bench report "$dir"
fi
# What comes back (the device tool returns folders 3 deep): the report, the logs, each run's files.
cp -r "$dir/report" "$OUT/" 2>/dev/null
cp "$dir"/packs/*.log "$dir/bench.json" "$OUT/"
for run in "$dir"/runs/*/*/seed_*; do
  name=$(realpath --relative-to="$dir/runs" "$run" | tr / _)
  mkdir -p "$OUT/runs/$name"
  cp "$run"/*.json "$run"/metrics.jsonl "$OUT/runs/$name/" 2>/dev/null
done
