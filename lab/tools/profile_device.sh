#!/usr/bin/env bash
# One device-machine call profiling a training iteration (lab/tools/profile_iteration.py) after the build
# (lab/tools/device_build.sh); the report goes to the output and $OUT/profile.log, the Chrome trace to
# $OUT/trace.json when TRACE=1. Arguments go to the script (--packs, trainer flags). Run with carry [".deps"]:
#   bash lab/tools/profile_device.sh --packs 16
set -uo pipefail
source lab/tools/device_build.sh
trace=()
[ "${TRACE:-0}" = 1 ] && trace=(--trace "$OUT/trace.json")
python3 lab/tools/profile_iteration.py "$@" "${trace[@]}" 2>&1 | grep -v '^iteration\|^kage.ppo.train' |
  tee "$OUT/profile.log"
