#!/usr/bin/env bash
# The Python layers' GPU check (issue 21, item 4), as run: two trees carried beside the working tree, built on
# the device with lab/tools/device_build.sh's recipe (each tree's own copy, bench/device_build.sh at these
# commits), then `kage.bench speed` at K = 8 with the fastest flags, the builds alternating (ABBAAB).
# Prepare here:  git archive 45d8930 | tar -x -C .before;  git archive 76aa28f | tar -x -C .after
# (plus the two fixes this record names); carry [".deps", ".before", ".after"].
# tests/gpu ran first, in the same lease: (cd .after && source bench/device_build.sh && pytest -q tests/gpu).
T=$OUT
for t in after before; do
  (cd .$t && ln -sfn ../.deps .deps && OUT=$T/$t bash -c 'source bench/device_build.sh >/dev/null' && echo "$t built")
done
F="--bf16 --fused-input --cuda-graph --triton-conv"
for rt in 1:after 1:before 2:before 2:after 3:after 3:before; do
  r=${rt%%:*}; t=${rt#*:}
  (cd .$t && export LD_LIBRARY_PATH=$PWD/.deps/usr/lib/x86_64-linux-gnu:/usr/local/cuda/lib64 \
     PYTHONPATH=$PWD/build-dev/python KAGE_CACHE_DIR=/tmp/kage-cache-$t PYTHONUNBUFFERED=1 &&
   python3 -m kage.bench speed --packs 8 --device cuda --json "$T/speed_$t.jsonl" $F 2>&1 |
     tee -a "$T/speed_$t.log" | grep "^| 8\|Error" | sed "s/^/$r $t /")
done
