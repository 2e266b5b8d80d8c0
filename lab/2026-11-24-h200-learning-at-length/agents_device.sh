#!/usr/bin/env bash
# One device-machine call for "your own agent": the baseline and the example agent (the baseline trained
# with kage.ppo.augment:random_shift) side by side on background/1 for the same number of steps
# (TOTAL_TIMESTEPS, default 1,703,936 as lab/2026-11-23-h100-lone-run-background-1/train_device.sh; SEEDS,
# default 1; PACK, default 1), each through `python3 -m kage.bench run` into its own directory, then `kage.bench report` on each. The two
# reports' tables and a side-by-side pairs table (compare.md) come back under $OUT. Run with carry [".deps"]:
#   bash lab/2026-11-24-h200-learning-at-length/agents_device.sh [extra trainer flags]
set -uo pipefail
source lab/tools/device_build.sh
root=/tmp/kage-agents
rm -rf "$root"
for agent in baseline random_shift; do
  extra=()
  [[ $agent == random_shift ]] && extra=(--augment kage.ppo.augment:random_shift)
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/1 --seeds "${SEEDS:-1}" --pack "${PACK:-1}" \
    --out "$root/$agent" --device cuda --total-timesteps "${TOTAL_TIMESTEPS:-1703936}" "${extra[@]}" "$@" \
    2>&1 | tee "$OUT/run_$agent.log"
  python3 -m kage.bench report "$root/$agent" 2>&1 | tee -a "$OUT/run_$agent.log"
  mkdir -p "$OUT/$agent"
  cp "$root/$agent/report/"*.md "$root/$agent/report/"*.csv "$root/$agent/bench.json" "$OUT/$agent/" 2>/dev/null
done
{
  echo "# background/1: the baseline and the example agent (random shift), same steps and seeds"
  for agent in baseline random_shift; do
    echo; echo "## $agent"; echo
    sed -n '/^## success/,/^## distance/p' "$OUT/$agent/pairs.md" | sed '$d'
  done
} > "$OUT/compare.md"
cat "$OUT/compare.md"
