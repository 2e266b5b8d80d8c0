#!/usr/bin/env bash
# charts/SPS's clock against the wall (issue 38): a pack of 5 runs of background/10 for 100 iterations, with DrAC
# colour jitter's flags and then with the baseline's, at the table's flags; for each, the runs' logged training
# time (global_step / charts/SPS), their evaluation points' seconds, and the wall time from the first run's
# run.json (written once the pack has opened) to its summary.json. Then kage.bench speed at K = 5 with DrAC's flags,
# whose iterations are timed with a device synchronisation. Run with carry [".deps"].
set -uo pipefail
source lab/tools/device_build.sh
F="--bf16 --fused-input --cuda-graph --triton-conv"
DRAC="--augment kage.ppo.augment:color_jitter --augment-mode drac"
for method in drac baseline; do
  dir=/tmp/clock-$method
  extra=$([ "$method" = drac ] && echo "$DRAC")
  # shellcheck disable=SC2086
  python3 -m kage.bench run suites/kage_bench.yaml --pairs background/10 --seeds 1-5 --share-training --pack 5 \
    --total-timesteps 1638400 --out "$dir" $F $extra >"$OUT/run_$method.log" 2>&1 || tail -20 "$OUT/run_$method.log"
  python3 - "$dir" "$method" <<'PY' | tee -a "$OUT/summary.txt"
import glob, json, os, sys
root, method = sys.argv[1:]
for run in sorted(glob.glob(f"{root}/runs/background/10/seed_*")):
    rows = [json.loads(line) for line in open(f"{run}/metrics.jsonl")]
    last = [r for r in rows if r["kind"] == "train"][-1]
    train = last["global_step"] / last["charts/SPS"]
    evals = sum(r["seconds"] for r in rows if r["kind"] == "eval")
    wall = os.path.getmtime(f"{run}/summary.json") - os.path.getmtime(f"{run}/run.json")
    print(f"{method} {os.path.basename(run)}: iterations {last['iteration']}, logged training {train:.1f} s "
          f"({5 * last['global_step'] / train:,.0f} steps/s for the pack), evaluation points {evals:.1f} s, "
          f"wall from run.json to summary.json {wall:.1f} s, not in either {wall - train - evals:.1f} s")
PY
done
# shellcheck disable=SC2086
timeout 200 python3 -m kage.bench speed --packs 5 --device cuda $F $DRAC >"$OUT/speed_drac.txt" 2>&1
grep '^|' "$OUT/speed_drac.txt"
