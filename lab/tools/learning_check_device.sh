#!/usr/bin/env bash
# One device-machine call for the fast path's learning check: 8 paired seeds trained on shape_black and
# evaluated on background/1 and agent_appearance/1 (`kage.bench run --share-training`, one pack of 8) at
# STEPS steps, once with the float32 default and once with FAST's flags; then each directory's report, the
# paired comparison (`kage.bench compare`), and per run the train success_once reached and whether the seed
# collapsed to never jumping (lab/tools/learning_summary.py). Build first (lab/tools/device_build.sh). With run's
# carry [".deps"]. The run folders live in RUNS on the machine (a killed call resumes there), the reports
# and summaries go to $OUT; VARIANTS="default", then VARIANTS="fast", splits the check over two calls of one
# lease, the second also comparing the two:
#   bash lab/tools/learning_check_device.sh
set -uo pipefail
source lab/tools/device_build.sh
STEPS=${STEPS:-2000000}
FAST=${FAST:---bf16 --fused-input --cuda-graph --triton-conv}
RUNS=${RUNS:-/tmp/kage-learning-check}
common=(kage_bench --pairs background/1 agent_appearance/1 --seeds 1-8 --share-training --pack 8 --device cuda
        --total-timesteps "$STEPS")
for variant in ${VARIANTS:-default fast}; do
  flags=()
  # shellcheck disable=SC2206
  [ "$variant" = fast ] && flags=($FAST)
  t0=$SECONDS
  python3 -m kage.bench run "${common[@]}" --out "$RUNS/$variant" "${flags[@]}" 2>&1 |
    grep -v '^iteration' | tail -5
  echo "$variant: $((SECONDS - t0)) s (flags: ${flags[*]:-none})" | tee -a "$OUT/times.txt"
  python3 -m kage.bench report "$RUNS/$variant" 2>&1 | tail -20
  python3 lab/tools/learning_summary.py "$RUNS/$variant" >"$OUT/$variant-summary.txt"
done
[[ -d $RUNS/default && -d $RUNS/fast ]] || exit 0  # one variant a call: compare after the second
python3 -m kage.bench compare "$RUNS/default" "$RUNS/fast" --names default fast --out "$OUT/compare" 2>&1 | tail -30
