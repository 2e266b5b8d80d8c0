#!/usr/bin/env bash
# One lease of one GPU, two jobs (lab record beside this script):
#  - kage_render as the one render entry point (grouped and per-batch launches alike), checked against the tree
#    before it (d0be770, unpacked in .before): `kagec bench --gpu` before/after, GPU = CPU on every shipped
#    config, the GPU tests of the step paths and kage.jax's equality check;
#  - DrAC colour jitter's task 2 of `--pack 5` (background/4, seeds 1-5; issue 40), trained by the runner of
#    lab/tools/table_device.sh from the .before tree, the code its other tasks were trained with.
# PART (one a call; make the next call at once, the device gives the machine back 30 s after a call):
#   bench   compare_builds_device.sh's bench (builds both trees), then starts the runner
#   tests   the after build's GPU tests and checks while the runner trains, then waits for it (table_device.sh)
#   wait    waits for the runner and packs its task (table_device.sh)
# Prepare here: git archive d0be770 -- . ':!results' ':!lab/2026*' | tar -x -C .before; move
# results/kage-bench-table out of the working tree for the calls (64 MiB); carry [".deps", ".before"].
set -uo pipefail
OUT=${OUT:-/tmp/kage-device-out}
FLAGS="--bf16 --fused-input --cuda-graph --triton-conv --augment kage.ppo.augment:color_jitter --augment-mode drac"
table() {  # LIMIT: the runner's table_device.sh call, from the .before tree, its output under $OUT/table
  ln -sfn "$PWD/.deps" .before/.deps  # absolute: table_device.sh copies the tree to its ROOT
  (cd .before && OUT=$OUT/table BUILD=build-runner COMMIT=d0be770 TASK=2 SUITE=kage_bench SEEDS=1-5 PACK=5 \
     DIR=/tmp/kage-m-drac_color_jitter PUBLISHED=none FLAGS="$FLAGS" LIMIT=$1 bash lab/tools/table_device.sh)
}
case ${PART:?PART=bench, tests or wait} in
  bench)
    STEPS=bench bash lab/tools/compare_builds_device.sh
    table 40 ;;
  tests)
    source lab/tools/device_build.sh >/dev/null || exit 1
    python3 -m pytest -q -p no:cacheprovider tests/gpu/test_step_batches_gpu.py tests/gpu/test_step_graph_gpu.py \
      tests/gpu/test_gpu_vec.py tests/gpu/test_mixture_gpu.py tests/gpu/test_array_layout_gpu.py \
      tests/gpu/test_train_mixture_gpu.py 2>&1 | tail -15 | tee "$OUT/gpu_tests.log"
    python3 lab/tools/jax_check.py equal configs/throughput/simplest.yaml configs/throughput/hardest.yaml \
      configs/kage_bench/filters/7-eval.yaml 2>&1 | tail -8 | tee "$OUT/jax_equal.log"
    STEPS=check bash lab/tools/compare_builds_device.sh 2>&1 | tail -8 | tee "$OUT/check_summary.log"
    table $((570 - SECONDS)) ;;
  wait)
    table 570 ;;
esac
