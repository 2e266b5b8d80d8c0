#!/usr/bin/env bash
# One device-machine call for packed training speed: build (lab/tools/device_build.sh), then
# `python3 -m kage.bench speed` once per flag set, each line of SETS being "PACKS|TRAINER FLAGS"
# (default below). Tables go to the output, JSON lines to $OUT/speed.jsonl. Run with carry [".deps"]:
#   SETS=$'1,16|\n1,4,8,16,32|--bf16 --channels-last' bash lab/tools/speed_device.sh
set -uo pipefail
source lab/tools/device_build.sh
SETS=${SETS:-$'1,16|\n16|--bf16\n16|--bf16 --channels-last\n1,4,8,16,32|--bf16 --channels-last --cuda-graph'}
while IFS='|' read -r packs flags; do
  [ -z "$packs" ] && continue
  # shellcheck disable=SC2086
  python3 -m kage.bench speed --packs "$packs" --device cuda --json "$OUT/speed.jsonl" $flags 2>&1 |
    grep -v '^iteration\|^kage.ppo.train' | tee -a "$OUT/speed.log"
done <<<"$SETS"
