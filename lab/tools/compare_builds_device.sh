#!/usr/bin/env bash
# One device-machine call for a change that must not alter GPU behaviour or speed:
#  1. `kagec bench CONFIG --gpu` at 2^LOG2 environments (default 14) for each of CONFIGS (default simplest and
#     hardest), with kagec built from an earlier tree in .before and from the working tree, the two builds
#     alternating back to back ROUNDS times (default 3, after one warm-up round that fills the kernel cache);
#  2. GPU = CPU on every shipped config with the working tree's build: `kagec compile --no-gpu --no-host`,
#     then `kage_gpu_throughput --check-only` (the generic kernels against the CPU batch, 32 environments).
# STEPS (default "bench check") picks the parts; a warm machine keeps both builds, so the two parts can be
# two calls. Prepare .before here (listed in .git/info/exclude): git archive COMMIT | tar -x -C .before
# Carry [".deps", ".before"]:
#   STEPS=bench bash lab/tools/compare_builds_device.sh; STEPS=check bash lab/tools/compare_builds_device.sh
set -uo pipefail
CONFIGS=${CONFIGS:-"configs/throughput/simplest.yaml configs/throughput/hardest.yaml"}
LOG2=${LOG2:-14}
ROUNDS=${ROUNDS:-3}
STEPS=${STEPS:-bench check}
tools=$PWD/lab/tools  # the .before tree may predate them
source "$tools/device_build.sh"
ninja -C "$BUILD" kage_gpu_throughput >>"$OUT/build.log" 2>&1 || { tail -40 "$OUT/build.log"; exit 1; }
after=$PWD/$BUILD/kagec

if [[ $STEPS == *bench* ]]; then
(cd .before && ln -sfn ../.deps .deps && OUT=$OUT/before source "$tools/device_build.sh" >/dev/null) ||
  { echo "the .before tree did not build: $OUT/before/build.log"; exit 1; }

bench() {  # TREE CONFIG -> the row's steps/s with observations, of TREE's kagec with TREE's runtime headers
  (cd "$1" && KAGE_ROOT=$PWD KAGE_CACHE_DIR=$PWD/.kage-cache "$PWD/$BUILD/kagec" bench "$2" --gpu \
    --min-log2 "$LOG2" --max-log2 "$LOG2" 2>>"$OUT/bench.err") | awk -F'|' '/^\| configs/ {print $4}'
}
declare -A tree=([before]=$PWD/.before [after]=$PWD)
for config in $CONFIGS; do bench "${tree[before]}" "$config" >/dev/null; bench "${tree[after]}" "$config" >/dev/null; done
for round in $(seq "$ROUNDS"); do
  for config in $CONFIGS; do
    for build in before after; do
      echo "$round $config $build $(bench "${tree[$build]}" "$config")" | tee -a "$OUT/rounds.txt"
    done
  done
done
python3 - "$OUT/rounds.txt" <<'PY'
import statistics, sys
rows = [line.split() for line in open(sys.argv[1])]
for config in dict.fromkeys(r[1] for r in rows):
    median = {b: statistics.median(float(r[3]) for r in rows if r[1] == config and r[2] == b) for b in ("before", "after")}
    print(f"{config}: before {median['before']:.4g}, after {median['after']:.4g} steps/s (median of "
          f"{len(rows) // 4}); after / before = {median['after'] / median['before']:.4f}")
PY
fi

[[ $STEPS == *check* ]] || exit 0
rm -rf /tmp/kage-all && mkdir -p /tmp/kage-all
for config in $(find configs -name '*.yaml' | sort); do
  id=$(echo "${config#configs/}" | tr / _)
  "$after" compile "$config" -o "/tmp/kage-all/${id%.yaml}" --no-gpu --no-host >/dev/null 2>>"$OUT/compile.err" ||
    echo "not compiled: $config (see compile.err)"
done
fatbin=$(find "$BUILD" -name dynamic.fatbin | head -1)
gpu_throughput=$(find "$BUILD" -name kage_gpu_throughput -type f | head -1)
"$gpu_throughput" "$fatbin" --compiled /tmp/kage-all/* --nvrtc-root "$PWD" --check-only --check-envs 32 \
  >"$OUT/check.log" 2>&1
echo "kage_gpu_throughput --check-only: exit $?, $(ls /tmp/kage-all | wc -l) compiled configs"
grep -c PASS "$OUT/check.log"; grep -v PASS "$OUT/check.log" | tail -15
